"""Fractality of a safe-basin boundary: the uncertainty exponent (Grebogi, McDonald, Ott & Yorke,
Phys. Lett. A 99, 1983; McDonald et al., Physica D 17, 1985).

An initial condition x is *epsilon-uncertain* when x, x + eps e and x - eps e (e a unit vector,
here along q0 or p0 at random) do not all have the same outcome (safe or escaped at t_eval).
For a basin boundary of box-counting dimension d in the D = 2 dimensional IC plane, the
fraction of uncertain ICs scales as ``f(eps) ~ eps^alpha`` with ``alpha = D - d``: a smooth
boundary has alpha = 1, a fractal one alpha < 1 (final-state sensitivity: halving eps removes
less than half of the uncertain ICs).  Past the Melnikov tangency of the hilltop saddle the
boundary of the safe basin becomes fractal (safebasins.analysis.melnikov).

:func:`uncertainty_exponent` integrates the base points and their perturbed copies in ONE
escape chart (paired ICs) and fits ``log f`` against ``log eps`` by weighted least squares
(binomial errors of the counts).
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.wells.base import WellLike
from safebasins.wells.provenance import api_provenance
from safebasins.analysis.safe import is_safe
from safebasins.numerics import escape_chart

__all__ = ["uncertainty_exponent", "MIN_UNCERTAIN"]

#: eps values with fewer uncertain ICs than this are left out of the fit (too noisy)
MIN_UNCERTAIN = 10


def exponent_dataset(eps: npt.ArrayLike, n_uncertain: npt.ArrayLike, n: int,
                     eps_attrs: Mapping[str, Any]) -> xr.Dataset:
    """f(eps) = n_uncertain / n of n random base points, its binomial standard error and the
    weighted least-squares fit of log f against log eps over the eps with at least MIN_UNCERTAIN
    uncertain points: a Dataset over ``eps`` (``n_uncertain``, ``fraction``, ``fraction_err``,
    ``used``) with attributes ``alpha``, ``alpha_err`` (NaN when fewer than two eps qualify) and
    ``boundary_dimension`` (2 - alpha).  Shared by the exponent of fresh integrations
    (:func:`uncertainty_exponent`) and of a labelled grid
    (:func:`safebasins.analysis.basin_measures.grid_uncertainty_exponent`)."""
    e = np.asarray(eps, dtype=float)
    k = np.asarray(n_uncertain, dtype=np.int64)
    f = k / n
    err = np.sqrt(np.maximum(f * (1 - f), 1.0 / n) / n)
    used = k >= MIN_UNCERTAIN
    alpha = alpha_err = np.nan
    if used.sum() >= 2:
        x, y = np.log(e[used]), np.log(f[used])
        wgt = (f[used] / err[used]) ** 2                # 1 / var(log f)
        A = np.stack([x, np.ones_like(x)], axis=1)
        cov = np.linalg.inv(A.T @ (wgt[:, None] * A))
        alpha, _ = cov @ (A.T @ (wgt * y))
        alpha_err = float(np.sqrt(cov[0, 0]))
        alpha = float(alpha)
    ds = xr.Dataset(
        {"n_uncertain": ("eps", k, {"units": "1", "long_name": "eps-uncertain base points"}),
         "fraction": ("eps", f, {"units": "1", "long_name": "fraction of eps-uncertain initial conditions f(eps)"}),
         "fraction_err": ("eps", err, {"units": "1", "long_name": "binomial standard error of f(eps)"}),
         "used": ("eps", used, {"long_name": f"in the fit (at least {MIN_UNCERTAIN} uncertain points)"})},
        coords={"eps": ("eps", e, dict(eps_attrs))},
    )
    ds.attrs.update(alpha=alpha, alpha_err=alpha_err, boundary_dimension=2.0 - alpha if np.isfinite(alpha) else np.nan)
    return ds


def _box(box):
    b = checks.check_finite("box", box)
    if b.shape != (2, 2) or not (b[:, 1] > b[:, 0]).all():
        raise ValueError(f"box must be ((q_lo, q_hi), (p_lo, p_hi)) with lo < hi, got {box!r}")
    return b


@api_provenance
def uncertainty_exponent(F: float, Omega: float, Psi: float, xi_max: float, box: npt.ArrayLike, *,
                         eps: npt.ArrayLike = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4), n: int = 4000, cycles: int = 500,
                         t_eval: float | None = None, seed: int = 0, well: WellLike = None, damping: float = 0.0,
                         steps_per_cycle: int = 32, threads: int | None = None, backend: str = "cpu") -> xr.Dataset:
    """Uncertainty exponent alpha of the safe-basin boundary (energy criterion H0 > xi_max) and
    the boundary dimension ``2 - alpha``.

    Parameters
    ----------
    F, Omega, Psi : the forcing F sin(Omega t + Psi).
    xi_max : energy threshold.
    box : ((q_lo, q_hi), (p_lo, p_hi)) of the random base points (seeded: ``seed``).
    eps : perturbation sizes (relative to nothing: absolute, in q0 or p0 units).
    n : base points.
    cycles, t_eval : horizon and evaluation time (default: the horizon); safe = escape_cycle > t_eval.
    well, damping, steps_per_cycle, threads, backend : as numerics.escape_chart.

    Returns
    -------
    xr.Dataset over ``eps``: ``n_uncertain``, ``fraction`` (f(eps)), ``fraction_err`` (binomial),
    ``used`` (in the fit); attributes ``alpha``, ``alpha_err``, ``boundary_dimension`` (2 - alpha),
    ``n``, ``seed``, ``safe_fraction`` (of the base points).  alpha is NaN when fewer than two
    eps have at least MIN_UNCERTAIN uncertain ICs.
    """
    b = _box(box)
    e = np.atleast_1d(checks.check_positive("eps", eps)).astype(float)
    if e.ndim != 1 or np.unique(e).size != e.size:
        raise ValueError(f"eps must be distinct positive values, got {eps!r}")
    n = checks.check_positive_int("n", n)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    t_eval = float(cycles) if t_eval is None else checks.check_scalar("t_eval", t_eval, checks.check_nonnegative)
    if t_eval > cycles:
        raise ValueError(f"t_eval must be <= cycles ({cycles}), got {t_eval}")
    rng = np.random.default_rng(int(seed))
    q = rng.uniform(b[0, 0], b[0, 1], n)
    p = rng.uniform(b[1, 0], b[1, 1], n)
    along_q = rng.random(n) < 0.5
    dq = np.where(along_q, 1.0, 0.0)[None, :] * e[:, None]
    dp = np.where(along_q, 0.0, 1.0)[None, :] * e[:, None]
    Q = np.concatenate([q, (q + dq).ravel(), (q - dq).ravel()])
    P = np.concatenate([p, (p + dp).ravel(), (p - dp).ravel()])
    ch = escape_chart(Q, P, F, Omega, Psi, xi_max=(xi_max,), cycles=cycles, steps_per_cycle=steps_per_cycle,
                      threads=threads, grid=False, well=well, damping=damping, backend=backend)
    safe = np.asarray(is_safe(ch["escape_cycle_energy"].isel(xi_max=0).values, t_eval), bool)
    base = safe[:n]
    plus = safe[n:n + e.size * n].reshape(e.size, n)
    minus = safe[n + e.size * n:].reshape(e.size, n)
    uncertain = (plus != base[None, :]) | (minus != base[None, :])
    ds = exponent_dataset(e, uncertain.sum(axis=1), n,
                          {"units": "1", "long_name": "perturbation of the initial condition"})
    ds.attrs.update(n=n, seed=int(seed), safe_fraction=float(base.mean()), F=float(F), Omega=float(Omega),
                    Psi=float(Psi), xi_max=float(xi_max), cycles=int(cycles), t_eval=t_eval,
                    **{k: ch.attrs[k] for k in ("damping",) if k in ch.attrs},
                    method="f(eps) ~ eps^alpha, x and x +- eps e with e along q0 or p0 at random; weighted fit of log "
                           "f")
    return ds
