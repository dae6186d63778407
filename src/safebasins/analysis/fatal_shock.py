"""The minimal fatal shock: the smallest kick that drives a damped forced well's attractor to escape.

For ``q'' + beta q' + V'(q) = F sin(Omega t + Psi)`` with ``beta > 0`` the steady responses inside
the well are period-1 attractors (a fixed point of the stroboscopic map; the resonant and the
non-resonant branch where both exist).  A shock at forcing phase ``phi`` (the instant where
``Omega t + Psi = phi``) moves the state from the attractor's point ``x_a(phi)`` to ``x_a + d``;
the minimal fatal shock (MFS) is the smallest ``N(d)`` for which the trajectory from ``x_a + d``
escapes within ``cycles`` forcing periods, by the escape criteria of the compiled engine
(:func:`safebasins.numerics.escape_chart`: ``H0 = p^2/2 + V(q) > xi_max`` or ``q`` beyond a barrier,
checked after every step).  It is the distance from ``x_a`` to the unsafe set, i.e. the LIM radius
of the safe basin of that horizon centred on the attractor, found without a grid's resolution.

Norms: ``N(d) = sqrt(w_q dq^2 + w_p dp^2)``; the energy norm has ``(w_q, w_p) = (omega0^2, 1)``
(``omega0`` the well's linear frequency at the bottom; ``N^2 / 2`` is the energy the kick gives the
linearised oscillator), the weighted norm the user's ``weights``.

Algorithm (:func:`minimal_fatal_shock`): the attractors by iterating the compiled map from a grid
of seeds (:func:`safebasins.analysis.basin_labels.map_labels`), polished by Newton on the DOP853
map with their Floquet multipliers (:func:`safebasins.analysis.floquet.periodic_orbit`); then per
attractor, phase and norm one compiled batch over a polar grid of directions x radii (the grid
estimate: the smallest escaping radius) and over a Cartesian grid around ``x_a`` (the LIM of
:func:`safebasins.analysis.integrity.integrity_measures`); then k-section in radius along the
grid's best local minima over the direction and a bounded Brent search over the direction with
the k-section inside (:func:`scipy.optimize.minimize_scalar`).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr
from scipy.optimize import minimize_scalar

from safebasins.analysis.basin_labels import map_labels
from safebasins.analysis.floquet import forced_flow, forced_flow_dense, periodic_orbit
from safebasins.analysis.integrity import integrity_measures
from safebasins.core import checks
from safebasins.core.settling import settle_iterations
from safebasins.core.cf import annotate
from safebasins.numerics import criteria, engine, escape_chart, stroboscopic_map
from safebasins.numerics.problem import check_cycles
from safebasins.wells import resolve_well, well_attrs
from safebasins.wells.base import Well, WellLike
from safebasins.wells.provenance import api_provenance

__all__ = ["minimal_fatal_shock", "energy_weights", "NORMS"]

Array = npt.NDArray[np.float64]

#: the norms of the result: the energy norm always, the user's weighted norm when weights are given
NORMS = ("energy", "weighted")
#: points per k-section round (the bracket shrinks by K_SECTION + 1 per compiled call)
K_SECTION = 31
#: default steps per cycle: the engine checks the energy after each step, so a trajectory that grazes
#: xi_max between steps is missed and the MFS lies above the continuous-time one (measured on the
#: escape equation against DOP853: 0.5% at 32 steps per cycle, 1e-5 at 128)
STEPS_PER_CYCLE = 128
#: DOP853 tolerance of the attractor's orbit (Newton on the map, flow to each phase)
_RTOL = 1e-11
#: k-section rounds at most (the bracket has shrunk by 32^12 ~ 1e18 by then)
_MAX_ROUNDS = 12
_ONE = {"units": "1"}


def energy_weights(well: Well) -> tuple[float, float]:
    """``(omega0^2, 1)``: the weights of the energy norm ``sqrt(p^2 + omega0^2 q^2)``, ``omega0`` the
    well's frequency at vanishing energy (``Well.omega``)."""
    om0 = float(np.asarray(well.omega(1e-12 * float(well.barrier_energy))))
    return om0 * om0, 1.0


