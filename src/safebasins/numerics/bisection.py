"""Numeric critical forcing F_cr(Omega): ensemble bisection (Section 3.1) plus a fine F scan."""
from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

from safebasins import checks
from safebasins.io.provenance import api_provenance
from safebasins.numerics import criteria, engine, schemes
from safebasins.numerics.problem import check_cycles, check_damping, ensemble_problem
from safebasins.wells import QuarticWell, resolve_well

DEFAULT_N_SCAN = 301


class BracketWarning(RuntimeWarning):
    """F_bracket did not contain the escape threshold at some Omega (their F_cr is NaN)."""


def _warn_bracket(Om, br, ends, cycles):
    """Name the Omega whose F_cr is NaN because F_bracket misses the threshold, and a bracket to try."""
    n = Om.size
    low_escapes, high_safe = ends[:n], ~ends[n:]
    lo, hi = float(br[0]), float(br[1])
    parts = []
    if high_safe.any():
        parts.append(f"F_bracket[1] = {hi:g} does not escape within {cycles} cycles at Omega = "
                     f"{_list(Om[high_safe])} ({int(high_safe.sum())} of {n})")
    if low_escapes.any():
        parts.append(f"F_bracket[0] = {lo:g} already escapes at Omega = {_list(Om[low_escapes])} "
                     f"({int(low_escapes.sum())} of {n})")
    suggest = (0.0 if low_escapes.any() else lo, 4.0 * hi if high_safe.any() else hi)
    warnings.warn(f"F_bracket = ({lo:g}, {hi:g}) did not contain the escape threshold: " + "; ".join(parts)
                  + f". F_cr is NaN there; try a larger bracket, e.g. F_bracket=({suggest[0]:g}, {suggest[1]:g}).",
                  BracketWarning, stacklevel=4)  # the caller of critical_forcing_numeric (api_provenance)


def _list(values, most=6):
    text = ", ".join(f"{v:g}" for v in values[:most])
    return text + (f", ... ({values.size - most} more)" if values.size > most else "")


def _escapes(q0, p0, Omega, F, Psi, thr_kw, cycles, spc, threads, integrator, backend, w, damping):
    """One compiled ensemble: trajectory k with (Omega[k], F[k]); True where it escapes."""
    n = Omega.size
    problem = ensemble_problem(np.full(n, q0), np.full(n, p0), np.arange(n), Omega, F, Psi, cycles=cycles,
                               steps_per_cycle=spc, stop_any=True, integrator=integrator, well=w, damping=damping,
                               **thr_kw)
    sE, sQ = engine.integrate(problem, backend, threads=threads)
    return ((sE >= 0).any(axis=1)) | ((sQ >= 0).any(axis=1))


