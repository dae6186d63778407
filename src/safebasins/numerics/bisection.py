"""Numeric critical forcing F_cr(Omega): ensemble bisection (Section 3.1) plus a fine F scan.

The default F bracket is the well's own: ``(0, F_static)`` with ``F_static`` the well's static
escape force (:attr:`safebasins.wells.base.Well.static_escape_force`, rounded up to two significant
digits: round scan points, and last-bit differences of the well's geometry between machines do not
move them).  A constant force above ``F_static`` pushes the particle out; a forcing slow against the
well (``Omega -> 0``) escapes there, and resonance lowers the threshold.  Above the resonance
(``Omega`` beyond the well's frequencies, or a softening well forced above its amplitude-dependent
frequency) the threshold can exceed it: where ``F_hi`` does not escape, the bracket's top is
doubled, one ensemble per doubling over the Omega that need it, at most ``max_widenings`` times
(:data:`MAX_WIDENINGS`: up to 8 ``F_hi``).  Only when that is exhausted, or where ``F_lo`` already
escapes, is F_cr NaN (a :class:`BracketWarning` names those Omega).  The bisection and the scan at
an Omega both use its final bracket: a widened Omega gives what a call with that bracket gives.
"""
from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.wells.provenance import api_provenance
from safebasins.numerics import criteria, engine, schemes
from safebasins.numerics.problem import check_cycles, ensemble_problem
from safebasins.wells import QuarticWell, Well, resolve_well
from safebasins.wells.base import WellLike

DEFAULT_N_SCAN = 301
#: how often the bracket's top may be doubled where it does not escape (up to 2**3 = 8 F_hi)
MAX_WIDENINGS = 3


class BracketWarning(RuntimeWarning):
    """F_bracket did not contain the escape threshold at some Omega (their F_cr is NaN)."""


def default_bracket(well: WellLike) -> tuple[float, float]:
    """``(0, F_static)``: the default F bracket of :func:`critical_forcing_numeric` for a well,
    ``F_static`` (:attr:`~safebasins.wells.base.Well.static_escape_force`) rounded up to two
    significant digits (the quartic 0.39, the cubic 0.25, the pendulum 1, sech^2 0.77)."""
    f = float(resolve_well(well).static_escape_force)
    unit = 10.0 ** (math.floor(math.log10(f)) - 1)
    # the slack keeps a value a few ulps above a round number (0.25000000000000006) at it
    return 0.0, float(round(math.ceil(f / unit * (1.0 - 1e-9)) * unit, 12))


def _warn_bracket(Om: np.ndarray, br: np.ndarray, top: np.ndarray, low_escapes: np.ndarray, high_safe: np.ndarray,
                  cycles: int, widenings: int) -> None:
    """Name the Omega whose F_cr is NaN because the bracket ``br`` (its top widened to ``top``) misses
    the threshold, and a bracket to try."""
    n = Om.size
    lo, hi = float(br[0]), float(br[1])
    parts = []
    if high_safe.any():
        grown = (f"F_bracket[1] doubled {widenings} times, F = {float(np.max(top[high_safe])):g}," if widenings
                 else f"F_bracket[1] = {hi:g}")
        parts.append(f"{grown} does not escape within {cycles} cycles at Omega = "
                     f"{_list(Om[high_safe])} ({int(high_safe.sum())} of {n})")
    if low_escapes.any():
        parts.append(f"F_bracket[0] = {lo:g} already escapes at Omega = {_list(Om[low_escapes])} "
                     f"({int(low_escapes.sum())} of {n})")
    reach = float(np.max(top))
    suggest = (0.0 if low_escapes.any() else lo, 4.0 * reach if high_safe.any() else hi)
    warnings.warn(f"F_bracket = ({lo:g}, {hi:g}) did not contain the escape threshold: " + "; ".join(parts)
                  + f". F_cr is NaN there; try a larger bracket, e.g. F_bracket=({suggest[0]:g}, {suggest[1]:g}).",
                  BracketWarning, stacklevel=4)  # the caller of critical_forcing_numeric (api_provenance)