def _unit(theta: Array, wts: tuple[float, float]) -> Array:
    """Directions (2, n) of norm 1 at the angles ``theta`` of the scaled plane (sqrt(w_q) dq, sqrt(w_p) dp)."""
    return np.stack([np.cos(theta) / math.sqrt(wts[0]), np.sin(theta) / math.sqrt(wts[1])])


class _Shocks:
    """The escape test of perturbed attractor states at one forcing phase (the compiled engine)."""

    def __init__(self, w: Well, F: float, Omega: float, damping: float, xi: float, cycles: int, spc: int,
                 threads: int | None, tol: float) -> None:
        self.w, self.F, self.Omega, self.beta, self.xi = w, F, Omega, damping, xi
        self.cycles, self.spc, self.threads, self.tol = cycles, spc, threads, tol

    def escape_cycle(self, X: Array, phi: float) -> Array:
        """Escape cycle (+inf: safe within the horizon) of every column of X (2, n), forcing phase phi."""
        ds = escape_chart(X[0], X[1], self.F, self.Omega, phi, xi_max=(self.xi,), well=self.w, cycles=self.cycles,
                          steps_per_cycle=self.spc, threads=self.threads, grid=False, damping=self.beta)
        return np.asarray(ds["escape_cycle_energy"].values[0], dtype=float)

    def section(self, x_a: Array, phi: float, U: Array, lo: Array, hi: Array) -> tuple[Array, Array]:
        """k-section of the brackets ``[lo, hi]`` (lo safe, hi escaping) along the directions U (2, n)
        until ``hi - lo <= tol hi``; each round keeps the first escaping point and the one below it."""
        lo, hi = lo.copy(), hi.copy()
        frac = np.arange(1, K_SECTION + 1) / (K_SECTION + 1)
        for _ in range(_MAX_ROUNDS):
            open_ = np.flatnonzero(hi - lo > self.tol * hi)
            if open_.size == 0:
                break
            r = lo[open_, None] + (hi - lo)[open_, None] * frac[None, :]       # (m, K)
            X = x_a[:, None, None] + U[:, open_, None] * r[None]
            esc = np.isfinite(self.escape_cycle(X.reshape(2, -1), phi)).reshape(r.shape)
            first = np.where(esc.any(axis=1), np.argmax(esc, axis=1), K_SECTION)
            rows = np.arange(open_.size)
            hi[open_] = np.where(first < K_SECTION, r[rows, np.minimum(first, K_SECTION - 1)], hi[open_])
            lo[open_] = np.where(first > 0, r[rows, np.maximum(first - 1, 0)], lo[open_])
        return lo, hi

    def ray(self, x_a: Array, phi: float, u: Array, r_cap: float, n: int) -> tuple[float, float]:
        """``(lo, hi)``: the first escaping radius along u (2,) on ``n`` radii up to ``r_cap``, refined;
        ``(r_cap, 2 r_cap)`` when none of them escapes."""
        r = r_cap * np.arange(1, n + 1) / n
        esc = np.isfinite(self.escape_cycle(x_a[:, None] + u[:, None] * r[None, :], phi))
        if not esc.any():
            return r_cap, 2.0 * r_cap
        i = int(np.argmax(esc))
        lo, hi = self.section(x_a, phi, u[:, None], np.array([r[i - 1] if i else 0.0]), np.array([r[i]]))
        return float(lo[0]), float(hi[0])


def _local_minima(first: Array, n_best: int) -> npt.NDArray[np.intp]:
    """Indices of the ``n_best`` smallest circular local minima of ``first`` (ties: every index of a
    flat minimum counts once, its first)."""
    left, right = np.roll(first, 1), np.roll(first, -1)
    cand = np.flatnonzero((first < left) & (first <= right) & np.isfinite(first))
    if cand.size == 0:
        cand = np.array([int(np.argmin(first))])
    return cand[np.argsort(first[cand], kind="stable")][:n_best]


