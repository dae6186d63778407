"""The attractors of the damped forced well followed across Omega or F, with their basins' integrity.

For ``q'' + beta q' + V'(q) = F sin(Omega t + Psi)`` (beta > 0) the steady responses inside the well
are period-1 orbits, fixed points of the stroboscopic map of phase ``Psi``; in the hysteresis band of
the bent resonance peak a small-amplitude (non-resonant) and a large-amplitude (resonant) attractor
coexist, joined through folds by an unstable (saddle) branch.  :func:`continue_attractors`

1. labels the basins on a grid of initial conditions over the well's IC window at every swept value
   (the compiled map, :func:`safebasins.numerics.stroboscopic_map`, and
   :func:`safebasins.analysis.basin_labels.map_labels`): escape and the attractors the grid settles on;
2. follows every period-1 attractor found there by pseudo-arclength continuation of the fixed point of
   the DOP853 period map (:mod:`safebasins.analysis.arclength`: eqs C1-C5 of docs/continuation.md),
   through folds onto the saddle branch, with the Floquet multipliers, the folds, branch points and
   period doublings located, until the branch leaves the swept range or the well (the largest energy
   ``H0`` on the orbit reaches ``xi_max``: the compiled map's escape test);
3. at every swept value, matches each followed attractor (a stable stretch of a branch) to its label
   and measures its basin (:func:`safebasins.analysis.integrity.integrity_measures`): GIM (the
   basin's area over the unforced safe set's on the same grid), LIM (the radius of the largest disc
   centred on the attractor inside its basin, over the unforced LIM at the well bottom), and the
   share of the IC window.  Where the most of an attractor's basin is lost to escape between
   neighbouring swept values (grid nodes in its basin at one value that escape at the next, in GIM
   units; not the nodes it hands over to another attractor) is its Dover cliff.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.analysis import arclength as al
from safebasins.analysis.basin_labels import map_labels
from safebasins.analysis.integrity import integrity_measures
from safebasins.core import cf, checks
from safebasins.core.settling import settle_iterations
from safebasins.numerics import criteria, engine, stroboscopic_map
from safebasins.numerics.problem import check_cycles
from safebasins.wells import resolve_well, well_attrs
from safebasins.wells.base import Well, WellLike
from safebasins.wells.provenance import api_provenance

__all__ = ["continue_attractors", "PERIOD_MAX", "ATTRACTOR_CLASSES"]

Array = npt.NDArray[np.float64]

#: longest period the basin labels look for (ICs settling on a period-2 to 4 orbit are not counted in
#: a period-1 attractor's basin)
PERIOD_MAX = 4
#: a label's attractor and a followed fixed point are one attractor within this max-norm distance (of
#: the IC window's q-width): the compiled map's fixed point is the scheme's, and the labels settle to 1e-4
MATCH_TOL = 0.01
#: ``attractor_class``: the first harmonic lags the forcing by less than pi/2 on every point (below the
#: amplitude-dependent resonance), by more (above it: the resonant branch), or both (through the peak)
ATTRACTOR_CLASSES = ("non_resonant", "resonant", "through_peak")
_ONE = {"units": "1"}


def _check_sweep(Omega: Any, F: Any) -> tuple[al.Parameter, Array, float, float]:
    """``(parameter, values, F, Omega)``: which of Omega and F is swept (a 1-D increasing array) and the
    other's value (a scalar)."""
    if (np.ndim(Omega) > 0) == (np.ndim(F) > 0):
        raise ValueError("Omega and F: exactly one must be a 1-D sweep (an array of at least 2 increasing values) "
                         f"and the other a scalar; got Omega with shape {np.shape(Omega)}, F with shape {np.shape(F)}")
    if np.ndim(Omega) > 0:
        vals = checks.check_1d("Omega", Omega, checks.check_positive)
        name: al.Parameter = "Omega"
        Fv, Omv = checks.check_scalar("F", F, checks.check_nonnegative), float(vals[0])
    else:
        vals = checks.check_1d("F", F, checks.check_nonnegative)
        name = "F"
        Fv, Omv = float(vals[0]), checks.check_scalar("Omega", Omega, checks.check_positive)
    if vals.size < 2 or not (np.diff(vals) > 0).all():
        raise ValueError(f"{name} must be a sweep of at least 2 strictly increasing values, got {vals.tolist()}")
    return name, vals, Fv, Omv