@api_provenance
def critical_forcing_numeric(Omega, xi_max, *, q0=0.0, p0=0.0, Psi=0.0, cycles=3000, tol=5e-5,
                             F_bracket=(0.0, 0.3), criterion="energy", n_scan=DEFAULT_N_SCAN,
                             steps_per_cycle=engine.DEFAULT_STEPS_PER_CYCLE, threads=None,
                             integrator=engine.DEFAULT_INTEGRATOR, backend="cpu", well=None, damping=0.0):
    """Numeric escape threshold F_cr(Omega) for the IC (q0, p0) (Section 3.1, Figs 10-12).

    Bisection: all Omega points advance together, one compiled ensemble per bisection level,
    until the bracket [F_lo (no escape within `cycles`), F_hi (escape)] is narrower than tol;
    F_cr = (F_lo + F_hi) / 2 (NaN where F_bracket[1] does not escape or F_bracket[0] does; a
    :class:`BracketWarning` then names those Omega and suggests a larger bracket).
    criterion "energy": escape when H0 > xi_max (or q beyond a barrier: ``|q| > 1`` for the quartic);
    "displacement": q outside the turning points of the energy level xi_max, ``|q| > q_max(xi_max)``
    (eq 4) for the quartic, q < q_minus(xi_max) or q > q_plus(xi_max) (well.turning_points) for
    any other well.  well: None (the quartic) or a polynomial well (see escape_chart); xi_max in
    (0, its barrier energy].  Escape is not monotone in F near the resonance minimum, so a scan on n_scan
    equally spaced F in F_bracket (one ensemble, Omega x F) also gives F_escape_low (lowest
    escaping F), F_escape_all (lowest F above which every scanned F escapes) and non_monotone
    (F_escape_all - F_escape_low > tol).  n_scan=0 skips the scan (variables NaN / False).
    integrator: "srkn6b" (default) or "rk4"; backend: "cpu", "cuda" or "auto"; damping: beta >= 0 of
    q'' + beta q' + V'(q) = F sin(...) (see escape_chart).

    Returns xr.Dataset over Omega: F_cr, F_cr_low, F_cr_high (final bracket), F_escape_low,
    F_escape_all, non_monotone; attrs xi_max, q0, p0, Psi, cycles, tol, criterion, F_bracket,
    n_scan, steps_per_cycle, integrator, bisection_levels, well (name), well_potential,
    well_barriers, escape_criteria, and for the displacement criterion q_lower, q_upper.
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
    damping = check_damping(damping)
    cycles = check_cycles("cycles", cycles)
    tol = checks.check_scalar("tol", tol, checks.check_positive)
    br = checks.check_nonnegative("F_bracket", F_bracket)
    if br.shape != (2,) or not np.isfinite(br).all() or not br[1] > br[0]:
        raise ValueError(f"F_bracket must be (F_lo, F_hi) with 0 <= F_lo < F_hi, got {F_bracket!r}")
    if criterion not in ("energy", "displacement"):
        raise ValueError(f"criterion must be 'energy' or 'displacement', got {criterion!r}")
    if isinstance(n_scan, bool) or not isinstance(n_scan, (int, np.integer)) or n_scan < 0 or n_scan == 1:
        raise ValueError(f"n_scan must be 0 (no scan) or an integer >= 2, got {n_scan!r}")
    schemes.check_integrator(integrator)
    spc = engine.check_step(Om, engine.check_steps_per_cycle(steps_per_cycle), w, integrator)
    threads = engine.check_threads(threads)
    bounds = {}
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
    # ---- bracket ends (one ensemble)
    ends = _escapes(q0, p0, np.concatenate([Om, Om]), np.concatenate([np.full(nO, br[0]), np.full(nO, br[1])]),
                    Psi, thr_kw, cycles, spc, threads, integrator, backend, w, damping)
    valid = ~ends[:nO] & ends[nO:]
    if not valid.all():
        _warn_bracket(Om, br, ends, cycles)
    lo = np.full(nO, br[0])
    hi = np.full(nO, br[1])
    levels = 0
    active = valid.copy()
    while active.any():
        idx = np.flatnonzero(active)
        mid = 0.5 * (lo[idx] + hi[idx])
        esc = _escapes(q0, p0, Om[idx], mid, Psi, thr_kw, cycles, spc, threads, integrator, backend, w, damping)
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
        Fs = np.linspace(br[0], br[1], int(n_scan))
        OO, FF = np.meshgrid(Om, Fs, indexing="ij")
        esc = _escapes(q0, p0, OO.ravel(), FF.ravel(), Psi, thr_kw, cycles, spc, threads, integrator, backend,
                       w, damping).reshape(nO, Fs.size)
        for k in range(nO):
            e = esc[k]
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
        },
        coords={"Omega": ("Omega", Om, {**u, "long_name": "forcing frequency"})},
    )
    ds.attrs.update(xi_max=xi, q0=q0, p0=p0, Psi=Psi, cycles=cycles, tol=tol, criterion=criterion,
                    F_bracket=br, n_scan=int(n_scan), steps_per_cycle=spc, integrator=engine.integrator_text(integrator, damping),
                    bisection_levels=levels,
                    F_scan_step=float((br[1] - br[0]) / (n_scan - 1)) if n_scan else np.nan,
                    escape_criteria=(f"energy ({w.energy_criterion()})" if criterion == "energy" else
                                     "displacement: q < q_lower or q > q_upper, the turning points of xi_max"),
                    **bounds, **w.numerics_attrs(), **engine.damping_attrs(damping))
    return ds