def _refine(sh: _Shocks, x_a: Array, phi: float, wts: tuple[float, float], theta: Array, first: Array,
            prev: Array, n_radii: int, n_best: int) -> dict[str, float]:
    """The MFS of one attractor, phase and norm from its polar grid (first escaping radius per
    direction ``first``, the radius below it ``prev``): k-section on every direction (so that the
    local minima over the direction are not plateaus of the radius grid), then bounded Brent over
    the direction within one grid step of the best local minima."""
    ok = np.flatnonzero(np.isfinite(first))
    lo_all, hi_all = np.full(theta.size, np.inf), np.full(theta.size, np.inf)
    lo_all[ok], hi_all[ok] = sh.section(x_a, phi, _unit(theta[ok], wts), prev[ok], first[ok])
    idx = _local_minima(hi_all, n_best)
    lo, hi = lo_all[idx], hi_all[idx]
    out = {"mfs": float(hi[0]), "mfs_safe": float(lo[0]), "theta": float(theta[idx[0]])}
    dth = 2.0 * np.pi / theta.size
    for k, j in enumerate(idx):
        r_cap = float(hi[k]) * (1.0 + 2.0 / n_radii)
        seen: dict[float, tuple[float, float]] = {}

        def radius(t: float) -> float:
            if t not in seen:
                seen[t] = sh.ray(x_a, phi, _unit(np.array([t]), wts)[:, 0], r_cap, n_radii)
            return seen[t][1]

        minimize_scalar(radius, bounds=(float(theta[j]) - dth, float(theta[j]) + dth), method="bounded",
                        options={"xatol": 1e-4 * dth, "maxiter": 60})
        for t, (r_lo, r_hi) in seen.items():
            if r_hi < out["mfs"] and r_lo < r_cap:
                out = {"mfs": r_hi, "mfs_safe": r_lo, "theta": t}
    return out


def _attractors(w: Well, F: float, Omega: float, beta: float, phi0: float, xi: float, n_seeds: int, spc: int,
                threads: int | None) -> list[dict[str, Any]]:
    """The stable period-1 orbits the seeds settle on, polished by Newton at the section phi0, by amplitude."""
    T = 2.0 * np.pi / Omega
    (lo, hi), (pl, ph) = w.ic_window()
    q0 = np.linspace(lo, hi, n_seeds + 2)[1:-1]
    p0 = np.linspace(pl, ph, n_seeds + 2)[1:-1]
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    n_iter = settle_iterations(beta, Omega)
    strobe = stroboscopic_map(Q, P, F, Omega, phi0, n_iter=n_iter, xi_max=xi, well=w, steps_per_cycle=spc,
                              threads=threads, damping=beta)
    try:
        lab = map_labels(strobe, period_max=1)
    except ValueError as exc:
        raise ValueError(f"F = {F!r}: no attractor inside the well ({exc})") from exc
    found: list[dict[str, Any]] = []
    for qa, pa in zip(lab.attrs["attractor_q"], lab.attrs["attractor_p"]):
        orb = periodic_orbit(w, F, Omega, beta, phi0, np.array([[qa], [pa]]), rtol=_RTOL)
        if not (orb.converged and orb.stable):
            continue
        x = orb.point
        if any(np.max(np.abs(x - a["point"])) < 1e-6 for a in found):
            continue
        t = T * np.arange(64) / 64
        qt = forced_flow_dense(w, F, Omega, beta, np.array([phi0]), x[:, None], T, _RTOL)(t)[0, 0]
        found.append({"point": x, "mu": float(np.max(np.abs(orb.multipliers))),
                      "amplitude": 0.5 * float(np.max(qt) - np.min(qt)), "residual": orb.residual})
    if not found:
        raise ValueError(f"F = {F!r}: no stable period-1 orbit inside the well (Newton did not converge)")
    return sorted(found, key=lambda a: a["amplitude"])


def _check_weights(weights: Any) -> tuple[float, float] | None:
    if weights is None:
        return None
    a = checks.check_1d("weights", weights, checks.check_positive)
    if a.size != 2:
        raise ValueError(f"weights must be a pair (w_q, w_p) of positive numbers, got {a.tolist()}")
    return float(a[0]), float(a[1])