def _labels(w: Well, F: float, Om: float, beta: float, Psi: float, xi: float, q0: Array, p0: Array,
            n_iter: int | None, spc: int, threads: int | None) -> xr.DataArray:
    """The basin labels of the grid (0 escape, k the k-th attractor of map_labels); none settled: all 0."""
    n = settle_iterations(beta, Om, n_iter)
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    strobe = stroboscopic_map(Q, P, F, Om, Psi, n_iter=n, xi_max=xi, well=w, steps_per_cycle=spc, threads=threads,
                              damping=beta)
    if bool(strobe["escaped"].all()):
        lab = xr.DataArray(np.zeros(Q.shape, np.int64), dims=("q0", "p0"), coords={"q0": q0, "p0": p0})
        lab.attrs.update(attractor_q=[], attractor_p=[], attractor_period=[], n_unsettled=0)
        return lab
    try:
        return map_labels(strobe, period_max=PERIOD_MAX)
    except ValueError as exc:
        raise ValueError(f"n_iter: no IC of the grid settled within {n} map iterations at F = {F!r}, "
                         f"Omega = {Om!r} ({exc}); raise n_iter") from exc


class _Tracker:
    """The curves followed so far, their stable runs (the attractors) and each run's orbit at each swept value."""

    def __init__(self, fam: al.Family, values: Array, ds_max: float, max_points: int) -> None:
        self.fam, self.values, self.ds_max, self.max_points = fam, values, ds_max, max_points
        self.curves: list[al.Curve] = []
        self.runs: list[tuple[int, int, int]] = []            # (curve, first point, last point)
        self.at: list[list[al.Point | None]] = []              # run -> orbit at each swept value

    def known(self, k: int, x: Array, tol: float) -> bool:
        """A followed attractor lies within ``tol`` (max norm) of ``x`` at the k-th swept value."""
        for orbits in self.at:
            pt = orbits[k]
            if pt is not None and float(np.max(np.abs(pt.y[:2] - x))) < tol:
                return True
        return False

    def add(self, seed: al.Point) -> None:
        bounds = (float(self.values[0]), float(self.values[-1]))
        cur = al.curve(self.fam, seed, bounds, self.ds_max, self.max_points)
        pts = cur.points
        c = len(self.curves)
        self.curves.append(cur)
        i = 0
        while i < len(pts):
            if not pts[i].stable:
                i += 1
                continue
            j = i
            while j + 1 < len(pts) and pts[j + 1].stable:
                j += 1
            self.runs.append((c, i, j))
            self.at.append([self._orbit(pts, i, j, float(lam)) for lam in self.values])
            i = j + 1

    def _orbit(self, pts: list[al.Point], i: int, j: int, lam: float) -> al.Point | None:
        """The run's stable orbit at ``lam`` (chords from one point before to one after the run)."""
        lo, hi = max(i - 1, 0), min(j + 1, len(pts) - 1)
        for pt in al.at_parameter(self.fam, pts[lo:hi + 1], lam):
            if pt.stable and pt.energy_max < self.fam.xi_max:
                return pt
        return None


