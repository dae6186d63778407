"""Escape in the damped slow flow: safe initial conditions and the critical forcing (docs/damping.md).

With damping the level curves of C (eq 18) no longer are the slow trajectories (``C' = -beta J
gamma'``), so eqs (21)-(26) do not apply: an IC is classified by following its slow trajectory
(:func:`safebasins.theory.damped_flow.integrate_batch`) until it reaches ``xi_max`` (escaped) or is
certified to settle on an attractor below it (trapping ellipse or trapping loop; for beta > 0 the
flow has no periodic orbit).  A trajectory decided by neither within the horizon is *undecided*:
it is reported, never counted as safe.

* :func:`slow_flow_outcomes`: the outcome (settled / escaped / undecided) of initial conditions
  ``(q0, p0)`` at tau = 0; :func:`safebasins.theory.slow_flow_escapes` with ``damping > 0`` is
  ``outcome != settled``.
* :func:`damped_critical_forcing` (``critical_forcing(..., damping > 0)``): the smallest F for
  which the slow trajectory from ``(gamma_ini, xi_ini)`` reaches xi_max, by a scan in F and
  bisection.  A necessary condition gives the scan's floor: at the crossing of ``J = J(xi_max)``
  the action grows, ``J' = -F A sin(phi) - beta J > 0``, so ``F > F_min = beta J(xi_max) /
  A(xi_max)``.
"""
from __future__ import annotations

import warnings

from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from safebasins.core import checks
from safebasins.core.checks import check_finite, check_scalar
from safebasins.theory.damped import SlowTables, forcing_and_level, slow_tables, to_tilde
from safebasins.theory.damped_flow import ESCAPED, SETTLED, STATUS, UNDECIDED, default_t_max, integrate_batch, pivots
from safebasins.theory.types import BoolArray, FloatArray, WellArg
from safebasins.wells import resolve_well
from safebasins.wells.base import Well

__all__ = ["slow_flow_outcomes", "damped_critical_forcing", "UndecidedWarning"]


class UndecidedWarning(RuntimeWarning):
    """Some slow trajectories were neither certified to settle nor seen to escape within the horizon
    (counted as escaping, never as safe)."""


def _decide(tab: SlowTables, X0: FloatArray, Y0: FloatArray, F: FloatArray, Om: FloatArray, beta: float, xm: float,
            pair: NDArray[np.intp], t_factor: float = 1.0,
            retry: float = 10.0) -> tuple[NDArray[np.int8], FloatArray, FloatArray]:
    """Status codes (:data:`~safebasins.theory.damped_flow.STATUS`) of trajectories from (X0, Y0)
    (sheared frame) for parameter pairs (F, Om) (1-D; ``pair``: each lane's pair), with the lanes
    still undecided after the default horizon tried once more with ``retry`` times that horizon.
    Returns ``(status, t_end, attractor_xi)``."""
    pv = pivots(tab, F, Om, beta, xm)
    T = t_factor * default_t_max(pv, beta)
    status, t_end, att, _ = integrate_batch(tab, X0, Y0, F, Om, beta, xm, pv, pair, T)
    und = np.nonzero(status == UNDECIDED)[0]
    if und.size and retry > 1:
        s2, t2, a2, _ = integrate_batch(tab, X0[und], Y0[und], F, Om, beta, xm, pv, pair[und], retry * T)
        status[und], t_end[und], att[und] = s2, t2, a2
    fp_xi = pv.fp.xi[pair, np.maximum(att, 0)]
    return status, t_end, np.where(att >= 0, fp_xi, np.nan)


