"""Stroboscopic (period) map, eq (29)."""
from __future__ import annotations

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.core import cf
from safebasins.wells.provenance import api_provenance
from safebasins.numerics import engine, schemes
from safebasins.numerics.problem import check_cycles, displacement_pairs, ensemble_problem
from safebasins.wells import resolve_well
from safebasins.wells.base import WellLike


@api_provenance
def stroboscopic_map(q0: npt.ArrayLike, p0: npt.ArrayLike, F: float, Omega: float, Psi: float, *, n_iter: int = 3000,
                     xi_max: float | None = 0.25, q_max: float | None = None, q_bounds: npt.ArrayLike | None = None,
                     well: WellLike = None, steps_per_cycle: int = engine.DEFAULT_STEPS_PER_CYCLE,
                     threads: int | None = None, integrator: str = engine.DEFAULT_INTEGRATOR,
                     damping: float = 0.0) -> xr.Dataset:
    """Period-map iterates (q(nT), p(nT)), T = 2 pi / Omega, n = 0..n_iter, of paired ICs.

    Parameters
    ----------
    q0, p0
        Paired initial conditions of equal shape (flattened in C order to dim 'sample').
    xi_max, q_max, q_bounds
        Energy threshold (None: no energy criterion); displacement threshold (None: none); one
        asymmetric displacement bound pair (lo, hi) (None: none).  A trajectory has escaped
        once it crosses ANY given threshold (energy: H0 > xi_max or q beyond a barrier;
        displacement: ``|q| > q_max``, q < lo or q > hi); its iterates from that period on are
        NaN and it is no longer integrated.  q_max and q_bounds must be nested.
    well
        None (the quartic) or a polynomial well (see escape_chart).
    integrator
        "srkn6b" (default) or "rk4" (see escape_chart).

    Returns
    -------
    xr.Dataset
        q, p (sample, iteration) (iteration 0 = the IC), escaped (sample, bool), escape_cycle
        (sample; step / steps_per_cycle, +inf = not within n_iter cycles), q0, p0 (sample);
        attrs F, Omega, Psi, xi_max, q_max, n_iter, steps_per_cycle, integrator, well (name),
        well_potential, well_barriers, escape_criteria, and q_lower, q_upper when q_bounds is
        given.
    """
    qa = checks.check_finite("q0", q0)
    pa = checks.check_finite("p0", p0)
    if qa.shape != pa.shape:
        raise ValueError(f"q0 and p0 must have the same shape, got {qa.shape} and {pa.shape}")
    Q, P = qa.ravel(), pa.ravel()
    F = checks.check_scalar("F", F, checks.check_nonnegative)
    Omega = checks.check_scalar("Omega", Omega, checks.check_positive)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    n_iter = check_cycles("n_iter", n_iter)
    damping = checks.check_damping(damping)
    w = resolve_well(well)
    xi = () if xi_max is None else (checks.check_scalar("xi_max", xi_max, w.check_threshold),)
    qm = () if q_max is None else (checks.check_scalar("q_max", q_max, w.check_displacement),)
    qb = np.zeros((0, 2)) if q_bounds is None else w.check_bounds("q_bounds", q_bounds)
    if qb.shape[0] > 1:
        raise ValueError(f"q_bounds must be one pair (lo, hi) for the map, got {qb.tolist()}")
    if not xi and not qm and not qb.shape[0]:
        raise ValueError("xi_max, q_max and q_bounds: at least one escape threshold is required")
    displacement_pairs(qm, qb)
    schemes.check_integrator(integrator)
    spc = engine.check_step(Omega, engine.check_steps_per_cycle(steps_per_cycle), w, integrator)
    threads = engine.check_threads(threads)

    problem = ensemble_problem(Q, P, np.zeros(Q.size, np.int64), [Omega], [F], Psi, xi_max=xi, q_max=qm, q_bounds=qb,
                               cycles=n_iter, steps_per_cycle=spc, stop_any=True, integrator=integrator, well=w,
                               damping=damping)
    sE, sQ, st = engine.run_cpu(problem, threads=threads, store=True)
    assert st is not None  # (store=True)
    steps = np.concatenate([sE, sQ], axis=1).astype(float)
    steps[steps < 0] = np.inf
    first = steps.min(axis=1)
    esc_cycle = first / spc
    n = Q.size
    ds = xr.Dataset(
        {
            "q": (("sample", "iteration"), st[:, :, 0], cf.attrs("q")),
            "p": (("sample", "iteration"), st[:, :, 1], cf.attrs("p")),
            "escaped": ("sample", np.isfinite(esc_cycle), {"long_name": "escaped within n_iter cycles"}),
            "escape_cycle": ("sample", esc_cycle, cf.attrs("escape_cycle")),
        },
        coords={
            "sample": ("sample", np.arange(n), cf.attrs("sample")),
            "iteration": ("iteration", np.arange(n_iter + 1), cf.attrs("iteration")),
            "q0": ("sample", Q, cf.attrs("q0")),
            "p0": ("sample", P, cf.attrs("p0")),
        },
    )
    ds.attrs.update(F=F, Omega=Omega, Psi=Psi, xi_max=xi[0] if xi else np.nan, q_max=qm[0] if qm else np.nan,
                    n_iter=n_iter, steps_per_cycle=spc, integrator=engine.integrator_text(integrator, damping),
                    map="eq (29): (q(t), p(t)) -> (q(t + T), p(t + T)), T = 2 pi / Omega; NaN after escape",
                    escape_criteria=f"energy ({w.energy_criterion()}); displacement: |q| > q_max, q < q_lower or "
                                    "q > q_upper", **w.numerics_attrs(), **engine.damping_attrs(damping))
    if qb.shape[0]:
        ds.attrs.update(q_lower=float(qb[0, 0]), q_upper=float(qb[0, 1]))
    return ds