@api_provenance
def continue_attractors(Omega: npt.ArrayLike, F: npt.ArrayLike, damping: float, well: WellLike = None, *,
                        Psi: float = 0.0, xi_max: float | None = None, n_grid: int = 101, n_iter: int | None = None,
                        step_max: float | None = None, max_points: int = 400,
                        steps_per_cycle: int = engine.DEFAULT_STEPS_PER_CYCLE,
                        threads: int | None = None) -> xr.Dataset:
    """The period-1 attractors inside the well followed across a sweep of Omega or of F, with their
    basins' integrity (module docstring; docs/continuation.md).

    Parameters
    ----------
    Omega, F : forcing frequency (> 0) and amplitude (>= 0) of
        ``q'' + beta q' + V'(q) = F sin(Omega t + Psi)``: one of them a 1-D sweep of at least 2
        increasing values (the continuation parameter lambda and the values where the basins are
        measured), the other a scalar.
    damping : beta > 0 (without damping there is no attractor).
    well : the potential (None: the paper's quartic; any form of :func:`safebasins.wells.resolve_well`).
    Psi : forcing phase at the section ``t = 0`` of the stroboscopic map (radians).
    xi_max : escape energy (default the barrier energy): the compiled map's escape test ``H0 > xi_max``,
        and a branch ends where the largest ``H0`` on its orbit reaches it.
    n_grid : nodes per side of the IC grid over the well's IC window (``Well.ic_window``).
    n_iter : map iterations of the labels (default ``max(50, 2 SETTLE / (beta T))``: transients
        decayed to ``exp(-SETTLE)``).
    step_max : largest arclength step in ``(q, p, kappa lambda)`` (``kappa`` = the IC window's q-width
        over the sweep's width; default that width / 20).
    max_points : points per direction of a branch at most.
    steps_per_cycle, threads : of the compiled map of the labels.

    Returns
    -------
    xr.Dataset with dims ``point`` (the continued branches, every curve in arclength order),
    ``multiplier`` (2), ``event``, ``attractor`` (each stable stretch of a branch), ``end`` (its low and
    high lambda end), the swept parameter (``Omega`` or ``F``, the sweep's values), ``q0``, ``p0``:

    * point: ``curve``, ``arclength``, ``parameter`` (lambda), ``q``, ``p`` (the fixed point),
      ``amplitude`` (largest ``|q|`` over the period), ``harmonic_amplitude``, ``phase_lag`` (``q ~
      a sin(Omega t + Psi - lag)``), ``energy_max``, ``multiplier_real``, ``multiplier_imag``,
      ``stable``, ``point_attractor`` (-1 on unstable points), ``residual``;
    * event: ``event_kind`` (flags of :data:`safebasins.analysis.arclength.EVENT_KINDS`: bifurcations
      and each curve's two ends, ``left_well`` / ``range_end`` / ``step_failure`` / ``max_points`` /
      ``closed``), ``event_curve``, ``event_parameter``, ``event_q``, ``event_p``,
      ``event_amplitude``, ``event_multiplier_real`` (event, multiplier), ``event_located`` (False
      where the location failed and the event's point is the nearest point of the branch);
    * attractor: ``attractor_curve``, ``attractor_class`` (:data:`ATTRACTOR_CLASSES`),
      ``attractor_end_parameter`` and ``attractor_end_kind`` (attractor, end: the lambda where the
      attractor ends and why: an event kind), ``cliff_low``, ``cliff_high``, ``cliff_drop`` (the
      neighbouring swept values between which the most of its basin escapes, and that GIM; NaN if
      none of it ever escapes);
    * (sweep, attractor): ``exists``, ``q_attractor``, ``p_attractor``, ``amplitude_attractor``,
      ``multiplier_modulus``, ``GIM``, ``LIM``, ``lim_radius``, ``basin_fraction`` (share of the IC
      window), ``basin_nodes``, ``matched`` (a label of the grid is this attractor's); NaN where the
      attractor does not exist at that value (``exists`` False), 0 where it exists but no grid node
      settles on it (``matched`` False: its basin is below the grid's resolution); ``lost_to_escape``
      (the GIM of its basin at the previous swept value whose nodes escape at this one; NaN at the first);
    * sweep: ``GIM_safe`` (every IC not escaping), ``lost_safe`` (as ``lost_to_escape``, the whole safe
      basin; its cliff in the scalars ``safe_cliff_low``, ``safe_cliff_high``, ``safe_cliff_drop``),
      ``n_grid_attractors`` (labels of any period up to :data:`PERIOD_MAX`), ``n_unfollowed`` (labels
      matched by no followed attractor: period > 1 or a fixed point Newton did not converge on),
      ``n_unsettled``; ``basin`` (sweep, q0, p0): -1 another attractor, 0 escape, k + 1 followed
      attractor k.
    """
    name, values, F0, Om0 = _check_sweep(Omega, F)
    beta = checks.check_positive_damping(damping, "without damping there is no attractor to follow")
    w = resolve_well(well)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    xi = float(w.check_threshold("xi_max", w.barrier_energy if xi_max is None else xi_max))
    n_grid = checks.check_positive_int("n_grid", n_grid)
    if n_grid < 9:
        raise ValueError(f"n_grid must be at least 9 (nodes per side of the IC grid), got {n_grid}")
    n_it = None if n_iter is None else check_cycles("n_iter", n_iter)
    max_points = checks.check_positive_int("max_points", max_points)
    if max_points < 3:
        raise ValueError(f"max_points must be at least 3, got {max_points}")
    (q_lo, q_hi), (p_lo, p_hi) = w.ic_window()
    width = q_hi - q_lo
    ds_max = width / 20.0 if step_max is None else checks.check_scalar("step_max", step_max, checks.check_positive)
    spc = engine.check_steps_per_cycle(steps_per_cycle)
    for om in (values if name == "Omega" else [Om0]):
        spc = engine.check_step(float(om), spc, w)
    n_threads = engine.check_threads(threads)

    fam = al.Family(well=w, F=F0, Omega=Om0, beta=beta, Psi=Psi, parameter=name,
                    kappa=width / float(values[-1] - values[0]), xi_max=xi)
    q0, p0 = np.linspace(q_lo, q_hi, n_grid), np.linspace(p_lo, p_hi, n_grid)
    labels = [_labels(w, *fam.forcing(float(v)), beta, Psi, xi, q0, p0, n_it, spc, n_threads) for v in values]
    tr = _Tracker(fam, values, ds_max, max_points)
    tol = MATCH_TOL * width
    e_lam = np.array([0.0, 0.0, 1.0])
    for k, lab in enumerate(labels):
        for qa, pa, per in zip(lab.attrs["attractor_q"], lab.attrs["attractor_p"], lab.attrs["attractor_period"]):
            if per != 1 or tr.known(k, np.array([qa, pa]), tol):
                continue
            seed = al.correct(fam, np.array([qa, pa, float(values[k])]), e_lam)
            if seed is None or not seed.stable or seed.energy_max >= xi or tr.known(k, seed.y[:2], 1e-6 * width):
                continue
            tr.add(seed)
    return _dataset(w, fam, values, tr, labels, q0, p0, xi, tol,
                    dict(damping=beta, Psi=Psi, xi_max=xi, parameter=name, kappa=fam.kappa, step_max=ds_max,
                         n_grid=n_grid, steps_per_cycle=spc, period_max=PERIOD_MAX, match_tol=tol,
                         **({"F": F0} if name == "Omega" else {"Omega": Om0})))