def slow_flow_outcomes(q0: ArrayLike, p0: ArrayLike, F: float, Omega: float, Psi: float, xi_max: float,
                       damping: float, fourier: str | None = None, well: WellArg = None) -> NDArray[np.int8]:
    """Where the damped slow trajectory of each initial condition ``(q0, p0)`` (tau = 0) goes.

    The IC is mapped to ``(theta0, xi_ini)`` (eqs 7, 14), ``gamma_ini = theta0 - Psi``, and its
    trajectory of the damped slow flow (docs/damping.md) followed until it reaches ``xi_max`` or is
    certified to settle below it.  Broadcasts q0 and p0; F, Omega, Psi, xi_max, damping (> 0) are
    scalars.

    Returns
    -------
    numpy.ndarray of int8
        0 = settled (safe), 1 = escaped (ICs at or above xi_max or beyond a barrier included),
        2 = undecided within 10 times the default horizon (not safe, not escaped: check for it).
    """
    w = resolve_well(well, fourier)
    beta = checks.check_damping(damping)
    if beta <= 0:
        raise ValueError("damping must be > 0 here (damping = 0 is the conservative slow flow: "
                         "slow_flow_escapes)")
    qc = check_finite("q0", q0)
    pc = check_finite("p0", p0)
    psi = check_scalar("Psi", Psi, check_finite)
    f, Om, xm, tab = forcing_and_level(w, F, Omega, xi_max)
    q, p = np.broadcast_arrays(qc, pc)
    out = np.full(q.shape, ESCAPED, np.int8)
    inside = w.in_well(q) & (w.H0(q, p) < xm)
    if inside.any():
        theta, xi = w.angle_energy(q[inside], p[inside])
        X0, Y0 = to_tilde(w, theta - psi, xi)
        status, _, _ = _decide(tab, np.ravel(X0), np.ravel(Y0), np.array([f]), np.array([Om]), beta, xm,
                               np.zeros(np.size(X0), np.intp))
        out[inside] = status
    return out


def damped_escapes(q0: ArrayLike, p0: ArrayLike, F: float, Omega: float, Psi: float, xi_max: float, damping: float,
                   fourier: str | None = None, well: WellArg = None) -> BoolArray:
    """:func:`slow_flow_outcomes` as the bool array of :func:`~safebasins.theory.slow_flow_escapes`
    (True = not settled); undecided ICs count as escaping, with an :class:`UndecidedWarning`."""
    status = slow_flow_outcomes(q0, p0, F, Omega, Psi, xi_max, damping, fourier=fourier, well=well)
    n = int(np.count_nonzero(status == UNDECIDED))
    if n:
        warnings.warn(f"{n} of {status.size} slow trajectories undecided (neither settled nor escaped within "
                      "the horizon): counted as escaping; slow_flow_outcomes reports them", UndecidedWarning,
                      stacklevel=3)
    out: BoolArray = status != SETTLED
    return out


def _escape_status(tab: SlowTables, X0: float, Y0: float, F: FloatArray, Om: FloatArray, beta: float,
                   xm: float) -> tuple[NDArray[np.int8], FloatArray, FloatArray]:
    """Status of the trajectory from (X0, Y0) at each (F, Om) pair (1-D arrays), with attractors."""
    return _decide(tab, np.full(F.size, X0), np.full(F.size, Y0), F, Om, beta, xm, np.arange(F.size))


