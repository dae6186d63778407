"""One slow trajectory of the (damped) slow flow, integrated with the well's exact functions.

The per-IC reference of :mod:`safebasins.theory.damped_flow` (same decisions: escape at xi_max,
trapping ellipse, trapping loop, undecided at t_max), with SciPy's DOP853 on
:func:`safebasins.theory.damped.rhs_exact` (xi from J by Newton on the exact J(xi), no tables)
and event location for the escape, the ellipses and the pivots' rays.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray
from scipy import integrate

from safebasins.core import checks
from safebasins.core.checks import check_finite, check_positive, check_scalar
from safebasins.theory.damped import forcing_and_level, from_tilde, rhs_exact, to_tilde
from safebasins.theory.damped_flow import Pivots, default_t_max, pivots
from safebasins.theory.types import FloatArray, WellArg
from safebasins.wells import resolve_well
from safebasins.wells.provenance import api_provenance

__all__ = ["slow_trajectory"]

OUTCOMES = ("settled", "escaped", "undecided", "bounded")


Flow = Callable[[float, Any], tuple[FloatArray, FloatArray]]
Index = int | np.integer[Any]


def _crossings(sol: Any, pv: Pivots, k_list: list[Index], first: int, f: Flow) -> list[tuple[float, Index, float, int]]:
    """Ray crossings (t, k, rho, direction) of one solve_ivp chunk, in time order (the rays'
    events are ``sol.t_events[first:]``)."""
    out: list[tuple[float, Index, float, int]] = []
    for j, k in enumerate(k_list):
        te, ye = sol.t_events[first + j], sol.y_events[first + j]
        for t, y in zip(te, ye):
            dx, dy = y[0] - pv.x[0, k], y[1] - pv.y[0, k]
            rho = pv.ux[0, k] * dx + pv.uy[0, k] * dy
            if rho <= 0:
                continue
            fx, fy = f(t, y)
            d = 1 if pv.ux[0, k] * fy - pv.uy[0, k] * fx > 0 else -1
            out.append((t, k, rho, d))
    return sorted(out)


def _transversal(pv: Pivots, k: Index, rho0: float, rho1: float, d: int, f: Flow) -> bool:
    for s in np.linspace(0.0, 1.0, 9):
        r = rho0 + s * (rho1 - rho0)
        fx, fy = f(0.0, (pv.x[0, k] + r * pv.ux[0, k], pv.y[0, k] + r * pv.uy[0, k]))
        if (pv.ux[0, k] * fy - pv.uy[0, k] * fx) * d <= 0:
            return False
    return True


@api_provenance
def slow_trajectory(xi_ini: float, gamma_ini: float, F: float, Omega: float, xi_max: float, damping: float = 0.0,
                    well: WellArg = None, fourier: str | None = None, t_max: float | None = None,
                    rtol: float = 1e-10, atol: float = 1e-12) -> xr.Dataset:
    """Integrate the damped slow flow (docs/damping.md) from ``(gamma_ini, xi_ini)`` until it reaches
    ``xi_max`` or settles, with the well's exact functions (DOP853, events).

    Parameters
    ----------
    xi_ini, gamma_ini : float
        Initial averaged energy (``0 <= xi_ini``) and slow phase (gamma = theta - Psi - Omega tau).
    F, Omega, xi_max : float
        Forcing amplitude (>= 0), frequency (> 0), energy threshold.
    damping : float
        beta >= 0.  With beta = 0 (the paper's flow) a trajectory that closes a loop round a centre
        is reported ``bounded`` (it is periodic).
    well, fourier : the potential (default the paper's quartic with eq (20)'s G).
    t_max : float, optional
        Slow-time horizon (default :func:`~safebasins.theory.damped_flow.default_t_max`).

    Returns
    -------
    xarray.Dataset
        over ``t`` (slow time in tau, the solver's steps): ``gamma``, ``xi``, ``J``.  attrs:
        ``outcome`` ("escaped" | "settled" | "bounded" | "undecided" -- check it: an undecided
        trajectory is not safe), ``detection`` (how it was decided), ``t_end``,
        ``attractor_xi``, ``attractor_gamma`` (the attracting fixed point it settles on, NaN
        otherwise), and the parameters.
    """
    w = resolve_well(well, fourier)
    beta = checks.check_damping(damping)
    x0 = check_scalar("xi_ini", xi_ini, lambda n, v: w.check_energy(n, v))
    g0 = check_scalar("gamma_ini", gamma_ini, check_finite)
    F, Om, xm, tab = forcing_and_level(w, F, Omega, xi_max)
    pv = pivots(tab, np.array([F]), np.array([Om]), beta, xm)
    T = float(default_t_max(pv, max(beta, 1e-300))[0]) if t_max is None else \
        check_scalar("t_max", t_max, check_positive)
    J_max = float(w.J(np.asarray(xm)))

    def f(t: float, y: Any) -> tuple[FloatArray, FloatArray]:
        return rhs_exact(w, np.asarray(y[0]), np.asarray(y[1]), F, Om, beta)

    def esc(t: float, y: NDArray[np.float64]) -> float:
        out: float = 0.5 * (y[0] * y[0] + y[1] * y[1]) - J_max
        return out
    esc.terminal, esc.direction = True, 1  # type: ignore[attr-defined]  # read by solve_ivp
    events: list[Callable[..., float]] = [esc]
    ell_k: list[Index] = []
    ray_k: list[Index] = []
    k: Index
    for k in np.nonzero(pv.valid[0])[0]:
        if pv.c[0, k] > 0:
            def ell(t: float, y: NDArray[np.float64], k: Index = k) -> float:
                dx, dy = y[0] - pv.x[0, k], y[1] - pv.y[0, k]
                out: float = pv.p11[0, k] * dx * dx + 2 * pv.p12[0, k] * dx * dy + pv.p22[0, k] * dy * dy - pv.c[0, k]
                return out
            ell.terminal, ell.direction = True, -1  # type: ignore[attr-defined]  # read by solve_ivp
            events.append(ell)
            ell_k.append(k)
    for k in np.nonzero(pv.valid[0])[0]:
        def ray(t: float, y: NDArray[np.float64], k: Index = k) -> float:
            out: float = pv.ux[0, k] * (y[1] - pv.y[0, k]) - pv.uy[0, k] * (y[0] - pv.x[0, k])
            return out
        events.append(ray)
        ray_k.append(k)

    y = np.array(to_tilde(w, g0, x0), float)
    ts, ys = [np.zeros(1)], [y[:, None]]
    t0, outcome, detection, t_end, att = 0.0, "undecided", f"neither within t_max = {T!r}", T, -1
    last: dict[Index, tuple[float, int]] = {}
    if 0.5 * float(y @ y) >= J_max:
        outcome, detection, t_end = "escaped", "starts at or above xi_max", 0.0
    for j, k in enumerate(ell_k):
        if outcome == "undecided" and events[1 + j](0.0, y) <= 0:
            outcome, t_end, att = "settled", 0.0, int(pv.index[0, k])
            detection = f"starts in the trapping ellipse of the fixed point {att}"
    chunk = max(10.0 * float(pv.t_scale[0]), 1.0)
    while outcome == "undecided" and t0 < T:
        t1 = min(t0 + chunk, T)
        sol = integrate.solve_ivp(f, (t0, t1), y, method="DOP853", rtol=rtol, atol=atol, events=events)
        stop = sol.t[-1]
        for t, k, rho, d in _crossings(sol, pv, ray_k, 1 + len(ell_k), f):
            prev = last.get(k)
            last[k] = (rho, d)
            if prev is None or prev[1] != d:
                continue
            closed = rho < prev[0] if beta > 0 else abs(rho - prev[0]) <= 1e-6 * prev[0]
            if closed and _transversal(pv, k, rho, prev[0], d, f):
                outcome = "settled" if beta > 0 else "bounded"
                detection = f"closed a trapping loop round the fixed point {int(pv.index[0, k])}"
                t_end, att, stop = t, int(pv.index[0, k]), t
                break
        if outcome == "undecided" and sol.status == 1:
            if sol.t_events[0].size:
                outcome, detection, t_end = "escaped", "reached xi_max", float(sol.t_events[0][0])
            else:
                j = next(i for i in range(len(ell_k)) if sol.t_events[1 + i].size)
                outcome = "settled"
                detection = f"entered the trapping ellipse of the fixed point {int(pv.index[0, ell_k[j]])}"
                t_end, att = float(sol.t_events[1 + j][0]), int(pv.index[0, ell_k[j]])
            stop = t_end
        keep = (sol.t > t0) & (sol.t <= stop)
        ts.append(sol.t[keep])
        ys.append(sol.y[:, keep])
        y, t0 = sol.y[:, -1], sol.t[-1]
        if not sol.success:
            detection = f"solver failed: {sol.message}"
            break
    t_all = np.concatenate(ts)
    Y = np.concatenate(ys, axis=1)
    if outcome == "undecided":
        t_end = float(t_all[-1])
    gam, xi = from_tilde(w, Y[0], Y[1])
    fp = pv.fp
    ax = float(fp.xi[0, att]) if att >= 0 else np.nan
    ag = float(fp.gamma[0, att]) if att >= 0 else np.nan
    return xr.Dataset(
        {"gamma": ("t", gam, {"units": "rad", "long_name": "slow phase gamma = theta - Psi - Omega tau"}),
         "xi": ("t", xi, {"units": "1", "long_name": "averaged energy"}),
         "J": ("t", 0.5 * (Y[0] ** 2 + Y[1] ** 2), {"units": "1", "long_name": "averaged action"})},
        coords={"t": ("t", t_all, {"units": "1", "long_name": "slow time (tau)"})},
        attrs={"outcome": outcome, "detection": detection, "t_end": float(t_end), "attractor_xi": ax,
               "attractor_gamma": ag, "xi_ini": x0, "gamma_ini": g0, "F": F, "Omega": Om, "xi_max": xm,
               "damping": beta, "t_max": T, "well": w.name, "fourier": w.fourier,
               "description": "slow trajectory of the damped slow flow, docs/damping.md"})