@api_provenance
def minimal_fatal_shock(F: float, Omega: float, damping: float, well: WellLike = None, *,
                        phases: npt.ArrayLike = (0.0,), xi_max: float | None = None, cycles: int = 20,
                        weights: npt.ArrayLike | None = None, radius_max: float | None = None,
                        n_directions: int = 64, n_radii: int = 48, n_refine: int = 3, n_lim: int = 101,
                        n_seeds: int = 7, tol: float = 1e-9,
                        steps_per_cycle: int = STEPS_PER_CYCLE, threads: int | None = None) -> xr.Dataset:
    """The minimal fatal shock of every period-1 attractor inside the well, at each forcing phase.

    Parameters
    ----------
    F, Omega, damping : forcing amplitude (>= 0), frequency (> 0) and damping beta (> 0: without
        damping there is no attractor) of ``q'' + beta q' + V'(q) = F sin(Omega t + Psi)``.
    well : the potential (None: the paper's quartic).
    phases : forcing phases ``phi = Omega t + Psi`` at the shock (radians).
    xi_max : escape energy of the criterion ``H0 > xi_max`` (default the barrier energy); ``q``
        beyond a barrier always escapes.
    cycles : horizon in forcing periods after the shock.
    weights : ``(w_q, w_p)`` of the weighted norm ``sqrt(w_q dq^2 + w_p dp^2)`` (None: energy norm only).
    radius_max : largest energy-norm radius searched (default ``1.5 sqrt(2 xi_max)``, the unforced
        MFS of the bottom is ``sqrt(2 xi_max)``); the weighted norm searches up to the weighted norm of
        that energy disc.  ValueError naming it when no shock up to it escapes.
    n_directions, n_radii : the polar grid; n_refine : local minima over the direction refined;
    n_lim : nodes per side of the Cartesian grid of the LIM (odd: the attractor is a node);
    n_seeds : seeds per side of the grid iterated to find the attractors;
    tol : relative width of the final radius bracket.
    steps_per_cycle, threads : of the compiled engine (default :data:`STEPS_PER_CYCLE`, 128).

    Returns
    -------
    xr.Dataset over ``attractor``, ``phase``, ``norm``: ``mfs`` (refined; its shock escapes),
    ``mfs_safe`` (the bracket's safe end), ``mfs_grid`` (the polar grid's estimate), ``shock_dq``,
    ``shock_dp`` (the shock of norm ``mfs``), ``shock_angle`` (its angle in the scaled plane),
    ``escape_cycle`` (when the MFS shock escapes), ``lim`` (the LIM radius on the Cartesian grid),
    ``lim_spacing`` (that grid's node diagonal); ``q_attractor``, ``p_attractor`` (attractor,
    phase); ``multiplier_modulus``, ``response_amplitude`` (attractor).
    """
    F = checks.check_scalar("F", F, checks.check_nonnegative)
    Omega = checks.check_scalar("Omega", Omega, checks.check_positive)
    beta = checks.check_positive_damping(damping, "without damping there is no attractor to shock")
    w = resolve_well(well)
    phi = checks.check_1d("phases", phases, checks.check_finite)
    xi = float(w.check_threshold("xi_max", w.barrier_energy if xi_max is None else xi_max))
    cycles = check_cycles("cycles", cycles)
    wts = _check_weights(weights)
    n_dir = checks.check_positive_int("n_directions", n_directions)
    n_rad = checks.check_positive_int("n_radii", n_radii)
    n_best = checks.check_positive_int("n_refine", n_refine)
    n_lim = checks.check_positive_int("n_lim", n_lim)
    n_seeds = checks.check_positive_int("n_seeds", n_seeds)
    if n_dir < 8:
        raise ValueError(f"n_directions must be at least 8, got {n_dir}")
    if n_lim < 3 or n_lim % 2 == 0:
        raise ValueError(f"n_lim must be an odd integer >= 3 (the attractor a node), got {n_lim}")
    tol = checks.check_scalar("tol", tol, checks.check_positive)
    if not tol < 0.1:
        raise ValueError(f"tol must be below 0.1 (a relative bracket width), got {tol!r}")
    R_e = 1.5 * math.sqrt(2.0 * xi) if radius_max is None else checks.check_scalar("radius_max", radius_max,
                                                                                    checks.check_positive)
    spc = engine.check_step(Omega, engine.check_steps_per_cycle(steps_per_cycle), w)
    threads = engine.check_threads(threads)

    norms = [("energy", energy_weights(w))] + ([("weighted", wts)] if wts is not None else [])
    e_w = norms[0][1]
    # the weighted norm's search radius: its largest value on the energy disc of radius R_e
    radii = [R_e * max(math.sqrt(nw[0] / e_w[0]), math.sqrt(nw[1] / e_w[1])) for _, nw in norms]
    atts = _attractors(w, F, Omega, beta, float(phi[0]), xi, n_seeds, spc, threads)
    sh = _Shocks(w, F, Omega, beta, xi, cycles, spc, threads, tol)
    theta = 2.0 * np.pi * np.arange(n_dir) / n_dir
    s_lim = np.linspace(-1.0, 1.0, n_lim)
    shape = (len(atts), phi.size, len(norms))
    res = {k: np.full(shape, np.nan) for k in ("mfs", "mfs_safe", "mfs_grid", "theta", "lim", "cycle")}
    X_a = np.full((2, len(atts), phi.size), np.nan)
    T = 2.0 * np.pi / Omega
    for a, att in enumerate(atts):
        tau = np.mod(phi - phi[0], 2.0 * np.pi) / Omega
        for k in range(phi.size):
            X_a[:, a, k] = att["point"] if tau[k] == 0 else forced_flow(
                w, F, Omega, beta, np.array([phi[0]]), att["point"][:, None], float(tau[k]), _RTOL)[:, 0]
    for k in range(phi.size):
        # one compiled batch per phase: every attractor's and norm's polar and LIM grids
        blocks = []
        for a in range(len(atts)):
            for n, (_, nw) in enumerate(norms):
                r = radii[n] * np.arange(1, n_rad + 1) / n_rad
                polar = (_unit(theta, nw)[:, :, None] * r[None, None, :]).reshape(2, -1)
                S1, S2 = np.meshgrid(radii[n] * s_lim, radii[n] * s_lim, indexing="ij")
                cart = np.stack([S1.ravel() / math.sqrt(nw[0]), S2.ravel() / math.sqrt(nw[1])])
                blocks.append(X_a[:, a, k][:, None] + np.concatenate([polar, cart], axis=1))
        centres = X_a[:, :, k]
        esc = np.isfinite(sh.escape_cycle(np.concatenate(blocks + [centres], axis=1), float(phi[k])))
        if esc[-len(atts):].any():
            raise ValueError(f"xi_max: the attractor itself crosses xi_max = {xi!r} at phase {float(phi[k])!r} "
                             "(its fatal shock is 0); raise xi_max")
        esc = esc[:-len(atts)].reshape(len(atts), len(norms), -1)
        for a in range(len(atts)):
            for n, (_, nw) in enumerate(norms):
                r = radii[n] * np.arange(1, n_rad + 1) / n_rad
                e_pol = esc[a, n, :n_dir * n_rad].reshape(n_dir, n_rad)
                if not e_pol.any():
                    raise ValueError(f"radius_max: no shock up to it escapes attractor {a} at phase {float(phi[k])!r} "
                                     f"within {cycles} cycles (norm {norms[n][0]}); raise radius_max or cycles")
                i = np.where(e_pol.any(axis=1), np.argmax(e_pol, axis=1), -1)
                first = np.where(i >= 0, r[np.maximum(i, 0)], np.inf)
                prev = np.where(i > 0, r[np.maximum(i - 1, 0)], 0.0)
                out = _refine(sh, X_a[:, a, k], float(phi[k]), nw, theta, first, prev, n_rad, n_best)
                safe = ~esc[a, n, n_dir * n_rad:].reshape(n_lim, n_lim)
                lim = integrity_measures(safe, radii[n] * s_lim, radii[n] * s_lim, bottom=(0.0, 0.0))["r_local"]
                res["mfs_grid"][a, k, n] = float(np.min(first))
                res["lim"][a, k, n] = float(lim)
                for key in ("mfs", "mfs_safe", "theta"):
                    res[key][a, k, n] = out[key]
    D = np.stack([_unit(res["theta"][a, k, n:n + 1], norms[n][1])[:, 0] * res["mfs"][a, k, n]
                  for a in range(shape[0]) for k in range(shape[1]) for n in range(shape[2])], axis=1)
    for k in range(phi.size):       # the escape cycle of each MFS shock (one batch per phase)
        Xk = D.reshape(2, *shape)[:, :, k, :] + X_a[:, :, k][:, :, None]
        res["cycle"][:, k, :] = sh.escape_cycle(Xk.reshape(2, -1), float(phi[k])).reshape(shape[0], shape[2])
    return _dataset(w, atts, phi, norms, radii, n_lim, res, D.reshape(2, *shape), X_a,
                    dict(F=F, Omega=Omega, damping=beta, xi_max=xi, cycles=cycles, steps_per_cycle=spc, period=T,
                         tol=tol, n_directions=n_dir, n_radii=n_rad, n_refine=n_best, radius_max=R_e))


