"""Defaults that follow the well: an experiment of a kind whose defaults were chosen for the
quartic (erosion, true_basin, integrity_map) gets, for another well, the same values carried
over by that well's own scales (IC window, barrier energy, static escape force, linear
frequency, first harmonic); the quartic keeps its values exactly; given values stay."""
from __future__ import annotations

import math

import pytest

from safebasins import wells
from safebasins.pipeline import well_defaults as WD
from safebasins.pipeline.config import ConfigError
from safebasins.pipeline.plan import plan
from tests.pipeline.test_config import base, merged  # noqa: F401  (the fixture)

MEMS = {"expression": "q**2/2 - 0.05/(1-q) + 0.05 + 0.05*q"}


def _params(base, name, block):
    return plan(merged(base, {"experiments": {name: block}})).experiments[name].params


def test_the_quartic_keeps_its_values(base):
    ero = _params(base, "e", {"kind": "erosion"})
    assert ero["xi_max"] == [0.18, 0.22] and ero["Omega"] == 0.9 and ero["fourier"] == ["paper", "exact"]
    assert ero["grid"]["q0"] == [-0.85, 0.85] and ero["grid"]["p0"] == [-0.7, 0.7] and ero["grid"]["n"] == [121, 121]
    assert ero["F"][0] == 0.0 and ero["F"][-1] == 0.15 and len(ero["F"]) == 31
    tb = _params(base, "t", {"kind": "true_basin"})
    assert tb["F"] == 0.01 and tb["xi_max"] == [0.18]
    assert tb["grid"]["q0"] == [-0.72, 0.72] and tb["grid"]["p0"] == [-0.63, 0.63]
    im = _params(base, "m", {"kind": "integrity_map", "Omega": {"start": 0.8, "stop": 1.0, "num": 3},
                             "F": {"start": 0.0, "stop": 0.04, "num": 3}})
    assert im["xi_max"] == 0.18 and im["fourier"] == "paper" and im["grid"]["n"] == [61, 61]


@pytest.mark.parametrize("spec", ["pendulum", "sech2", "cubic", MEMS])
def test_another_well_gets_its_own_scales(base, spec):
    w = wells.from_spec(wells.spec_of(spec))
    E_b = float(w.barrier_energy)
    (q_lo, q_hi), (p_lo, p_hi) = w.ic_window()
    ero = _params(base, "e", {"kind": "erosion", "well": spec})
    # each value carried over by the well's scale (three significant digits)
    assert ero["xi_max"] == pytest.approx([0.72 * E_b, 0.88 * E_b], rel=5e-3)
    assert max(ero["xi_max"]) < E_b
    assert ero["fourier"] == ["exact"]
    assert ero["F"][-1] == pytest.approx(0.15 / (2 / (3 * math.sqrt(3))) * w.static_escape_force, rel=5e-3)
    # the linear frequency, independently: sqrt(V'') at the bottom by a central difference
    h = 1e-4
    omega0 = math.sqrt((float(w.dV(h)) - float(w.dV(-h))) / (2 * h))
    assert ero["Omega"] == pytest.approx(0.9 * omega0, rel=5e-3)
    g = ero["grid"]
    assert g["q0"] == pytest.approx([0.85 * q_lo, 0.85 * q_hi], rel=5e-3)
    assert g["p0"] == pytest.approx([0.7 / 0.75 * p_lo, 0.7 / 0.75 * p_hi], rel=5e-3)
    # inside the well: the window's corners on the q axis are below the barrier energy
    assert float(w.V(g["q0"][0])) < E_b and float(w.V(g["q0"][1])) < E_b
    tb = _params(base, "t", {"kind": "true_basin", "well": spec})
    assert tb["fourier"] == ["exact"] and tb["xi_max"] == pytest.approx([0.72 * E_b], rel=5e-3)


def test_given_values_are_kept(base):
    block = {"kind": "erosion", "well": "pendulum", "xi_max": [1.0], "Omega": 0.8, "fourier": "exact",
             "grid": {"q0": [-2.0, 2.0], "p0": [-1.0, 1.0], "n": 11}, "F": [0.0, 0.1]}
    ero = _params(base, "e", block)
    assert ero["xi_max"] == [1.0] and ero["Omega"] == 0.8 and ero["grid"]["n"] == [11, 11] and ero["F"] == [0.0, 0.1]


def test_paper_harmonic_still_refused_for_another_well(base):
    """An explicit fourier: paper names the key (the default no longer sets it)."""
    with pytest.raises(ConfigError, match=r"experiments\.e\.fourier"):
        _params(base, "e", {"kind": "erosion", "well": "pendulum", "fourier": "paper"})


def test_the_schema_says_what_null_means():
    s = WD.nullable({"$ref": "#/$defs/grid", "description": "IC grid"}, "the well's window")
    assert s["default"] is None and s["description"] == "IC grid; null (the default): the well's window"
    assert s["oneOf"] == [{"type": "null"}, {"$ref": "#/$defs/grid"}]
