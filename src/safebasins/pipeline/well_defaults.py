"""Config defaults that follow the experiment's well.

A kind whose defaults were chosen for the paper's quartic (an IC window, a truncation level, a
forcing range, a frequency near the 1:1 resonance, the paper's first harmonic) declares them as
the quartic's values, and the schema's default is ``null``; :func:`fill` replaces every ``null``
before the kind's checks run, by that value carried over to the experiment's well by its own
scale:

* IC windows (``grid``): each edge as the same fraction of the well's IC window
  (:meth:`~safebasins.wells.base.Well.ic_window`; the quartic's is [-1, 1] x [-0.75, 0.75]);
* energies (``xi_max``): the same fraction of the barrier energy E_b (the quartic's is 1/4);
* forcing amplitudes (``F``): the same fraction of the static escape force
  (:attr:`~safebasins.wells.base.Well.static_escape_force`, the quartic's 2 / (3 sqrt 3));
* forcing frequencies (``Omega``): the same fraction of the linear frequency at the well bottom
  (the quartic's is 1);
* the first harmonic (``fourier``): the paper's for the quartic, the exact one for every other
  well (the paper's is the quartic's own truncated series).

Every carried-over number is rounded to three significant digits (the quartic keeps its values
exactly: its scale is 1).  The filled values are written into the experiment's parameter file.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from safebasins.wells import Well

__all__ = ["WellScale", "scale_of", "nullable", "window", "energy", "energies", "force_range", "force", "frequency",
           "fourier", "fill"]

#: the quartic's scales, the reference of the kinds' declared defaults
QUARTIC_WINDOW = ((-1.0, 1.0), (-0.75, 0.75))
QUARTIC_BARRIER_ENERGY = 0.25
QUARTIC_STATIC_FORCE = 2.0 / (3.0 * math.sqrt(3.0))
QUARTIC_FREQUENCY = 1.0

#: a default: a function of the well's scale giving the config value
WellDefault = Callable[["WellScale"], Any]


@dataclass(frozen=True)
class WellScale:
    """The scales of a well that the defaults follow."""

    name: str
    window: tuple[tuple[float, float], tuple[float, float]]
    barrier_energy: float
    static_force: float
    frequency: float


def _round3(x: float) -> float:
    """``x`` to three significant digits (0 stays 0)."""
    return 0.0 if x == 0 else float(f"{x:.3g}")


def scale_of(well: Well) -> WellScale:
    """The scales of ``well``: the quartic gets the reference values exactly."""
    if well.name == "quartic":
        return WellScale("quartic", QUARTIC_WINDOW, QUARTIC_BARRIER_ENERGY, QUARTIC_STATIC_FORCE, QUARTIC_FREQUENCY)
    (q_lo, q_hi), (p_lo, p_hi) = well.ic_window()
    E_b = float(well.barrier_energy)
    # omega(E) -> the linear frequency as E -> 0 (relative error ~ E / E_b, here 1e-6)
    om = float(well.omega(1e-6 * E_b))
    return WellScale(well.name, ((float(q_lo), float(q_hi)), (float(p_lo), float(p_hi))), E_b,
                     float(well.static_escape_force), om)


def window(q0: tuple[float, float], p0: tuple[float, float], n: int) -> WellDefault:
    """An IC grid whose edges are the quartic's ``q0``, ``p0`` as fractions of its IC window."""
    def make(s: WellScale) -> dict:
        (Ql, Qh), (Pl, Ph) = QUARTIC_WINDOW
        (ql, qh), (pl, ph) = s.window
        return {"q0": [_round3(q0[0] / Ql * ql), _round3(q0[1] / Qh * qh)],
                "p0": [_round3(p0[0] / Pl * pl), _round3(p0[1] / Ph * ph)], "n": int(n)}
    return make


def energy(xi: float) -> WellDefault:
    """A truncation level: the quartic's ``xi`` as a fraction of the barrier energy."""
    return lambda s: _round3(xi / QUARTIC_BARRIER_ENERGY * s.barrier_energy)


def energies(xis: list[float]) -> WellDefault:
    """A list of truncation levels (:func:`energy` each)."""
    return lambda s: [energy(x)(s) for x in xis]


def force(F: float) -> WellDefault:
    """A forcing amplitude: the quartic's ``F`` as a fraction of the static escape force."""
    return lambda s: _round3(F / QUARTIC_STATIC_FORCE * s.static_force)


def force_range(stop: float, num: int) -> WellDefault:
    """Forcing amplitudes ``0 .. stop`` (the quartic's), ``num`` values."""
    return lambda s: {"start": 0.0, "stop": force(stop)(s), "num": int(num)}


def frequency(Omega: float) -> WellDefault:
    """A forcing frequency: the quartic's ``Omega`` as a fraction of the linear frequency."""
    return lambda s: _round3(Omega / QUARTIC_FREQUENCY * s.frequency)


def fourier(paper: Any) -> WellDefault:
    """The first harmonic: ``paper`` (the quartic's value) for the quartic, else the exact one
    (a list when ``paper`` is one)."""
    def make(s: WellScale) -> Any:
        if s.name == "quartic":
            return paper
        return ["exact"] if isinstance(paper, list) else "exact"
    return make


def fill(block: dict, defaults: dict[str, WellDefault], well: Well) -> None:
    """Replace, in place, every ``null`` value of ``block`` that ``defaults`` names by the
    well's own default."""
    todo = [k for k in defaults if block.get(k) is None]
    if not todo:
        return
    s = scale_of(well)
    for k in todo:
        block[k] = defaults[k](s)


def nullable(schema: dict, follows: str) -> dict:
    """The config schema of a key whose default follows the well: ``schema`` or null (the
    default), ``follows`` saying what the null becomes."""
    text = schema.get("description")
    return {"description": (f"{text}; " if text else "") + f"null (the default): {follows}",
            "oneOf": [{"type": "null"}, {k: v for k, v in schema.items() if k != "description"}], "default": None}