def _dataset(w: Well, atts: list[dict[str, Any]], phi: Array, norms: list[tuple[str, tuple[float, float]]],
             radii: list[float], n_lim: int, res: dict[str, Array], D: Array, X_a: Array,
             attrs: dict[str, Any]) -> xr.Dataset:
    def var(dims: tuple[str, ...], data: Any, long_name: str) -> tuple[tuple[str, ...], Any, dict[str, str]]:
        return dims, data, {**_ONE, "long_name": long_name}

    APN, AP, A = ("attractor", "phase", "norm"), ("attractor", "phase"), ("attractor",)
    spacing = np.array([2.0 * r / (n_lim - 1) * math.sqrt(2.0) for r in radii])
    ds = xr.Dataset(
        {
            "mfs": var(APN, res["mfs"], "minimal fatal shock: smallest norm of an escaping perturbation (refined)"),
            "mfs_safe": var(APN, res["mfs_safe"], "largest safe radius of the final bracket along the MFS direction"),
            "mfs_grid": var(APN, res["mfs_grid"], "smallest escaping radius on the polar grid"),
            "shock_dq": var(APN, D[0], "dq of the minimal fatal shock"),
            "shock_dp": var(APN, D[1], "dp of the minimal fatal shock"),
            "shock_angle": var(APN, res["theta"], "angle of the MFS in the plane (sqrt(w_q) dq, sqrt(w_p) dp)"),
            "escape_cycle": var(APN, res["cycle"], "escape cycle of the trajectory after the minimal fatal shock"),
            "lim": var(APN, res["lim"], "LIM: radius of the largest safe disc centred on the attractor (grid)"),
            "lim_spacing": var(("norm",), spacing, "node diagonal of the LIM grid (its resolution)"),
            "q_attractor": var(AP, X_a[0], "q of the attractor at the phase of the shock"),
            "p_attractor": var(AP, X_a[1], "p of the attractor at the phase of the shock"),
            "multiplier_modulus": var(A, np.array([a["mu"] for a in atts]), "largest Floquet multiplier modulus"),
            "response_amplitude": var(A, np.array([a["amplitude"] for a in atts]),
                                      "half the peak-to-peak q of the periodic response"),
        },
        coords={"attractor": ("attractor", np.arange(len(atts)),
                              {**_ONE, "long_name": "attractor index, by amplitude"}),
                "phase": ("phase", phi, {"units": "rad", "long_name": "forcing phase Omega t + Psi at the shock"}),
                "norm": ("norm", np.array([n for n, _ in norms]), {"long_name": "norm of the shock"}),
                "weight_q": ("norm", np.array([nw[0] for _, nw in norms]), {**_ONE, "long_name": "w_q of the norm"}),
                "weight_p": ("norm", np.array([nw[1] for _, nw in norms]), {**_ONE, "long_name": "w_p of the norm"}),
                "search_radius": ("norm", np.array(radii), {**_ONE, "long_name": "largest radius searched"})},
        attrs={"title": "minimal fatal shock of the attractors of the damped forced well", **well_attrs(w), **attrs,
               "norm_definition": "sqrt(w_q dq^2 + w_p dp^2); energy: (w_q, w_p) = (omega0^2, 1)",
               "escape_criteria": criteria.criteria_text(w), "integrator": engine.integrator_text(
                   engine.DEFAULT_INTEGRATOR, attrs["damping"]),
               "method": "attractors: compiled map from seeds, Newton on the DOP853 map (analysis.floquet); MFS: "
                         "polar grid, k-section in radius, bounded Brent over the direction; LIM: "
                         "analysis.integrity on a Cartesian grid centred on the attractor"})
    return annotate(ds)