def _integrity(w: Well, tr: _Tracker, labels: list[xr.DataArray], q0: Array, p0: Array, xi: float,
               tol: float) -> tuple[dict[str, Array], Array, npt.NDArray[np.int16]]:
    """Per (sweep, attractor) the basin measures, per sweep value the safe GIM and counts, and the remapped labels."""
    n_s, n_a = len(labels), len(tr.runs)
    out = {k: np.full((n_s, n_a), np.nan) for k in ("q", "p", "amp", "mu", "GIM", "LIM", "r", "frac")}
    out["nodes"] = np.zeros((n_s, n_a))
    out["matched"] = np.zeros((n_s, n_a))
    per_sweep = np.zeros((n_s, 5))          # GIM_safe, n labels, n unfollowed, n unsettled, unforced nodes
    basin = np.zeros((n_s, q0.size, p0.size), np.int16)
    for k, lab in enumerate(labels):
        L = np.asarray(lab.values)
        aq, ap = np.asarray(lab.attrs["attractor_q"], float), np.asarray(lab.attrs["attractor_p"], float)
        per = np.asarray(lab.attrs["attractor_period"], int)
        owner = np.full(aq.size, -1)
        for a in range(n_a):
            pt = tr.at[a][k]
            if pt is None:
                continue
            out["q"][k, a], out["p"][k, a], out["amp"][k, a] = pt.y[0], pt.y[1], pt.amplitude
            out["mu"][k, a] = float(np.max(np.abs(pt.mu)))
            d = np.maximum(np.abs(aq - pt.y[0]), np.abs(ap - pt.y[1]))
            d[(per != 1) | (owner >= 0)] = np.inf
            if d.size and float(np.min(d)) < tol:
                owner[int(np.argmin(d))] = a
        masks = np.stack([L == j + 1 for j in range(aq.size)] + [L != 0]) if aq.size else (L != 0)[None]
        m = integrity_measures(masks, q0, p0, np.full(masks.shape[0], xi), well=w)
        per_sweep[k] = (m["GIM"][-1], aq.size, int((owner < 0).sum()), lab.attrs.get("n_unsettled", 0),
                        m["area_unforced"][-1] / ((q0[1] - q0[0]) * (p0[1] - p0[0])))
        basin[k][L != 0] = -1
        for j in range(aq.size):
            a = int(owner[j])
            if a < 0:
                continue
            basin[k][L == j + 1] = a + 1
            pt = tr.at[a][k]
            assert pt is not None
            r = integrity_measures(masks[j], q0, p0, bottom=(float(pt.y[0]), float(pt.y[1])))["r_local"]
            out["GIM"][k, a], out["r"][k, a] = m["GIM"][j], float(r)
            out["LIM"][k, a] = float(r) / m["r_local_unforced"][j]
            out["frac"][k, a], out["nodes"][k, a] = masks[j].mean(), masks[j].sum()
            out["matched"][k, a] = 1
        for a in range(n_a):                # exists, no node settles on it: a basin below the grid's resolution
            if tr.at[a][k] is not None and not out["matched"][k, a]:
                out["GIM"][k, a] = out["LIM"][k, a] = out["r"][k, a] = out["frac"][k, a] = 0.0
    return out, per_sweep, basin


