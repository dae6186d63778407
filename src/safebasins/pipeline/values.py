"""Turning config values into resolved parameters: ranges, grids, angles, curve lists.

Resolved parameters are plain Python (lists, floats, ints, str) so that they dump to YAML and
hash stably (``results/params/<experiment>.yaml``).
"""
from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, SupportsFloat

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from safebasins.wells.base import Well


def as_list(v: Any) -> list[Any]:
    return list(v) if isinstance(v, (list, tuple)) else [v]


def angle(v: SupportsFloat | str) -> float:
    """A config angle: a number (radians) or the string "pi" / "-pi"."""
    if isinstance(v, str):
        return -math.pi if v.strip().startswith("-") else math.pi
    return float(v)


def fmt(v: SupportsFloat | str, angle: bool = False) -> str:
    """Compact number for titles, labels and captions (``%g``; a string stays as it is).  With
    ``angle=True`` a simple multiple of pi is written with pi: ``pi``, ``-pi/2``, ``3pi/4``
    (the one angle formatter of the command line and the pipeline's texts)."""
    if isinstance(v, str):
        return v
    x = float(v)
    if angle and x != 0:
        for den in (1, 2, 3, 4, 6):
            num = x / math.pi * den
            if abs(num - round(num)) < 1e-12:
                k = round(num)
                return f"{'-' if k < 0 else ''}{abs(k) if abs(k) != 1 else ''}pi{f'/{den}' if den > 1 else ''}"
    return f"{x:g}"


def range_values(r: Mapping[str, Any]) -> list[float]:
    """Values of a {start, stop, num} or {start, stop, step} range (endpoints included; a key
    set to null counts as absent)."""
    start, stop = float(r["start"]), float(r["stop"])
    vals: NDArray[np.floating[Any]]
    if r.get("num") is not None:
        vals = np.linspace(start, stop, int(r["num"]))
    else:
        step = float(r["step"])
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        vals = start + step * np.arange(n)
    # round away float noise (0.30000000000000004) so YAML files read well and stay stable
    return [float(np.round(v, 12)) for v in vals]


def values(v: Any) -> list[float]:
    """A scalar, a list or a range, as a list of floats."""
    if isinstance(v, dict):
        return range_values(v)
    return [float(x) for x in as_list(v)]


def grid(g: Mapping[str, Any]) -> dict[str, list[float] | list[int]]:
    """Resolved IC grid ``{q0: [lo, hi], p0: [lo, hi], n: [nq, np]}``."""
    n = g["n"]
    nq, np_ = (n, n) if isinstance(n, int) else (int(n[0]), int(n[1]))
    return {"q0": [float(g["q0"][0]), float(g["q0"][1])], "p0": [float(g["p0"][0]), float(g["p0"][1])],
            "n": [nq, np_]}


def grid_axes(g: Mapping[str, Any]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """1-D q0 and p0 axes of a resolved grid (endpoints included)."""
    nq, np_ = g["n"]
    return (np.linspace(g["q0"][0], g["q0"][1], nq), np.linspace(g["p0"][0], g["p0"][1], np_))


def box(b: Iterable[Sequence[SupportsFloat]]) -> list[list[float]]:
    return [[float(lo), float(hi)] for lo, hi in b]


def curve_lists(blk: Mapping[str, Any]) -> dict[str, list[Any]]:
    """The list-valued keys that make F_cr curves: xi_max, xi_ini, gamma_ini and, for a damped
    block (:func:`damping_param`), damping."""
    keys = ("xi_max", "xi_ini", "gamma_ini") + (("damping",) if damping_param(blk.get("damping", 0.0)) else ())
    return {k: as_list(blk[k]) for k in keys}


def curves(blk: Mapping[str, Any], with_psi: bool) -> list[dict[str, Any]]:
    """F_cr curves from list-valued xi_max / xi_ini / gamma_ini (and damping; equal lengths or
    length 1)."""
    lists = curve_lists(blk)
    n = max(len(v) for v in lists.values())
    varying = [k for k, v in lists.items() if len(v) > 1]
    out: list[dict[str, Any]] = []
    for i in range(n):
        c = {k: (v[i] if len(v) > 1 else v[0]) for k, v in lists.items()}
        xi_max, xi_ini, gamma_ini = float(c["xi_max"]), float(c["xi_ini"]), angle(c["gamma_ini"])
        label = ", ".join(f"{k} = {fmt(c[k])}" for k in varying) if varying else f"xi_max = {fmt(xi_max)}"
        cur: dict[str, Any] = {"label": label, "xi_max": xi_max, "xi_ini": xi_ini, "gamma_ini": gamma_ini}
        if "damping" in c:
            cur["damping"] = float(c["damping"])
        if with_psi:
            cur["Psi"] = angle(blk["Psi"])
        out.append(cur)
    return out


def tile_slice(n: int, tiles: int, tile: int) -> slice:
    """Contiguous block ``tile`` (0-based) of ``tiles`` nearly equal blocks of range(n)."""
    if not 0 <= tile < tiles:
        raise ValueError(f"tile must lie in [0, {tiles}), got {tile}")
    edges = np.linspace(0, n, tiles + 1).round().astype(int)
    return slice(int(edges[tile]), int(edges[tile + 1]))


def well(params: Mapping[str, Any], fourier: str | None = None) -> Well:
    """The well object of resolved parameters (``params["well"]``, a spec of
    :func:`safebasins.wells.spec_of`) with the experiment's first harmonic (``fourier``: one
    variant of a list-valued ``params["fourier"]``; numeric-only kinds have none)."""
    from safebasins import wells

    # kinds without a first harmonic (numerics only: no "fourier" parameter) get the default one
    return wells.from_spec(params["well"], params.get("fourier") if fourier is None else fourier)


def base_well(params: Mapping[str, Any]) -> Well:
    """The well of resolved parameters for the numerics (which have no first harmonic) and for
    library calls that loop over the variants of a list-valued ``params["fourier"]`` themselves
    (the quartic with eq (20) as printed; safebasins.analysis.common.variant_well picks each)."""
    from safebasins import wells

    return wells.from_spec(params["well"])


def damping_param(beta: float | list[float]) -> dict[str, float | list[float]]:
    """``{"damping": beta}`` (a float, or a list for kinds whose curves vary it) of an experiment
    with damping; nothing for the undamped equation, whose parameter files (and datasets) stay
    the paper's: no ``damping`` parameter means beta = 0."""
    vals = [float(b) for b in as_list(beta)]
    if not any(b > 0 for b in vals):
        return {}
    return {"damping": vals if isinstance(beta, list) else vals[0]}


def damping(params: Mapping[str, Any]) -> float:
    """The damping beta of resolved parameters (0 for the undamped equation; :func:`damping_param`)."""
    beta = params.get("damping", 0.0)
    if isinstance(beta, list):
        raise ValueError(f"experiment {params['experiment']!r}: damping is a list of curves' values here")
    return float(beta)
