"""Safe-basin boundaries on the RM and in the IC plane (paper Sec. 2.3, eqs 27-28).

With ``a(xi) = C(0, xi)``, ``b(xi) = C(pi, xi)`` and their suffix extrema
``A*(xi) = max_[xi, xi_max] a``, ``B*(xi) = min_[xi, xi_max] b`` (see
:mod:`safebasins.theory.slow_flow`), a point (gamma, xi) is safe iff
``C(gamma, xi) < A*(xi)`` (safe on the gamma = 0 side) or ``C(gamma, xi) > B*(xi)``
(safe on the gamma = pi side).  Where ``A*(xi) > a(xi)``, ``A*`` is constant and equal to
``a`` at the upper end of that xi-interval, which is either

* ``xi_max`` — the level of the tangency at gamma* = 0 (eq 27): boundary of maximum type, or
* an interior local maximum of ``a`` — a saddle on gamma = 0 (eq 28): boundary of saddle type;

likewise for ``B*`` with gamma* = pi.  Each boundary is the level curve ``C = C_level``
restricted to that xi-interval, ``cos(gamma) = (h(xi) - C_level) / (F G(xi))``; it is traced
as a function of xi (upper branch gamma >= 0 with xi ascending, then the mirror branch
gamma <= 0 with xi descending).

Kinds (paper Sec. 2.3):

* ``"saddle"``   boundary through a saddle (SBST, eq 28);
* ``"island"``   maximum type (SBMT) whose ends both lie on the same ray as its tangency point —
  a closed curve that does not wrap the phase cylinder (the LPT-bounded basin, C_level = 0
  through the well bottom, is the special island case);
* ``"peninsula"`` maximum type whose curve runs from one ray to the other, i.e. wraps around
  the cylinder; the safe region lies between it and the circle xi = 0.

Several boundaries can coexist (Fig 9: a saddle-type boundary on the gamma = 0 side and an
island on the gamma = pi side) and the basin can be disjoint (Fig 14, e.g. F = 0.01,
Omega = 0.9, Psi = pi, xi_max = 0.13 ... 0.18).  At ``xi_max = 1/4`` every point is safe in the
slow flow (G(1/4) = 0); the curves returned there are the measure-zero level ``C = h(1/4)``.
The paper's text after eq (27) refers to "the curve (28)" for islands/peninsulas; it means the
SBMT boundary (27).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray
from scipy import optimize

from safebasins.core.checks import check_finite, check_nonnegative, check_positive, check_positive_int, check_scalar
from safebasins.theory.profile import SlowFlowProfile, resolved_shift, unshear, xi_grid
from safebasins.theory.types import BoolArray, FloatArray, WellArg
from safebasins.wells import resolve_well
from safebasins.wells.provenance import api_provenance

__all__ = ["safe_basin_boundaries"]


def _runs(mask: BoolArray) -> list[tuple[int, int]]:
    """(start, stop) index pairs (stop exclusive) of consecutive True in a 1-D bool array."""
    m = np.concatenate([[False], mask, [False]]).astype(int)
    d = np.diff(m)
    return list(zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0]))


def _root(fun: Callable[[float], float], lo: float, hi: float) -> float:
    flo, fhi = fun(lo), fun(hi)
    if flo == 0:
        return lo
    if fhi == 0:
        return hi
    if flo * fhi > 0:
        return lo if abs(flo) < abs(fhi) else hi
    return float(optimize.brentq(fun, lo, hi, xtol=1e-15, rtol=1e-14))


def _side_curves(prof: SlowFlowProfile, side: int, n_points: int) -> list[dict[str, Any]]:
    """Boundary curves on one side (0: gamma = 0 side via a/A*, 1: gamma = pi side via b/B*)."""
    F, Om, w = prof.F, prof.Omega, prof.well
    xi = prof.xi
    f_own = prof.a if side == 0 else prof.b            # the side's own ray function
    f_opp = prof.b if side == 0 else prof.a
    S = prof.A if side == 0 else prof.B               # suffix extremum
    sgn = 1.0 if side == 0 else -1.0                   # A* > a  <=>  sgn*(S - f) > 0
    scale = max(F * float(np.max(prof.Gv)), 1e-300)
    tol = 1e-13 * scale
    mask = sgn * (S - f_own) > tol
    n = xi.size

    def own(x: float, L: float) -> float:
        h = x - Om * w.J(x)
        g = F * w.harmonic_amplitude(x)
        return float((h - g if side == 0 else h + g) - L)

    def opp(x: float, L: float) -> float:
        h = x - Om * w.J(x)
        g = F * w.harmonic_amplitude(x)
        return float((h + g if side == 0 else h - g) - L)

    curves: list[dict[str, Any]] = []
    for i0, i1 in _runs(mask):
        u = i1                                          # upper end node: f_own(u) == level
        if u >= n:                                      # cannot happen (S == f at the last node)
            continue
        L = float(S[i0])
        saddle = u != n - 1
        # lower end: where f_own crosses L between nodes i0-1 and i0 (or xi = 0)
        xl = xi[0] if i0 == 0 else _root(lambda x: own(x, L), xi[i0 - 1], xi[i0])
        xu = xi[u]
        # the curve exists where the opposite-ray function is on the far side of L
        ok = sgn * (f_opp[i0:u] - L) >= 0              # side 0: b >= L ; side 1: a <= L
        nodes = np.concatenate([[xl], xi[i0:u], [xu]])
        okn = np.concatenate([[True], ok, [True]])
        okn[0] = okn[-1] = True                        # own-ray end points: cos(gamma) = +-1
        for j0, j1 in _runs(okn):
            lo_on_own = j0 == 0
            hi_on_own = j1 == nodes.size
            # run ends strictly inside: the curve reaches the opposite ray there
            lo = nodes[j0] if lo_on_own else _root(lambda x: opp(x, L), nodes[j0 - 1], nodes[j0])
            hi = nodes[j1 - 1] if hi_on_own else _root(lambda x: opp(x, L), nodes[j1 - 1], nodes[j1])
            if hi <= lo:
                continue
            x = xi_grid(lo, hi, n_points)
            h = x - Om * w.J(x)
            g = F * w.harmonic_amplitude(x)
            with np.errstate(divide="ignore", invalid="ignore"):
                cg = np.where(g > 0, (h - L) / g, 0.0)
            gam = np.arccos(np.clip(cg, -1.0, 1.0))
            # exact end values
            gam[0] = (0.0 if side == 0 else np.pi) if lo_on_own else (np.pi if side == 0 else 0.0)
            gam[-1] = (0.0 if side == 0 else np.pi) if hi_on_own else (np.pi if side == 0 else 0.0)
            if lo_on_own and x[0] == 0.0:
                gam[0] = np.arccos(np.clip(cg[1], -1, 1)) if g[1] > 0 else 0.5 * np.pi
            if saddle:
                kind = "saddle"
            else:   # LPT (x[0] == 0, through the well bottom) counts as an island
                kind = "island" if lo_on_own == hi_on_own else "peninsula"
            gv = np.concatenate([gam, -gam[::-1]])
            xv = np.concatenate([x, x[::-1]])
            curves.append(dict(kind=kind, level=L, gamma=gv, xi=xv,
                               ray=0.0 if side == 0 else np.pi, saddle=saddle,
                               xi_top=float(xu), safe_sign=-1 if side == 0 else 1))
    return curves


@api_provenance
def safe_basin_boundaries(F: float, Omega: float, Psi: float, xi_max: float, fourier: str | None = None,
                          n_points: int = 400, well: WellArg = None) -> xr.Dataset:
    """Boundaries of the analytic safe basin (paper Sec. 2.3, eqs 27-28).

    Parameters
    ----------
    F, Omega, Psi, xi_max : float
        Forcing amplitude (>= 0), frequency (> 0), phase, truncation energy in (0, 1/4].
    fourier : "paper" | "exact"
        Which G (eq 20) of the quartic (default "paper").
    well : safebasins.wells.Well
        The potential (default: the paper's quartic).  Curves are traced on the sheared rays
        gamma + delta(xi) = 0, pi of a well whose first harmonic has a phase delta(xi) and
        returned in the slow phase gamma itself.
    n_points : int
        Samples in xi per branch of each curve (each curve has 2 * n_points vertices, plus
        NaN separator rows where it crosses gamma = +-pi).

    Returns
    -------
    xarray.Dataset with
      dim ``curve``: ``kind`` (str: island | peninsula | saddle), ``C_level`` (value of C, eq 18,
      on the curve), ``ray`` (0 or pi: the ray of its tangency / saddle point), ``xi_top``
      (energy of that point: xi_max for maximum type, xi of the saddle for saddle type),
      ``safe_sign`` (-1: the safe side is C < C_level, i.e. towards gamma = 0; +1: C > C_level);
      dim ``vertex``: ``gamma`` (in [-pi, pi]), ``xi``, ``q0_vertex``, ``p0_vertex`` (the vertex in
      the IC plane, via eqs 15, 17 with theta0 = gamma + Psi; named apart from the grid axes
      ``q0``, ``p0`` of the masks stored beside them), ``curve_index`` (int; consecutive vertices of one curve form a
      polyline; NaN rows split it where it crosses gamma = +-pi).
      attrs: F, Omega, Psi, xi_max, fourier, saddle_gamma, saddle_xi (the saddle below xi_max
      whose level bounds the basin, else the lowest saddle below xi_max, else NaN; located by
      Brent's method on dC/dxi = 0 along the ray, cf. Newton-Raphson in Sec. 3.2).
    """
    w = resolve_well(well, fourier)
    F = check_scalar("F", F, check_nonnegative)
    Om = check_scalar("Omega", Omega, check_positive)
    Psi = check_scalar("Psi", Psi, check_finite)
    xm = check_scalar("xi_max", xi_max, w.check_analytic_threshold)
    n_points = check_positive_int("n_points", n_points)
    if n_points < 3:
        raise ValueError("n_points must be >= 3")
    prof = SlowFlowProfile(F, Om, xm, w)
    curves = []
    if F > 0:
        curves = _side_curves(prof, 0, n_points) + _side_curves(prof, 1, n_points)

    # saddle attributes
    sad = [(0.0, float(x)) for x in prof.a_max if x < xm] + \
          [(np.pi, float(x)) for x in prof.b_min if x < xm]
    bind = [(c["ray"], c["xi_top"]) for c in curves if c["saddle"]]
    if bind:
        sg, sx = min(bind, key=lambda t: t[1])
    elif sad:
        sg, sx = min(sad, key=lambda t: t[1])
    else:
        sg, sx = np.nan, np.nan
    if np.isfinite(sx) and resolved_shift(w, sx) != 0:
        sg = unshear(sg, resolved_shift(w, sx))

    gam_parts: list[FloatArray] = []
    xi_parts: list[FloatArray] = []
    idx_parts: list[NDArray[np.int64]] = []
    for k, c in enumerate(curves):
        g, x = c["gamma"], c["xi"]
        shift = resolved_shift(w, np.minimum(x, w.barrier_energy))
        if np.any(shift != 0):  # back from the sheared rays to the slow phase
            g = unshear(g, shift)
            c["ray"] = float(unshear(c["ray"], resolved_shift(w, c["xi_top"])))
        jump = np.nonzero(np.abs(np.diff(g)) > np.pi)[0]
        if jump.size:
            g = np.insert(g, jump + 1, np.nan)
            x = np.insert(x, jump + 1, np.nan)
        gam_parts.append(g)
        xi_parts.append(x)
        idx_parts.append(np.full(g.size, k, dtype=np.int64))
    gam: FloatArray
    xis: FloatArray
    idx: NDArray[np.int64]
    if curves:
        gam, xis, idx = np.concatenate(gam_parts), np.concatenate(xi_parts), np.concatenate(idx_parts)
    else:
        gam, xis, idx = np.empty(0), np.empty(0), np.empty(0, np.int64)
    fin = np.isfinite(gam)
    q0 = np.full(gam.shape, np.nan)
    p0 = np.full(gam.shape, np.nan)
    if fin.any():
        q0[fin], p0[fin] = w.phase_point(gam[fin] + Psi, np.minimum(xis[fin], np.nextafter(w.barrier_energy, 0)))

    ds = xr.Dataset(
        {
            "kind": ("curve", np.array([c["kind"] for c in curves], dtype=object).astype(str)
                     if curves else np.array([], dtype=str),
                     {"long_name": "safe-basin boundary type (island | peninsula | saddle)"}),
            "C_level": ("curve", np.array([c["level"] for c in curves], float),
                        {"units": "1", "long_name": "value of the first integral C (eq 18) on the boundary"}),
            "ray": ("curve", np.array([c["ray"] for c in curves], float),
                    {"units": "rad", "long_name": "slow phase of the tangency or saddle point"}),
            "xi_top": ("curve", np.array([c["xi_top"] for c in curves], float),
                       {"units": "1", "long_name": "energy of the tangency or saddle point"}),
            "safe_sign": ("curve", np.array([c["safe_sign"] for c in curves], np.int8),
                          {"long_name": "safe side: -1 where C < C_level, +1 where C > C_level"}),
            "gamma": ("vertex", gam, {"units": "rad", "long_name": "slow phase gamma = theta - Psi - Omega tau"}),
            "xi": ("vertex", xis, {"units": "1", "long_name": "averaged energy"}),
            "q0_vertex": ("vertex", q0, {"units": "1", "long_name": "initial displacement"}),
            "p0_vertex": ("vertex", p0, {"units": "1", "long_name": "initial momentum"}),
            "curve_index": ("vertex", idx, {"long_name": "index of the curve a vertex belongs to"}),
        },
        attrs={"F": F, "Omega": Om, "Psi": Psi, "xi_max": xm, "fourier": w.fourier, "well": w.name,
               "saddle_gamma": float(sg), "saddle_xi": float(sx),
               "description": "analytic safe-basin boundaries, Karmi et al. Sec. 2.3 (eqs 27-28)"},
    )
    return ds
