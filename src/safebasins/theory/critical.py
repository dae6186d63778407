"""Critical forcing F_cr(Omega) for escape from one initial point on the RM (paper eqs 22-26).

With ``h(xi) = xi - Omega J(xi)``, ``h0 = h(xi_ini)``, ``G0 = G(xi_ini)``, ``c = cos(gamma_ini)`` the IC
escapes iff (see :mod:`safebasins.theory.slow_flow`) for every ``xi`` in ``(xi_ini, xi_max]``

    (A)  F (G(xi) - G0 c) >= h(xi) - h0      (level curve stays above the ray gamma = 0)
    (B)  F (G(xi) + G0 c) >= h0 - h(xi)      (level curve stays below the ray gamma = pi)

Each is linear in F, so the escaping set of F is an interval ``[F_lo, F_hi]`` and
``F_cr = F_lo = max`` of the lower bounds ``L_A = (h - h0)/(G - G0 c)``,
``L_B = (h0 - h)/(G + G0 c)`` over xi (where the denominators are positive).  Denominators
can be negative (G decreases to 0 at the separatrix): those constraints are upper bounds, and
if ``F_lo > F_hi`` the IC never escapes in the slow flow (``F_cr = NaN``, mechanism "none").

Where the maximum sits names the mechanism:

* ``xi = xi_max`` in (A): the level curve becomes tangent to ``xi = xi_max`` at gamma* = 0, eq (24)
  with the + sign:  ``F = (h(xi_max) - h0) / (G(xi_max) - G0 c)``.  Labelled **SMM** when, at
  that F, the slow flow has a saddle on the ray gamma = 0 *above* xi_max (``a(xi)`` has a local
  maximum in (xi_max, 1/4)) — the paper's "saddle maximum mechanism" (Sec. 2.2, Fig. 3, red
  dotted line); otherwise **MM_0**.
* ``xi = xi_max`` in (B): tangency at gamma* = pi, eq (24) with the - sign: **MM_pi**
  (Fig. 3, green dashed line).
* an interior maximum of L_A (L_B): at that F the curve through the IC passes through a
  saddle on gamma = 0 (pi) below xi_max (``a' = 0`` there, eqs 25-26): **SM**.
  (An interior maximum of ``L_A`` in xi is exactly a point where ``a(xi) = C0`` and
  ``a'(xi) = 0`` with ``a`` locally maximal, i.e. a saddle.)

For the zero IC this reduces to ``F_cr = max_{0 < xi <= xi_max} |xi - Omega J(xi)| / G(xi)``.

Notes on the paper
------------------
* Eq (24) is written with ``C0`` as if it were independent of F; for a nonzero IC
  ``C0 = h0 - F G0 cos(gamma_ini)`` depends on F and the explicit solution is the one above.  The
  "+" sign of eq (24) is the tangency at gamma* = pi, the "-" sign the one at gamma* = 0.
* At ``xi_max = 1/4`` exactly, ``G(1/4) = 0`` and the tangency point is undefined (as the paper
  remarks); in the slow flow no level curve except ``C = h(1/4)`` reaches the separatrix, so
  ``F_cr`` is NaN there.  Use a threshold slightly below 1/4 (the paper uses 0.2499).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from safebasins.core import checks
from safebasins.core.checks import check_finite, check_positive, check_scalar
from safebasins.theory.damped import slow_tables
from safebasins.theory.damped_escape import damped_critical_forcing
from safebasins.theory.profile import resolved_shift, unshear, xi_grid
from safebasins.theory.types import BoolArray, FloatArray, WellArg
from safebasins.wells import resolve_well
from safebasins.wells.provenance import api_provenance

__all__ = ["critical_forcing", "MECHANISMS"]

MECHANISMS = ("none", "MM_0", "MM_pi", "SM", "SMM")
NONE, MM_0, MM_PI, SM, SMM = range(5)

#: relative accuracy of h(xi) - h0 = xi - Omega J(xi) - h0 as computed (J of a tabulated well is
#: known to ~1e-13): a branch F = (h - h0) / (G -+ G0 c) within what it resolves is 0, no positive
#: lower bound.  (At Omega = omega(xi_ini), e.g. Omega = 1 from the zero IC, the saddle branch
#: tends to F = 0 at xi_ini and its sign is the last bit's.)
H_ACCURACY = 1e-12


def _bisect(fun: Callable[[FloatArray], FloatArray], lo: FloatArray, hi: FloatArray,
            n_iter: int = 60) -> FloatArray:
    """Vectorised bisection for a sign change fun(lo) > 0 > fun(hi)."""
    lo, hi = lo.copy(), hi.copy()
    for _ in range(n_iter):
        mid = 0.5 * (lo + hi)
        pos = fun(mid) > 0
        lo = np.where(pos, mid, lo)
        hi = np.where(pos, hi, mid)
    return 0.5 * (lo + hi)


def _interior_max(L: FloatArray, valid: BoolArray, xi: FloatArray,
                  refine_fun: Callable[[NDArray[np.intp], FloatArray], FloatArray],
                  n_iter: int = 60) -> tuple[FloatArray, FloatArray, BoolArray]:
    """Largest interior local maximum of L (rows = Omega) with its xi, refined on the derivative.

    refine_fun(rows, x) -> sign-carrying derivative of L at x for the given rows.
    """
    nO, N = L.shape
    Lm = np.where(valid, L, -np.inf)
    left = Lm[:, :-2]                            # nodes 1..N-2 (Lm[:, 0] is -inf)
    mid = Lm[:, 1:-1]
    right = Lm[:, 2:]
    is_max = np.isfinite(mid) & (mid >= left) & (mid >= right)
    cand = np.where(is_max, mid, -np.inf)
    k = np.argmax(cand, axis=1)
    val = cand[np.arange(nO), k]
    exists = np.isfinite(val)
    i = k + 1                                   # node index
    x_node = xi[i]
    x_out = np.where(exists, x_node, np.nan)
    v_out = np.where(exists, val, np.nan)
    rows = np.nonzero(exists)[0]
    if rows.size:
        lo = xi[i[rows] - 1]
        hi = xi[i[rows] + 1]
        lo = np.where(i[rows] - 1 == 0, lo + 1e-9 * (hi - lo), lo)
        hi = np.where(i[rows] + 1 == N - 1, hi - 1e-9 * (hi - lo), hi)
        s_lo = refine_fun(rows, lo)
        s_hi = refine_fun(rows, hi)
        ok = (s_lo > 0) & (s_hi < 0)
        if ok.any():
            r = rows[ok]
            x_ref = _bisect(lambda x: refine_fun(r, x), lo[ok], hi[ok], n_iter)
            x_out[r] = x_ref
    return x_out, v_out, exists


@api_provenance
def critical_forcing(Omega: ArrayLike, xi_max: float, xi_ini: float = 0.0, gamma_ini: float = 0.0,
                     fourier: str | None = None, n_grid: int = 2001, well: WellArg = None,
                     damping: float = 0.0) -> xr.Dataset:
    """Critical forcing amplitude F_cr(Omega) of the slow flow (eqs 22-26).

    Parameters
    ----------
    Omega : array_like, > 0
        Forcing frequencies (becomes the coordinate ``Omega``).
    xi_max : float in (0, 1/4]
        Energy truncation level.
    xi_ini, gamma_ini : float
        Initial point on the RM (``0 <= xi_ini < xi_max``; gamma_ini = theta0 - Psi).  Zero IC by default.
    fourier : "paper" | "exact"
        Which G (eq 20) of the quartic to use (default "paper").
    well : safebasins.wells.Well
        The potential (default: the paper's quartic).  For a well whose first harmonic has a
        phase delta(xi) the tangencies and saddles lie on gamma + delta(xi) = 0, pi and the
        initial point enters through cos(gamma_ini + delta(xi_ini)).
    n_grid : int
        Nodes of the xi grid used to bracket the maxima (refined by bisection).
    damping : float, >= 0
        beta of ``q'' + beta q' + V'(q) = F sin(Omega tau + Psi)``.  0 (default): the conservative
        slow flow, eqs (22)-(26), as below.  beta > 0: F_cr is the smallest F for which the
        trajectory of the damped slow flow from (gamma_ini, xi_ini) reaches xi_max before it settles
        on an attractor (:func:`safebasins.theory.damped_escape.damped_critical_forcing`, by a scan
        in F and bisection; docs/damping.md); the Dataset then has ``F_cr``, ``F_settle``,
        ``F_cr_undamped``, ``F_min``, ``xi_attractor``, ``t_escape``, ``undecided`` (F_cr is NaN
        where an undecided trajectory leaves it unknown) instead of the mechanism branches.

    Returns
    -------
    xarray.Dataset
        Over ``Omega`` (damping = 0), with

        * ``F_cr``: smallest F at which the level curve through (gamma_ini, xi_ini) reaches
          xi_max (NaN if it never does);
        * ``mechanism``: int8, flag_values [0..4], flag_meanings "none MM_0 MM_pi SM SMM";
        * ``F_MM_0``: eq (24) through gamma* = 0 where no gamma = 0 saddle lies above xi_max
          (NaN otherwise, and where the tangency value is not a positive lower bound);
        * ``F_SMM``: the same eq (24) value where such a saddle exists above xi_max (the branches
          F_MM_0 and F_SMM are disjoint; their union is eq (24) with gamma* = 0);
        * ``F_MM_pi``: eq (24) through gamma* = pi;
        * ``F_SM``: largest F of eqs (25)-(26) with the saddle in (xi_ini, xi_max) (NaN if none);
        * ``xi_saddle``, ``gamma_saddle``: the saddle of the F_SM branch (gamma 0 or pi;
          -delta(xi) or pi - delta(xi) for an asymmetric well);
        * ``xi_saddle_smm``: the saddle above xi_max on the F_SMM branch.

        F_cr equals the largest existing branch, provided no upper-bound constraint excludes it.
        Attributes: xi_max, xi_ini, gamma_ini, fourier, well.
    """
    well = resolve_well(well, fourier)
    w, fourier, E_b = well, well.fourier, well.barrier_energy
    Om = np.atleast_1d(check_positive("Omega", Omega)).astype(float)
    if Om.ndim != 1:
        raise ValueError("Omega must be a scalar or 1-D array")
    xm = check_scalar("xi_max", xi_max, w.check_threshold)
    x0 = check_scalar("xi_ini", xi_ini, w.check_energy)
    if x0 >= xm:
        raise ValueError(f"xi_ini must be < xi_max ({xm}), got {x0}")
    g0 = check_scalar("gamma_ini", gamma_ini, check_finite)
    if not isinstance(n_grid, (int, np.integer)) or n_grid < 16:
        raise ValueError("n_grid must be an integer >= 16")
    beta = checks.check_damping(damping)
    if beta > 0:
        # the undamped F_cr seeds the scan; the damped flow's tables end just below the barrier
        F0 = critical_forcing(Om, min(xm, slow_tables(w).xi_top), x0, g0, n_grid=n_grid, well=w)["F_cr"].values
        return damped_critical_forcing(Om, xm, x0, g0, beta, w, F_undamped=F0)
    w.check_analytic_threshold("xi_max", xm)     # the level curves of C need an orbit at xi_max

    nO = Om.size
    xi = xi_grid(x0, xm, int(n_grid))
    Jg, Gg = w.J(xi), w.harmonic_amplitude(xi)
    J0, G0 = float(w.J(np.asarray(x0))), float(w.harmonic_amplitude(np.asarray(x0)))
    c = np.cos(g0 + float(w.harmonic_shift(np.asarray(x0))))
    h = xi[None, :] - Om[:, None] * Jg[None, :]
    h0 = x0 - Om * J0
    numA = h - h0[:, None]
    numB = -numA
    dA = Gg - G0 * c
    dB = Gg + G0 * c
    tiny = 1e-14
    with np.errstate(divide="ignore", invalid="ignore"):
        LA = numA / dA[None, :]
        LB = numB / dB[None, :]
    posA, posB = dA > tiny, dB > tiny
    posA[0] = posB[0] = False                 # xi_ini itself: trivially satisfied
    # upper bounds and infeasible zero-denominator constraints
    negA, negB = dA < -tiny, dB < -tiny
    negA[0] = negB[0] = False
    zA = ~(posA | negA)
    zB = ~(posB | negB)
    zA[0] = zB[0] = False
    U = np.full(nO, np.inf)
    if negA.any():
        U = np.minimum(U, np.min(np.where(negA[None, :], LA, np.inf), axis=1))
    if negB.any():
        U = np.minimum(U, np.min(np.where(negB[None, :], LB, np.inf), axis=1))
    infeasible = np.zeros(nO, bool)
    if zA.any():
        infeasible |= np.any(zA[None, :] & (numA > 1e-13), axis=1)
    if zB.any():
        infeasible |= np.any(zB[None, :] & (numB > 1e-13), axis=1)

    def resolution(x: ArrayLike, rows: NDArray[np.intp], den: ArrayLike) -> FloatArray:
        """F below which a branch (h(x) - h0) / den is not resolved (H_ACCURACY)."""
        om = Om[rows]
        with np.errstate(divide="ignore"):
            out: FloatArray = H_ACCURACY * (np.abs(x) + om * np.abs(w.J(x)) + abs(x0) + om * abs(J0)) / np.abs(den)
            return out

    # --- endpoint tangencies, eq (24)
    end_ok = xm < E_b
    FA_end = np.where(posA[-1] & end_ok, LA[:, -1], np.nan)
    FB_end = np.where(posB[-1] & end_ok, LB[:, -1], np.nan)
    all_rows = np.arange(nO)
    FA_end = np.where(FA_end > resolution(xm, all_rows, dA[-1]), FA_end, np.nan)
    FB_end = np.where(FB_end > resolution(xm, all_rows, dB[-1]), FB_end, np.nan)

    # --- interior maxima (saddle mechanism), refined on the sign of dL/dxi
    def dLA(rows: NDArray[np.intp], x: FloatArray) -> FloatArray:
        om = Om[rows]
        hp = 1.0 - om / w.omega(x)
        num = x - om * w.J(x) - h0[rows]
        out: FloatArray = hp * (w.harmonic_amplitude(x) - G0 * c) - num * w.harmonic_amplitude_derivative(x)
        return out

    def dLB(rows: NDArray[np.intp], x: FloatArray) -> FloatArray:
        om = Om[rows]
        hp = 1.0 - om / w.omega(x)
        num = h0[rows] - (x - om * w.J(x))
        out: FloatArray = -hp * (w.harmonic_amplitude(x) + G0 * c) - num * w.harmonic_amplitude_derivative(x)
        return out

    def L_at(x: FloatArray, rows: NDArray[np.intp], which: int) -> FloatArray:
        om = Om[rows]
        hh = x - om * w.J(x)
        Gx = w.harmonic_amplitude(x)
        if which == 0:
            out: FloatArray = (hh - h0[rows]) / (Gx - G0 * c)
            return out
        out = (h0[rows] - hh) / (Gx + G0 * c)
        return out

    xA, vA, eA = _interior_max(LA, posA[None, :] & np.ones((nO, 1), bool), xi, dLA)
    xB, vB, eB = _interior_max(LB, posB[None, :] & np.ones((nO, 1), bool), xi, dLB)
    for xs, vs, es, side in ((xA, vA, eA, 0), (xB, vB, eB, 1)):
        r = np.nonzero(es)[0]
        if r.size:
            vs[r] = np.maximum(vs[r], L_at(xs[r], r, side))
            den = w.harmonic_amplitude(xs[r]) + (G0 * c if side else -G0 * c)
            es[r] &= vs[r] > resolution(xs[r], r, den)
    vA = np.where(eA, vA, np.nan)
    vB = np.where(eB, vB, np.nan)
    useB = np.nan_to_num(vB, nan=-np.inf) > np.nan_to_num(vA, nan=-np.inf)
    F_SM = np.where(useB, vB, vA)
    xi_saddle = np.where(np.isnan(F_SM), np.nan, np.where(useB, xB, xA))
    gamma_saddle = np.where(np.isnan(F_SM), np.nan, np.where(useB, np.pi, 0.0))
    fin = np.isfinite(gamma_saddle)
    if fin.any():     # gamma' = 0 or pi on the sheared rays: the saddle sits at gamma = gamma' - delta(xi)
        gamma_saddle[fin] = unshear(gamma_saddle[fin], resolved_shift(w, xi_saddle[fin]))

    # --- SMM: does a(xi) = h - F G have a local max in (xi_max, 1/4) at F = FA_end?
    xi_smm = np.full(nO, np.nan)
    has_smm = np.zeros(nO, bool)
    rows = np.nonzero(np.isfinite(FA_end))[0]
    # energies strictly below the barrier (xi_max = 1/6 of the cubic lies one ulp below its rounded
    # barrier energy: grid points there round onto it, and no interval is left for an SMM)
    up = xi_grid(xm, E_b, 600)[:-1] if xm < E_b else np.empty(0)
    up = up[up < E_b]
    if rows.size and up.size >= 2:
        dG_up = w.harmonic_amplitude_derivative(up)
        w_up = w.omega(up)
        ap = (1.0 - Om[rows, None] / w_up[None, :]) - FA_end[rows, None] * dG_up[None, :]
        sgn = ap > 0
        change = sgn[:, :-1] & ~sgn[:, 1:]
        hit = change.any(axis=1)
        if hit.any():
            rr = rows[hit]
            j = np.argmax(change[hit], axis=1)
            Fr = FA_end[rr]

            def dap(x: FloatArray, rr: NDArray[np.intp] = rr, Fr: FloatArray = Fr) -> FloatArray:
                out: FloatArray = 1.0 - Om[rr] / w.omega(x) - Fr * w.harmonic_amplitude_derivative(x)
                return out

            xi_smm[rr] = _bisect(dap, up[j], up[j + 1])
            has_smm[rr] = True
    F_MM_0 = np.where(has_smm, np.nan, FA_end)
    F_SMM = np.where(has_smm, FA_end, np.nan)

    # --- overall threshold and mechanism
    stack = np.stack([F_MM_0, FB_end, F_SM, F_SMM])           # codes 1, 2, 3, 4
    filled = np.nan_to_num(stack, nan=-np.inf)
    best = np.argmax(filled, axis=0)
    F_cr = filled[best, np.arange(nO)]
    mech = (best + 1).astype(np.int8)
    ok = np.isfinite(F_cr) & ~infeasible & (F_cr <= U * (1 + 1e-12))
    F_cr = np.where(ok, F_cr, np.nan)
    mech = np.where(ok, mech, NONE).astype(np.int8)

    def var(values: ArrayLike, long_name: str) -> tuple[str, Any, dict[str, str]]:
        return ("Omega", values, {"units": "1", "long_name": long_name})

    ds = xr.Dataset(
        {
            "F_cr": var(F_cr, "critical forcing amplitude (slow flow, eqs 22-26)"),
            "mechanism": ("Omega", mech, {
                "long_name": "escape mechanism setting F_cr",
                "flag_values": np.arange(5, dtype=np.int8),
                "flag_meanings": " ".join(MECHANISMS)}),
            "F_MM_0": var(F_MM_0, "maximum mechanism through gamma*=0, eq (24), no saddle above xi_max"),
            "F_MM_pi": var(FB_end, "maximum mechanism through gamma*=pi, eq (24)"),
            "F_SM": var(F_SM, "saddle mechanism, eqs (25)-(26)"),
            "F_SMM": var(F_SMM, "saddle maximum mechanism: eq (24) at gamma*=0 with a saddle above xi_max"),
            "xi_saddle": var(xi_saddle, "averaged energy of the saddle on the F_SM branch"),
            "gamma_saddle": ("Omega", gamma_saddle,
                             {"units": "rad", "long_name": "slow phase of the saddle on the F_SM branch"}),
            "xi_saddle_smm": var(xi_smm, "averaged energy of the saddle above xi_max on the F_SMM branch"),
        },
        coords={"Omega": ("Omega", Om, {"units": "1", "long_name": "forcing frequency"})},
        attrs={"xi_max": xm, "xi_ini": x0, "gamma_ini": g0, "fourier": fourier, "well": w.name,
               "description": "slow-flow (isolated 1:1 resonance) escape threshold, Karmi et al. eqs 18-26"},
    )
    return ds