def damped_critical_forcing(Omega: ArrayLike, xi_max: float, xi_ini: float, gamma_ini: float, damping: float,
                            well: Well, n_scan: int = 48, rtol: float = 1e-7,
                            F_undamped: FloatArray | None = None) -> xr.Dataset:
    """F_cr of the damped slow flow for validated arguments (``critical_forcing(..., damping > 0)``).

    For each Omega: a scan of ``n_scan`` geometric F values on ``[max(F_min, 0.3 F0), 2.5 F0 + F_min]``
    (F0: the undamped F_cr, or 4 F_min where it is NaN; the interval is moved down while its lowest
    value escapes and up, doubling, at most 8 times while none does), then bisection between the
    largest settling F below the first escaping one and that one, to a relative width ``rtol``.
    An escape window narrower than the scan's spacing below the first escaping scan value is missed.
    Cost: about 0.2 s per Omega at xi_max = 0.2 of the quartic; xi_max at the barrier energy is
    slow (cubic, xi_max = 1/6: 400 s for two Omega): near the separatrix omega ~ 1/log and dA/dxi
    diverge, and the trajectories that graze it need tens of thousands of steps.
    """
    if F_undamped is None:
        raise ValueError("F_undamped: the undamped F_cr per Omega seeds the scan (critical_forcing passes it)")
    w, beta = well, damping
    tab = slow_tables(w)
    xm = min(xi_max, tab.xi_top)
    Om = np.asarray(Omega, float)
    nO = Om.size
    X0, Y0 = (float(v) for v in to_tilde(w, gamma_ini, np.asarray(xi_ini)))
    F_min = beta * float(w.J(np.asarray(xm))) / float(w.harmonic_amplitude(np.asarray(xm)))
    F0 = np.where(np.isfinite(F_undamped), F_undamped, 4.0 * F_min)
    lo_end = np.maximum(F_min * (1 + 1e-9), 0.3 * F0)
    hi_end = 2.5 * F0 + F_min
    F_lo = np.full(nO, np.nan)            # largest F known to settle below the first escape
    F_hi = np.full(nO, np.nan)            # smallest F known to escape
    undecided = np.zeros(nO, bool)
    todo = np.ones(nO, bool)
    for _ in range(12):
        rows = np.nonzero(todo)[0]
        if not rows.size:
            break
        s = np.linspace(0.0, 1.0, n_scan)
        Fs = lo_end[rows, None] * (hi_end[rows, None] / lo_end[rows, None]) ** s[None, :]
        st, _, _ = _escape_status(tab, X0, Y0, Fs.ravel(), np.repeat(Om[rows], n_scan), beta, xm)
        st = st.reshape(rows.size, n_scan)
        esc = st == ESCAPED
        for j, r in enumerate(rows):
            if not esc[j].any():
                if hi_end[r] > 300 * F0[r]:
                    todo[r] = False                          # never escapes in range: NaN
                    undecided[r] = (st[j] == UNDECIDED).any()
                else:
                    lo_end[r], hi_end[r] = hi_end[r], 2.0 * hi_end[r]
                continue
            k = int(np.argmax(esc[j]))
            if k == 0 and lo_end[r] > F_min * (1 + 1e-6):
                hi_end[r] = lo_end[r]
                lo_end[r] = max(F_min * (1 + 1e-9), 0.3 * lo_end[r])
                continue
            todo[r] = False
            F_hi[r] = Fs[j, k]
            F_lo[r] = Fs[j, k - 1] if k > 0 else F_min
            undecided[r] = (st[j, :k] == UNDECIDED).any()
    rows = np.nonzero(np.isfinite(F_hi) & ~undecided)[0]
    for _ in range(200):
        rows = rows[(F_hi[rows] - F_lo[rows]) > rtol * F_hi[rows]]
        if not rows.size:
            break
        mid = 0.5 * (F_lo[rows] + F_hi[rows])
        st, _, _ = _escape_status(tab, X0, Y0, mid, Om[rows], beta, xm)
        e, u = st == ESCAPED, st == UNDECIDED
        F_hi[rows] = np.where(e, mid, F_hi[rows])
        F_lo[rows] = np.where(~e & ~u, mid, F_lo[rows])
        undecided[rows[u]] = True
        rows = rows[~u]
    ok = np.isfinite(F_hi) & ~undecided
    F_cr = np.where(ok, F_hi, np.nan)
    # where the trajectory settles just below F_cr, and how long the escape at F_cr takes
    att = np.full(nO, np.nan)
    t_esc = np.full(nO, np.nan)
    done = np.nonzero(ok)[0]
    if done.size:
        st, t_end, a = _escape_status(tab, X0, Y0, np.concatenate([F_lo[done], F_hi[done]]), np.tile(Om[done], 2),
                                      beta, xm)
        att[done] = np.where(st[:done.size] == SETTLED, a[:done.size], np.nan)
        t_esc[done] = np.where(st[done.size:] == ESCAPED, t_end[done.size:], np.nan)

    def var(values: ArrayLike, long_name: str, units: str = "1") -> tuple[str, Any, dict[str, str]]:
        return ("Omega", values, {"units": units, "long_name": long_name})

    return xr.Dataset(
        {"F_cr": var(F_cr, "critical forcing amplitude (damped slow flow)"),
         "F_settle": var(np.where(ok, F_lo, np.nan), "largest F below F_cr at which the slow trajectory settles"),
         "F_cr_undamped": var(np.asarray(F_undamped, float), "critical forcing of the undamped slow flow (eqs 22-26)"),
         "F_min": var(np.full(nO, F_min), "necessary condition beta J(xi_max) / A(xi_max)"),
         "xi_attractor": var(att, "averaged energy of the attractor reached just below F_cr"),
         "t_escape": var(t_esc, "slow time (tau) to reach xi_max at F_cr"),
         "undecided": ("Omega", undecided, {"long_name": "an undecided slow trajectory left F_cr unknown (NaN)"})},
        coords={"Omega": ("Omega", Om, {"units": "1", "long_name": "forcing frequency"})},
        attrs={"xi_max": float(xi_max), "xi_ini": float(xi_ini), "gamma_ini": float(gamma_ini), "damping": beta,
               "fourier": w.fourier, "well": w.name, "rtol": rtol, "n_scan": n_scan,
               "outcomes": " ".join(STATUS),
               "description": "escape threshold of the damped slow flow (isolated 1:1 resonance), docs/damping.md"},
    )