def _lost(basin: npt.NDArray[np.int16], label: int, unforced: Array) -> Array:
    """Per swept value (from the second), the nodes of ``label``'s basin at the previous value that escape at
    this one, over the unforced safe set's nodes (GIM units); NaN at the first value."""
    out = np.full(basin.shape[0], np.nan)
    out[1:] = ((basin[:-1] == label) & (basin[1:] == 0)).sum(axis=(1, 2)) / unforced[1:]
    return out


def _cliff(values: Array, lost: Array) -> tuple[float, float, float]:
    """The neighbouring swept values between which the most of a basin is lost to escape (NaN triple if none)."""
    if not np.nanmax(lost, initial=0.0) > 0:
        return math.nan, math.nan, math.nan
    k = int(np.nanargmax(lost))
    return float(values[k - 1]), float(values[k]), float(lost[k])


def _end(curve: al.Curve, i: int, lower: bool) -> tuple[str, float]:
    """Why and where (lambda) the run ending at point ``i`` of ``curve`` ends (towards its first point if
    ``lower``): the curve's end, or the bifurcation located at that point or the next."""
    pts = curve.points
    j = i - 1 if lower else i + 1
    if j < 0 or j >= len(pts):
        e = curve.ends[0 if lower else 1]
        return e.kind, float(e.point.y[2])
    for e in curve.events:
        if e.point is pts[i] or e.point is pts[j]:
            return e.kind, float(e.point.y[2])
    # a multiplier crossed +-1 between two points without a located event (its location failed)
    kind = "period_doubling" if pts[j].f_minus * pts[i].f_minus < 0 else "fold"
    return kind, float(0.5 * (pts[i].y[2] + pts[j].y[2]))