def _list(values: np.ndarray, most: int = 6) -> str:
    text = ", ".join(f"{v:g}" for v in values[:most])
    return text + (f", ... ({values.size - most} more)" if values.size > most else "")


def _escapes(q0: float, p0: float, Omega: np.ndarray, F: np.ndarray, Psi: float, thr_kw: dict[str, Any], cycles: int,
             spc: int, threads: int | None, integrator: str, backend: str, w: Well, damping: float) -> np.ndarray:
    """One compiled ensemble: trajectory k with (Omega[k], F[k]); True where it escapes."""
    n = Omega.size
    problem = ensemble_problem(np.full(n, q0), np.full(n, p0), np.arange(n), Omega, F, Psi, cycles=cycles,
                               steps_per_cycle=spc, stop_any=True, integrator=integrator, well=w, damping=damping,
                               **thr_kw)
    sE, sQ = engine.integrate(problem, backend, threads=threads)
    return np.asarray(((sE >= 0).any(axis=1)) | ((sQ >= 0).any(axis=1)))


@api_provenance
def critical_forcing_numeric(Omega: npt.ArrayLike, xi_max: float, *, q0: float = 0.0, p0: float = 0.0,
                             Psi: float = 0.0, cycles: int = 3000, tol: float = 5e-5,
                             F_bracket: tuple[float, float] | None = None, criterion: str = "energy",
                             n_scan: int = DEFAULT_N_SCAN, steps_per_cycle: int = engine.DEFAULT_STEPS_PER_CYCLE,
                             threads: int | None = None, integrator: str = engine.DEFAULT_INTEGRATOR,
                             backend: str = "cpu", well: WellLike = None, damping: float = 0.0,
                             max_widenings: int = MAX_WIDENINGS) -> xr.Dataset:
    """Numeric escape threshold F_cr(Omega) for the IC (q0, p0) (Section 3.1, Figs 10-12).

    Bisection: all Omega points advance together, one compiled ensemble per bisection level,
    until the bracket [F_lo (no escape within `cycles`), F_hi (escape)] is narrower than tol;
    F_cr = (F_lo + F_hi) / 2.  F_bracket: (F_lo, F_hi) with 0 <= F_lo < F_hi, or None for the well's
    own (:func:`default_bracket`: 0 to its static escape force).  Where F_hi does not escape it is
    doubled, at most ``max_widenings`` times (module docstring); F_cr is NaN where that is exhausted
    or F_bracket[0] already escapes (a :class:`BracketWarning` names those Omega).
    criterion "energy": escape when H0 > xi_max (or q beyond a barrier: ``|q| > 1`` for the quartic);
    criterion "displacement": q outside the turning points of the energy level xi_max, ``|q| > q_max(xi_max)``
    (eq 4) for the quartic, q < q_minus(xi_max) or q > q_plus(xi_max) (well.turning_points) for
    any other well.  well: None (the quartic) or a polynomial well (see escape_chart); xi_max in
    (0, its barrier energy].  Escape is not monotone in F near the resonance minimum, so a scan on n_scan
    equally spaced F in each Omega's final bracket (one ensemble, Omega x F) also gives F_escape_low (lowest
    escaping F), F_escape_all (lowest F above which every scanned F escapes) and non_monotone
    (F_escape_all - F_escape_low > tol).  n_scan=0 skips the scan (variables NaN / False).
    integrator: "srkn6b" (default) or "rk4"; backend: "cpu", "cuda" or "auto"; damping: beta >= 0 of
    q'' + beta q' + V'(q) = F sin(...) (see escape_chart).

    Returns xr.Dataset over Omega: F_cr, F_cr_low, F_cr_high (final bisection interval),
    F_escape_low, F_escape_all, non_monotone, F_bracket_used_high (the top of the bracket at that
    Omega after widening), F_bracket_widenings; attrs xi_max, q0, p0, Psi, cycles, tol, criterion,
    F_bracket (the bracket asked for, or the well's default), F_static (the well's static escape
    force), max_widenings, n_scan, F_scan_step (on F_bracket; a widened Omega's step is
    (F_bracket_used_high - F_bracket[0]) / (n_scan - 1)), steps_per_cycle, integrator,
    bisection_levels, well (name), well_potential, well_barriers, escape_criteria, and for the
    displacement criterion q_lower, q_upper.
    """
    Om = np.atleast_1d(checks.check_positive("Omega", Omega)).astype(float)
    if Om.ndim != 1:
        raise ValueError(f"Omega must be a scalar or 1-D, got shape {Om.shape}")
    if not np.isfinite(Om).all():
        raise ValueError("Omega must be finite")
    w = resolve_well(well)
    xi = checks.check_scalar("xi_max", xi_max, w.check_threshold)
    q0 = checks.check_scalar("q0", q0, checks.check_finite)
    p0 = checks.check_scalar("p0", p0, checks.check_finite)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    damping = checks.check_damping(damping)
    cycles = check_cycles("cycles", cycles)
    tol = checks.check_scalar("tol", tol, checks.check_positive)
    br = checks.check_nonnegative("F_bracket", default_bracket(w) if F_bracket is None else F_bracket)
    if br.shape != (2,) or not np.isfinite(br).all() or not br[1] > br[0]:
        raise ValueError(f"F_bracket must be (F_lo, F_hi) with 0 <= F_lo < F_hi, or None (the well's own), "
                         f"got {F_bracket!r}")
    if (isinstance(max_widenings, bool) or not isinstance(max_widenings, (int, np.integer))
            or not 0 <= max_widenings <= 20):
        raise ValueError(f"max_widenings must be an integer in [0, 20], got {max_widenings!r}")
    if criterion not in ("energy", "displacement"):
        raise ValueError(f"criterion must be 'energy' or 'displacement', got {criterion!r}")
    if isinstance(n_scan, bool) or not isinstance(n_scan, (int, np.integer)) or n_scan < 0 or n_scan == 1:
        raise ValueError(f"n_scan must be 0 (no scan) or an integer >= 2, got {n_scan!r}")
    schemes.check_integrator(integrator)
    spc = engine.check_step(Om, engine.check_steps_per_cycle(steps_per_cycle), w, integrator)
    threads = engine.check_threads(threads)
    bounds: dict[str, float] = {}
    thr_kw: dict[str, Any]
    if criterion == "energy":
        thr_kw = {"xi_max": (xi,), "q_max": ()}
    elif isinstance(w, QuarticWell):
        qm = float(np.sqrt(1.0 - np.sqrt(1.0 - 4.0 * xi)))
        thr_kw = {"xi_max": (), "q_max": (qm,)}
        bounds = {"q_lower": -qm, "q_upper": qm}
    else:
        qlo, qhi = criteria.displacement_bounds(xi, w)[0]
        thr_kw = {"xi_max": (), "q_bounds": ((qlo, qhi),)}
        bounds = {"q_lower": float(qlo), "q_upper": float(qhi)}

    nO = Om.size

    def run(Om_: np.ndarray, F_: np.ndarray) -> np.ndarray:
        return _escapes(q0, p0, Om_, F_, Psi, thr_kw, cycles, spc, threads, integrator, backend, w, damping)

    # ---- bracket ends (one ensemble), then the top doubled where it does not escape
    ends = run(np.concatenate([Om, Om]), np.concatenate([np.full(nO, br[0]), np.full(nO, br[1])]))
    low_escapes, top_escapes = ends[:nO], ends[nO:].copy()
    top = np.full(nO, br[1])
    widenings = np.zeros(nO, dtype=np.int64)
    for _ in range(int(max_widenings)):
        grow = np.flatnonzero(~low_escapes & ~top_escapes)
        if grow.size == 0:
            break
        top[grow] = 2.0 * top[grow]
        widenings[grow] += 1
        top_escapes[grow] = run(Om[grow], top[grow])
    valid = ~low_escapes & top_escapes
    if not valid.all():
        _warn_bracket(Om, br, top, low_escapes, ~low_escapes & ~top_escapes, cycles, int(max_widenings))
    lo = np.full(nO, br[0])
    hi = top.copy()
    levels = 0
    active = valid.copy()
    while active.any():
        idx = np.flatnonzero(active)
        mid = 0.5 * (lo[idx] + hi[idx])
        esc = run(Om[idx], mid)
        hi[idx[esc]] = mid[esc]
        lo[idx[~esc]] = mid[~esc]
        levels += 1
        active = valid & (hi - lo > tol)
    F_cr = np.where(valid, 0.5 * (lo + hi), np.nan)
    lo = np.where(valid, lo, np.nan)
    hi = np.where(valid, hi, np.nan)

    # ---- scan (one ensemble, Omega x F)
    F_low = np.full(nO, np.nan)
    F_all = np.full(nO, np.nan)
    non_mono = np.zeros(nO, dtype=bool)
    if n_scan:
        # each Omega on its own final bracket (equal to F_bracket unless widened there)
        FF = np.stack([np.linspace(br[0], t, int(n_scan)) for t in top])
        OO = np.repeat(Om[:, None], int(n_scan), axis=1)
        esc = run(OO.ravel(), FF.ravel()).reshape(nO, int(n_scan))
        for k in range(nO):
            e, Fs = esc[k], FF[k]
            if e.any():
                F_low[k] = Fs[np.argmax(e)]
            if e[-1]:
                last_safe = np.flatnonzero(~e)
                F_all[k] = Fs[last_safe[-1] + 1] if last_safe.size else Fs[0]
        non_mono = np.isfinite(F_low) & np.isfinite(F_all) & (F_all - F_low > tol)

    u = {"units": "1"}
    ds = xr.Dataset(
        {
            "F_cr": ("Omega", F_cr, {**u, "long_name": "numeric critical forcing amplitude (bisection midpoint)"}),
            "F_cr_low": ("Omega", lo, {**u, "long_name": "largest bisection F without escape"}),
            "F_cr_high": ("Omega", hi, {**u, "long_name": "smallest bisection F with escape"}),
            "F_escape_low": ("Omega", F_low, {**u, "long_name": "lowest escaping F on the scan"}),
            "F_escape_all": ("Omega", F_all, {**u, "long_name": "F above which every scanned F escapes"}),
            "non_monotone": ("Omega", non_mono, {"long_name": "escape not monotone in F (scan)"}),
            "F_bracket_used_high": ("Omega", top, {**u, "long_name": "top of the F bracket used (after widening)"}),
            "F_bracket_widenings": ("Omega", widenings, {"units": "1", "long_name":
                                                         "doublings of the bracket's top (F_bracket[1] 2**n)"}),
        },
        coords={"Omega": ("Omega", Om, {**u, "long_name": "forcing frequency"})},
    )
    ds.attrs.update(xi_max=xi, q0=q0, p0=p0, Psi=Psi, cycles=cycles, tol=tol, criterion=criterion,
                    F_bracket=br, F_static=float(w.static_escape_force), max_widenings=int(max_widenings),
                    n_scan=int(n_scan), steps_per_cycle=spc, integrator=engine.integrator_text(integrator, damping),
                    bisection_levels=levels,
                    F_scan_step=float((br[1] - br[0]) / (n_scan - 1)) if n_scan else np.nan,
                    escape_criteria=(f"energy ({w.energy_criterion()})" if criterion == "energy" else
                                     "displacement: q < q_lower or q > q_upper, the turning points of xi_max"),
                    **bounds, **w.numerics_attrs(), **engine.damping_attrs(damping))
    return ds
