"""The explorer's sliders and windows follow the well: Omega around omega(0), xi_max below the
barrier energy, F up to half the static escape force, the IC window of ``Well.ic_window``."""
from __future__ import annotations

import numpy as np
import pytest

from safebasins import wells
from safebasins.explore import ranges

#: static escape force max |V'| on the way to the barrier, in closed form (V' = 0 -> V'' = 0)
STATIC_FORCE = {
    "quartic": 2 / (3 * np.sqrt(3)),              # V' = q - q^3, max at q = 1/sqrt(3)
    "cubic": 0.25,                                # V' = q - q^2, max at q = 1/2
    "pendulum": 1.0,                              # V' = sin q
    "sech2": 4 / (3 * np.sqrt(3)),                # V' = 2 tanh sech^2, max at tanh^2 = 1/3
    "morse": 0.5,                                 # V' = 2 (1 - e^-q) e^-q, max at e^-q = 1/2 (right side only)
}


def test_every_named_well_has_a_closed_form_force():
    assert set(STATIC_FORCE) == set(wells.NAMED_WELLS)


@pytest.mark.parametrize("name", list(wells.NAMED_WELLS))
def test_static_escape_force_is_the_closed_form(name):
    assert ranges.static_escape_force(wells.resolve_well(name)) == pytest.approx(STATIC_FORCE[name], rel=1e-6)


@pytest.mark.parametrize("well", [*wells.NAMED_WELLS, {"expression": "1 - cos(q)"},
                                  {"expression": "q**2/2 - q**3/3"}, {"polynomial": [0, 0, 0.5, 0, -0.25]}])
def test_sliders_follow_the_well(well):
    r = ranges.well_ranges(well)
    w = wells.resolve_well(well)
    Eb, omega0 = float(w.barrier_energy), float(w.omega(0.0))
    assert (r.barrier_energy, r.omega0) == (Eb, omega0)
    assert r.Omega.start < omega0 < r.Omega.end and r.Omega.start <= r.Omega.value <= r.Omega.end
    assert r.xi_max.end == pytest.approx(ranges.TOP * Eb) and r.xi_max.end < Eb
    assert 0 < r.xi_max.start < r.xi_max.value < r.xi_max.end
    assert r.F.end == pytest.approx(0.5 * ranges.static_escape_force(w)) and 0 < r.F.value < r.F.end
    assert r.damping.value == 0.0 and r.damping.end == pytest.approx(ranges.DAMPING_MAX * omega0)
    (q_lo, q_hi), (p_lo, p_hi) = w.ic_window()
    assert (r.q_window, r.p_window) == ((q_lo, q_hi), (p_lo, p_hi))
    text = wells.NAMED_WELLS[well][1] if isinstance(well, str) else f"your well {r.label}"
    assert r.description().startswith(text) and f"E_b = {Eb:.4g}" in r.description()


def test_the_same_expression_gets_the_same_ranges_as_the_named_well():
    named, typed = ranges.well_ranges("pendulum"), ranges.well_ranges({"expression": "1 - cos(q)"})
    assert (named.name, typed.name) == ("pendulum", "expression")
    assert typed.label == "V = 1 - cos(q)" and "your well V = 1 - cos(q)" in typed.description()
    for field in ("F", "Omega", "Psi", "xi_max", "damping", "q_window", "p_window", "xi_top"):
        assert getattr(typed, field) == pytest.approx(getattr(named, field)), field


@pytest.mark.parametrize("well, match", [("no such well", "well: unknown well"),
                                         ({"expression": "x**2"}, "unknown name"),
                                         ({"expression": "sin(q)"}, "V'\\(0\\)"),
                                         ({"expression": "q**2/2 + q**4"}, "closed")])
def test_a_bad_well_names_the_problem(well, match):
    with pytest.raises(ValueError, match=match):
        ranges.well_ranges(well)