def _dataset(w: Well, fam: al.Family, values: Array, tr: _Tracker, labels: list[xr.DataArray], q0: Array,
             p0: Array, xi: float, tol: float, attrs: dict[str, Any]) -> xr.Dataset:
    name = fam.parameter
    pts = [(c, p) for c, cur in enumerate(tr.curves) for p in cur.points]
    evs = [(c, e) for c, cur in enumerate(tr.curves) for e in (cur.ends[0], *cur.events, cur.ends[1])]
    run_of = {}
    for a, (c, i, j) in enumerate(tr.runs):
        for p in tr.curves[c].points[i:j + 1]:
            run_of[id(p)] = a
    Y = np.array([p.y for _, p in pts]).reshape(-1, 3)
    mu = np.array([p.mu for _, p in pts]).reshape(-1, 2)
    lag = np.array([p.lag for _, p in pts])
    res, per_sweep, basin = _integrity(w, tr, labels, q0, p0, xi, tol)
    n_a = len(tr.runs)
    ends = np.full((n_a, 2), np.nan)
    end_kind = np.zeros((n_a, 2), np.int8)
    cls = np.zeros(n_a, np.int8)
    cliff = np.full((n_a, 3), np.nan)
    lost = np.full((values.size, n_a), np.nan)
    for a, (c, i, j) in enumerate(tr.runs):
        run = tr.curves[c].points[i:j + 1]
        both = [_end(tr.curves[c], i, True), _end(tr.curves[c], j, False)]
        both.sort(key=lambda e: e[1])
        ends[a] = [e[1] for e in both]
        end_kind[a] = [al.EVENT_KINDS.index(e[0]) for e in both]
        res_lag = np.array([p.lag for p in run]) > 0.5 * np.pi
        cls[a] = 1 if res_lag.all() else (0 if not res_lag.any() else 2)
        lost[:, a] = _lost(basin, a + 1, per_sweep[:, 4])
        cliff[a] = _cliff(values, lost[:, a])
    g_safe = per_sweep[:, 0]
    lost_safe = _lost(np.where(basin != 0, 1, 0).astype(np.int16), 1, per_sweep[:, 4])
    safe_cliff = _cliff(values, lost_safe)
    exists = np.isfinite(res["q"])
    flags = {"flag_values": np.arange(len(al.EVENT_KINDS), dtype=np.int8), "flag_meanings": " ".join(al.EVENT_KINDS)}
    P, PM, E, EM, A, AE, SA, S = (("point",), ("point", "multiplier"), ("event",), ("event", "multiplier"),
                                  ("attractor",), ("attractor", "end"), (name, "attractor"), (name,))

    def var(dims: tuple[str, ...], data: Any, long_name: str, **extra: Any) -> tuple[tuple[str, ...], Any,
                                                                                   dict[str, Any]]:
        units = {} if np.asarray(data).dtype.kind in "bU" or "flag_values" in extra else _ONE
        return dims, data, {**units, "long_name": long_name, **extra}

    lam_name = {"Omega": "forcing frequency Omega", "F": "forcing amplitude F"}[name]
    ev_mu = np.array([e.point.mu.real for _, e in evs]).reshape(-1, 2)
    data = {
        "curve": var(P, np.array([c for c, _ in pts], np.int64), "index of the continued curve"),
        "arclength": var(P, np.array([p.s for _, p in pts]), "arclength along the curve in (q, p, kappa lambda)"),
        "parameter": var(P, Y[:, 2], f"{lam_name} along the branches"),
        "q": var(P, Y[:, 0], "q of the period-1 orbit at the section (fixed point of the period map)"),
        "p": var(P, Y[:, 1], "p of the period-1 orbit at the section (fixed point of the period map)"),
        "amplitude": var(P, np.array([p.amplitude for _, p in pts]), "largest |q| over the period"),
        "harmonic_amplitude": var(P, np.array([p.harmonic for _, p in pts]),
                                  "amplitude of the first harmonic of q(t)"),
        "phase_lag": (P, lag, {"units": "rad", "long_name": "lag of the first harmonic of q behind the forcing"}),
        "energy_max": var(P, np.array([p.energy_max for _, p in pts]), "largest energy H0 over the period"),
        "multiplier_real": var(PM, mu.real, "Floquet multiplier, real part (larger modulus first)"),
        "multiplier_imag": var(PM, mu.imag, "Floquet multiplier, imaginary part"),
        "stable": var(P, np.array([p.stable for _, p in pts], bool), "both multipliers inside the unit circle"),
        "point_attractor": var(P, np.array([run_of.get(id(p), -1) for _, p in pts], np.int64),
                         "index of the attractor (stable stretch) the point belongs to; -1: unstable"),
        "residual": var(P, np.array([p.residual for _, p in pts]), "|P(x) - x| at Newton's last evaluation"),
        "event_kind": (E, np.array([al.EVENT_KINDS.index(e.kind) for _, e in evs], np.int8),
                       {"long_name": "bifurcation or end of a branch", **flags}),
        "event_curve": var(E, np.array([c for c, _ in evs], np.int64), "curve of the event"),
        "event_parameter": var(E, np.array([e.point.y[2] for _, e in evs]), f"{lam_name} at the event"),
        "event_q": var(E, np.array([e.point.y[0] for _, e in evs]), "q of the orbit at the event"),
        "event_p": var(E, np.array([e.point.y[1] for _, e in evs]), "p of the orbit at the event"),
        "event_amplitude": var(E, np.array([e.point.amplitude for _, e in evs]),
                               "largest |q| of the orbit at the event"),
        "event_multiplier_real": var(EM, ev_mu, "real parts of the multipliers at the event"),
        "event_located": var(E, np.array([e.located for _, e in evs], bool),
                             "the event is located (False: its location failed, the nearest point found)"),
        "attractor_curve": var(A, np.array([c for c, _, _ in tr.runs], np.int64), "curve of the attractor"),
        "attractor_class": (A, cls, {"long_name": "lag of the first harmonic below / above pi/2 on the whole "
                                                  "attractor, or both", "flag_values": np.arange(3, dtype=np.int8),
                                     "flag_meanings": " ".join(ATTRACTOR_CLASSES)}),
        "attractor_end_parameter": var(AE, ends, f"{lam_name} where the attractor ends"),
        "attractor_end_kind": (AE, end_kind, {"long_name": "why the attractor ends there", **flags}),
        "cliff_low": var(A, cliff[:, 0], "swept value before the largest loss of the basin to escape (Dover cliff)"),
        "cliff_high": var(A, cliff[:, 1], "swept value after the largest loss of the basin to escape"),
        "cliff_drop": var(A, cliff[:, 2], "GIM of the basin lost to escape between cliff_low and cliff_high"),
        "lost_to_escape": var(SA, lost, "GIM of the basin at the previous swept value that escapes at this one"),
        "exists": var(SA, exists, "the attractor exists at this value"),
        "matched": var(SA, res["matched"].astype(bool), "a grid label settles on the attractor"),
        "q_attractor": var(SA, res["q"], "q of the attractor at the section"),
        "p_attractor": var(SA, res["p"], "p of the attractor at the section"),
        "amplitude_attractor": var(SA, res["amp"], "largest |q| over the attractor's period"),
        "multiplier_modulus": var(SA, res["mu"], "largest Floquet multiplier modulus of the attractor"),
        "GIM": var(SA, res["GIM"], "GIM: area of the attractor's basin over the unforced safe area"),
        "LIM": var(SA, res["LIM"], "LIM: largest disc about the attractor in its basin, over the unforced LIM"),
        "lim_radius": var(SA, res["r"], "radius of the largest disc about the attractor inside its basin"),
        "basin_fraction": var(SA, res["frac"], "share of the IC window in the attractor's basin"),
        "basin_nodes": var(SA, res["nodes"].astype(np.int64), "grid nodes settling on the attractor"),
        "GIM_safe": var(S, g_safe, "GIM of the safe basin (every IC that does not escape)"),
        "n_grid_attractors": var(S, per_sweep[:, 1].astype(np.int64), "attractors of the labels (period <= 4)"),
        "n_unfollowed": var(S, per_sweep[:, 2].astype(np.int64), "labels' attractors no followed attractor matches"),
        "n_unsettled": var(S, per_sweep[:, 3].astype(np.int64), "ICs not settled within the map iterations"),
        "basin": ((name, "q0", "p0"), basin, {"long_name": "basin: -1 another attractor, 0 escape, k + 1 attractor k"}),
        "lost_safe": var(S, lost_safe, "GIM of the safe basin at the previous swept value that escapes at this one"),
        "safe_cliff_low": var((), safe_cliff[0], "swept value before the largest loss of the safe basin to escape"),
        "safe_cliff_high": var((), safe_cliff[1], "swept value after the largest loss of the safe basin to escape"),
        "safe_cliff_drop": var((), safe_cliff[2], "GIM of the safe basin lost to escape there"),
    }
    ds = xr.Dataset(
        data,
        coords={name: (name, values, cf.attrs(name)), "q0": ("q0", q0, cf.attrs("q0")),
                "p0": ("p0", p0, cf.attrs("p0")),
                "end": ("end", np.array(["low", "high"]), {"long_name": "end of the attractor in lambda"}),
                "attractor": ("attractor", np.arange(n_a), {**_ONE, "long_name": "attractor index"}),
                "multiplier": ("multiplier", np.arange(2), {**_ONE, "long_name": "Floquet multiplier index"})},
        attrs={"title": f"period-1 attractors of the damped forced well followed across {name}, with their "
                        "basins' integrity", **well_attrs(w), **attrs,
               "escape_criteria": criteria.criteria_text(w),
               "integrator": engine.integrator_text(engine.DEFAULT_INTEGRATOR, fam.beta),
               "method": "branches: pseudo-arclength continuation of the fixed point of the DOP853 period map, "
                         f"rtol {al.RTOL:g} (analysis.arclength; events by Illinois regula falsi); basins: "
                         "compiled stroboscopic map and analysis.basin_labels.map_labels; GIM, LIM: "
                         "analysis.integrity"})
    return cf.annotate(ds)
