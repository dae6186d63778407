"""Stochastic integrity: safe basins and erosion profiles of the escape probability under noise.

Under noise an initial condition is not safe or unsafe but escapes with a probability
``P_escape(q0, p0, t_eval)`` (:func:`safebasins.numerics.escape_probability`).  The stochastic
safe basin of level ``epsilon`` (Soliman & Thompson's stochastic integrity) is

    S_epsilon(t_eval) = {(q0, p0) : P_escape(q0, p0, t_eval) <= epsilon},

the ICs that escape within ``t_eval`` with probability at most ``epsilon``; its GIM, LIM and IF are
those of the deterministic basin (:func:`safebasins.analysis.integrity.integrity_measures` on the
boolean mask, normalised by the unforced set S0(xi_max) on the same grid, LIM about ``bottom``).

``P_escape`` is estimated from a finite number of paths.  The **conservative** basin

    S_epsilon^+(t_eval) = {(q0, p0) : P_escape_high(q0, p0, t_eval) <= epsilon}

uses the upper end of the 95% Wilson interval instead: each of its ICs is safe at level epsilon
with 95% confidence (pointwise, not simultaneously over the grid).  With ``paths`` paths the
smallest upper bound is ``z^2 / (paths + z^2)`` (no path escaped, z = 1.96): below that epsilon the
conservative basin is empty whatever the dynamics, and is refused.  At ``noise = 0`` every path is
the deterministic trajectory, ``P_escape`` is exact (0 or 1) and the counts are not binomial
samples: the conservative basin is the basin itself.

Exact relations (hold for every sample, not only on average): S_epsilon grows with epsilon and
shrinks with t_eval, S_epsilon^+ is inside S_epsilon, so GIM, LIM and IF follow.  At noise = 0,
S_epsilon is the deterministic safe basin ``escape_cycle > t_eval`` of the same grid, bit for bit
for every epsilon in (0, 1).  In the noise amplitude sigma there is no exact monotonicity (neither
for the true probabilities, nor for the same random numbers scaled by sigma).

:func:`stochastic_erosion` is the profile of these measures against sigma and/or F, one ensemble
per (F, sigma), all with the same seed (common random numbers: path m of an IC draws the same
Gaussians at every sigma and F, so neighbouring profile points differ by the dynamics, not by
independent sampling).

From the averaged theory (:func:`safebasins.theory.escape_probability`, a deterministic solve of
the backward Kolmogorov equation with no path counts) the basin is the plain set S_epsilon: there is
no confidence interval, so no conservative basin, and the Dataset's ``conservative`` attribute says
so.  :func:`stochastic_erosion_theory` is the profile from the theory, one solve per (F, sigma),
read by the same code.  docs/stochastic-integrity.md.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.analysis.integrity import MEASURE_ATTRS, grid_spacing, integrity_measures
from safebasins.core import cf, checks
from safebasins.core.cf import annotate
from safebasins.core.statistics import WILSON_Z, certifiable_epsilon, paths_needed
from safebasins.numerics import escape_probability
from safebasins.theory import escape_probability as theory_escape_probability
from safebasins.theory.noise_escape import RANGE_TOL
from safebasins.wells import from_attrs, resolve_well, well_attrs
from safebasins.wells.base import Well, WellLike
from safebasins.wells.provenance import api_provenance

__all__ = ["stochastic_safe_basin", "stochastic_erosion", "stochastic_erosion_theory", "certifiable_epsilon",
           "paths_to_certify"]

#: the measures computed for each basin (the normalisers area/r_*_unforced are shared)
MEASURES = ("GIM", "LIM", "IF", "area", "r_local", "r_global", "if_q0", "if_p0")
NORMALISERS = ("area_unforced", "r_local_unforced", "r_global_unforced")
#: suffix of the conservative basin's variables
CONSERVATIVE = "_conservative"

SAFE_ATTRS = {
    "safe": {"units": "1", "long_name": "stochastic safe basin: P_escape <= epsilon at t_eval"},
    "safe_conservative": {"units": "1", "long_name": "conservative stochastic safe basin: upper end of the 95% "
                                                     "Wilson interval P_escape_high <= epsilon at t_eval"},
}
DEFINITION = ("safe = P_escape <= epsilon (fraction of paths escaped at or before t_eval); conservative: "
              "P_escape_high <= epsilon (upper end of the 95% Wilson interval: safe at level epsilon with 95% "
              "confidence, pointwise); GIM/LIM/IF of the masks by safebasins.analysis.integrity.integrity_measures")
THEORY_DEFINITION = ("safe = P_escape <= epsilon (P_escape of the averaged theory, "
                     "safebasins.theory.escape_probability); GIM/LIM/IF of the mask by "
                     "safebasins.analysis.integrity.integrity_measures")
NO_CONSERVATIVE = ("none: the averaged theory's P_escape is a deterministic solve with no path counts, so no "
                   "confidence interval and no conservative basin")
#: the keywords of theory.escape_probability that stochastic_erosion_theory passes on
THEORY_KWARGS = ("cells", "steps_per_cycle", "advection", "noise_time")
ZERO_NOISE = ("at noise = 0 every path is the deterministic trajectory: P_escape is exact (0 or 1), the "
              "conservative basin is the basin, and one path per initial condition is integrated")
#: ensemble attributes carried into the basins' and profiles' Datasets
_CARRIED = ("F", "Omega", "Psi", "xi_max", "noise", "noise_time", "paths", "seed", "cycles", "steps_per_cycle",
            "damping", "noise_model", "noise_scheme", "variates", "integrator", "random_numbers",
            "boundary_correction", "escape_criteria", "theory", "solver")


# --------------------------------------------------------------------------- checks
def paths_to_certify(epsilon: npt.ArrayLike) -> int:
    """The fewest paths whose Wilson upper bound at no escape is <= ``epsilon`` (the smallest, for
    several): ``ceil(z^2 (1 - epsilon) / epsilon)`` (checked against :func:`certifiable_epsilon`)."""
    return paths_needed(float(_check_epsilon(epsilon)[0].min()))


def _check_epsilon(epsilon: Any) -> tuple[npt.NDArray[np.float64], bool]:
    """``epsilon`` as a 1-D array in (0, 1), strictly increasing, and whether it was a scalar."""
    a = checks.check_finite("epsilon", epsilon)
    if a.ndim > 1:
        raise ValueError(f"epsilon must be a scalar or a 1-D sequence, got shape {a.shape}")
    e = checks.check_nonempty("epsilon", np.atleast_1d(a).astype(float))
    if ((e <= 0) | (e >= 1)).any():
        raise ValueError(f"epsilon must lie in (0, 1) (a probability of escape), got {checks.value_repr(a)}")
    if (np.diff(e) <= 0).any():
        raise ValueError(f"epsilon must be strictly increasing, got {checks.value_repr(a)}")
    return e, a.ndim == 0


def _check_sweep(name: str, value: Any) -> tuple[npt.NDArray[np.float64], bool]:
    """A scalar or strictly increasing 1-D sequence of values >= 0 (``noise``, ``F``)."""
    a = checks.check_nonnegative(name, value)
    if a.ndim > 1:
        raise ValueError(f"{name} must be a scalar or a 1-D sequence, got shape {a.shape}")
    e = checks.check_nonempty(name, np.atleast_1d(a).astype(float))
    if (np.diff(e) <= 0).any():
        raise ValueError(f"{name} must be strictly increasing, got {checks.value_repr(a)}")
    return e, a.ndim == 0


def _check_bool(name: str, value: object) -> None:
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {value!r}")


def _check_certifiable(eps: npt.NDArray[np.float64], paths: int) -> None:
    floor = certifiable_epsilon(paths)
    if float(eps.min()) < floor:
        raise ValueError(f"epsilon = {float(eps.min())!r} is below {floor:.4g}, the smallest upper end of the 95% "
                         f"Wilson interval that {paths} paths can give (none escaped): the conservative basin "
                         f"would be empty whatever the dynamics; use paths >= {paths_to_certify(float(eps.min()))} "
                         "or conservative=False")


def _is_theory(ds: xr.Dataset) -> bool:
    """A map of the averaged theory (theory.escape_probability): no path counts."""
    return "theory" in ds.attrs and "paths" not in ds.attrs


def _check_ensemble(ds: Any) -> xr.Dataset:
    """``ds`` is an escape-probability map of numerics.escape_probability or theory.escape_probability
    on a (q0, p0) grid."""
    if not isinstance(ds, xr.Dataset):
        raise ValueError("ds must be the Dataset of numerics.escape_probability or theory.escape_probability, got "
                         f"{type(ds).__name__}")
    theory = _is_theory(ds)
    missing = [v for v in (("P_escape",) if theory else ("P_escape", "P_escape_high")) if v not in ds]
    missing += [a for a in (("noise", "xi_max", "well") if theory else ("noise", "paths", "xi_max", "well"))
                if a not in ds.attrs]
    if missing:
        raise ValueError(f"ds is not an escape-probability map: it lacks {', '.join(map(repr, missing))} "
                         "(make it with numerics.escape_probability or theory.escape_probability)")
    if not {"q0", "p0", "t_eval"} <= set(ds["P_escape"].dims):
        raise ValueError(f"ds must be an escape-probability map on a (q0, p0) grid (integrity measures need a grid; "
                         f"paired initial conditions have none), got P_escape dims {ds['P_escape'].dims}")
    grid_spacing(ds["q0"].values, ds["p0"].values)
    tol = RANGE_TOL if theory else 0.0     # the theory's Eulerian marches may overshoot by up to its own bound
    for v in ("P_escape",) if theory else ("P_escape", "P_escape_high"):
        x = ds[v].values
        if not ((x >= -tol) & (x <= 1 + tol)).all():       # (NaN fails too)
            raise ValueError(f"ds: {v} must be probabilities in [0, 1], got values outside (or NaN)")
    return ds


def _select_t_eval(ds: xr.Dataset, t_eval: npt.ArrayLike | None) -> xr.Dataset:
    if t_eval is None:
        return ds
    t = checks.check_finite("t_eval", t_eval)
    if t.ndim > 1:
        raise ValueError(f"t_eval must be a scalar or 1-D, got shape {t.shape}")
    have = ds["t_eval"].values
    absent = [float(x) for x in np.atleast_1d(t) if not (have == x).any()]
    if absent:
        raise ValueError(f"t_eval {absent} not in the map's evaluation times {have.tolist()} (escape_probability "
                         "evaluates P_escape only at its own t_eval)")
    return ds.sel(t_eval=float(t) if t.ndim == 0 else t)


# --------------------------------------------------------------------------- basins
def _measures(mask: xr.DataArray, xi_max: float, well: Well, bottom: tuple[float, float], suffix: str
              ) -> xr.Dataset:
    m = integrity_measures(mask, xi_max=xi_max, well=well, bottom=bottom)
    names = MEASURES + (NORMALISERS if not suffix else ())
    out = m[list(names)].rename({k: k + suffix for k in MEASURES})
    if suffix:
        for k in MEASURES:
            out[k + suffix].attrs["long_name"] = (MEASURE_ATTRS[k]["long_name"] +
                                                  ", conservative basin (P_escape_high <= epsilon)")
    return out.assign_attrs(m.attrs)


def _basin(ds: xr.Dataset, epsilon: Any, t_eval: npt.ArrayLike | None, conservative: bool | None,
           bottom: tuple[float, float]) -> xr.Dataset:
    ds = _check_ensemble(ds)
    theory = _is_theory(ds)
    eps, eps_scalar = _check_epsilon(epsilon)
    if conservative is None:
        conservative = not theory
    _check_bool("conservative", conservative)
    if theory and conservative:
        raise ValueError("conservative=True needs path counts (the Wilson interval of numerics.escape_probability); "
                         "the averaged theory's map has none: use conservative=False or None")
    b = checks.check_finite("bottom", bottom)
    if b.shape != (2,):
        raise ValueError(f"bottom must be a pair (q0, p0), got {checks.value_repr(b)}")
    bottom = (float(b[0]), float(b[1]))
    deterministic = float(ds.attrs["noise"]) == 0.0
    if conservative and not deterministic:
        _check_certifiable(eps, int(ds.attrs["paths"]))
    sel = _select_t_eval(ds, t_eval)
    e = xr.DataArray(eps[0] if eps_scalar else eps, dims=() if eps_scalar else ("epsilon",),
                     attrs=cf.attrs("epsilon"))
    well = from_attrs(ds.attrs)
    xi = float(ds.attrs["xi_max"])
    safe = (sel["P_escape"] <= e).assign_coords(epsilon=e).transpose(..., "q0", "p0")
    out = _measures(safe, xi, well, bottom, "")
    out["safe"] = safe.assign_attrs(SAFE_ATTRS["safe"])
    if conservative:
        upper = sel["P_escape"] if deterministic else sel["P_escape_high"]
        cons = (upper <= e).assign_coords(epsilon=e).transpose(..., "q0", "p0")
        out = out.merge(_measures(cons, xi, well, bottom, CONSERVATIVE), compat="override", join="exact",
                        combine_attrs="override")
        out["safe_conservative"] = cons.assign_attrs(SAFE_ATTRS["safe_conservative"])
    lead = [d for d in ("epsilon", "t_eval") if d in out.dims]
    out = out.transpose(*lead, ...)
    out.attrs.update({k: ds.attrs[k] for k in _CARRIED if k in ds.attrs})
    out.attrs.update(well_attrs(well))
    if theory:
        out.attrs.update(kind="stochastic", method=THEORY_DEFINITION, conservative=NO_CONSERVATIVE)
        return out
    out.attrs.update(kind="stochastic", method=DEFINITION, confidence=f"95% Wilson score interval (z = {WILSON_Z})")
    if deterministic:
        out.attrs["zero_noise"] = ZERO_NOISE
    else:
        out.attrs["conservative_epsilon_floor"] = certifiable_epsilon(int(ds.attrs["paths"]))
    return out


@api_provenance
def stochastic_safe_basin(ds: xr.Dataset, epsilon: npt.ArrayLike, *, t_eval: npt.ArrayLike | None = None,
                          conservative: bool | None = None, bottom: tuple[float, float] = (0.0, 0.0)) -> xr.Dataset:
    """The stochastic safe basin {P_escape <= epsilon} of an escape-probability map, with GIM, LIM, IF.

    Parameters
    ----------
    ds : a Dataset of :func:`safebasins.numerics.escape_probability` (an SDE ensemble) or of
        :func:`safebasins.theory.escape_probability` (the averaged theory) on a (q0, p0) grid (1-D
        uniform axes).
    epsilon : level(s) in (0, 1); a 1-D sequence (strictly increasing) adds the dimension ``epsilon``.
    t_eval : evaluation time(s) among the map's ``t_eval`` (None: all of them; a scalar: a scalar
        coordinate).
    conservative : also the conservative basin {P_escape_high <= epsilon} (the upper end of the 95%
        Wilson interval; at noise = 0 the basin itself).  An epsilon below
        :func:`certifiable_epsilon` of the map's ``paths`` is refused (the set would be empty).
        None (default): where the map has path counts (the numerics' maps), not for the theory's,
        which have no confidence interval (True is refused for them).
    bottom : centre of the LIM disk (default the well bottom (0, 0), as the deterministic profiles;
        an attractor's position for the damped well's basins).

    Returns
    -------
    xr.Dataset over (epsilon?, t_eval?) with ``safe`` (..., q0, p0), ``GIM``, ``LIM``, ``IF`` and the
    raw measures of :func:`~safebasins.analysis.integrity.integrity_measures` (``area``, ``r_local``,
    ``r_global``, ``if_q0``, ``if_p0`` and the normalisers ``*_unforced`` of the unforced set
    S0(xi_max) on the same grid); with ``conservative`` the same with the suffix ``_conservative``
    (``safe_conservative``, ``GIM_conservative``, ...).  Attributes: the ensemble's (F, Omega, Psi,
    xi_max, noise, paths, seed, scheme, well, ...), the definition and, under noise,
    ``conservative_epsilon_floor`` (:func:`certifiable_epsilon` of the paths).  From a theory map:
    the plain basin only, the theory's attributes (``theory``, ``solver``, ...) and ``conservative``
    saying that there is no conservative basin.
    """
    return annotate(_basin(ds, epsilon, t_eval, conservative, bottom))


# --------------------------------------------------------------------------- profiles
def _stack(parts: list[xr.Dataset], name: str, values: npt.NDArray[np.float64], scalar: bool) -> xr.Dataset:
    coord = xr.DataArray(values[0] if scalar else values, dims=() if scalar else (name,), attrs=cf.attrs(name))
    if scalar:
        return parts[0].assign_coords({name: coord})
    out = xr.concat(parts, dim=name, coords="minimal", compat="override", join="override",
                    combine_attrs="drop_conflicts")
    return out.assign_coords({name: coord})


def _profile(make_map: Callable[[float, float], xr.Dataset], Fs: npt.NDArray[np.float64], F_scalar: bool,
             sig: npt.NDArray[np.float64], sig_scalar: bool, epsilon: npt.ArrayLike, t_eval: npt.ArrayLike,
             conservative: bool | None, bottom: tuple[float, float], keep_masks: bool
             ) -> tuple[xr.Dataset, dict[str, Any]]:
    """The basins of ``make_map(F, sigma)`` over the sweep, stacked over (F?, noise?, epsilon?, t_eval),
    and the attributes of one map (a noisy one where there is one), less F and noise."""
    t_one = t_eval if np.ndim(t_eval) == 0 else None     # a scalar t_eval: a scalar coordinate
    rows = []
    attrs: dict[str, Any] = {}      # a noisy ensemble's, where there is one (its paths, scheme, correction)
    for Fi in Fs:
        cols = []
        for s in sig:
            ens = make_map(float(Fi), float(s))
            part = _basin(ens, epsilon, t_one, conservative, bottom)
            if keep_masks:
                names = [v for v in ("P_escape", "P_escape_high") if v in ens]
                maps = _select_t_eval(ens[names], t_one).transpose(..., "q0", "p0")
                part = part.merge(maps, compat="override", join="exact", combine_attrs="override")
            else:
                part = part.drop_vars([v for v in ("safe", "safe_conservative") if v in part])
            if not attrs or (s > 0 and float(attrs["noise"]) == 0):
                attrs = dict(part.attrs)
            cols.append(part if keep_masks else part.drop_vars(["q0", "p0"]))
        rows.append(_stack(cols, "noise", sig, sig_scalar))
    out = _stack(rows, "F", Fs, F_scalar)
    lead = [d for d in ("F", "noise", "epsilon", "t_eval") if d in out.dims]
    out = out.transpose(*lead, ...)
    for k in ("F", "noise"):
        attrs.pop(k)
    return out, attrs


@api_provenance
def stochastic_erosion(q0: npt.ArrayLike, p0: npt.ArrayLike, F: float | Sequence[float] | npt.ArrayLike,
                       Omega: float, Psi: float, *, noise: float | Sequence[float] | npt.ArrayLike,
                       epsilon: npt.ArrayLike, paths: int, xi_max: float, t_eval: npt.ArrayLike,
                       damping: float = 0.0, well: WellLike = None, seed: int = 0, cycles: int | None = None,
                       conservative: bool = True, bottom: tuple[float, float] = (0.0, 0.0),
                       keep_masks: bool = False, **ensemble_kwargs: Any) -> xr.Dataset:
    """Stochastic erosion profile: GIM, LIM, IF of the stochastic safe basin against sigma and/or F.

    One :func:`safebasins.numerics.escape_probability` ensemble per (F, noise), every one with the
    same ``seed`` (common random numbers), read by :func:`stochastic_safe_basin`.  At noise = 0 one
    path per IC is integrated (every path is the deterministic trajectory) and the profile is the
    deterministic one of :func:`safebasins.analysis.erosion.erosion_profile_numeric` on the same grid,
    bit for bit.

    Parameters
    ----------
    q0, p0 : 1-D uniform grid axes of the initial conditions.
    F : forcing amplitude(s) >= 0; a strictly increasing sequence adds the dimension ``F``.
    Omega, Psi : forcing frequency and phase.
    noise : sigma(s) >= 0 of ``dp = ... + sigma dW``; a strictly increasing sequence adds the dimension
        ``noise``.
    epsilon : escape-probability level(s) in (0, 1) (dimension ``epsilon`` for a sequence).
    paths : paths per initial condition at each noise > 0.
    xi_max : the energy threshold (one per call, as escape_probability).
    t_eval : evaluation time(s) in forcing cycles (dimension ``t_eval``).
    damping, well, seed, cycles : as escape_probability.
    conservative, bottom : as :func:`stochastic_safe_basin`.
    keep_masks : also return ``safe`` (and ``safe_conservative``) and the maps ``P_escape``,
        ``P_escape_high`` over (..., q0, p0).
    ensemble_kwargs : passed to escape_probability (``steps_per_cycle``, ``integrator``,
        ``correction``, ``variates``, ``noise_time``, ``threads``, ``backend``).

    Returns
    -------
    xr.Dataset over (F?, noise?, epsilon?, t_eval) with the variables of :func:`stochastic_safe_basin`
    (without the masks unless ``keep_masks``).
    """
    grid_spacing(q0, p0)
    Fs, F_scalar = _check_sweep("F", F)
    sig, sig_scalar = _check_sweep("noise", noise)
    eps, _ = _check_epsilon(epsilon)
    paths = checks.check_positive_int("paths", paths)
    _check_bool("conservative", conservative)
    _check_bool("keep_masks", keep_masks)
    if conservative and (sig > 0).any():
        _check_certifiable(eps, paths)
    w = resolve_well(well)

    def ensemble(Fi: float, s: float) -> xr.Dataset:
        return escape_probability(q0, p0, Fi, Omega, Psi, noise=s, paths=paths if s > 0 else 1, xi_max=xi_max,
                                  t_eval=t_eval, damping=damping, well=w, seed=seed, cycles=cycles,
                                  **ensemble_kwargs)

    out, attrs = _profile(ensemble, Fs, F_scalar, sig, sig_scalar, epsilon, t_eval, conservative, bottom,
                          keep_masks)
    out.attrs = {**attrs, "paths": paths}
    if (sig == 0).any():
        out.attrs["zero_noise"] = ZERO_NOISE
    out.attrs["kind"] = "stochastic"
    return annotate(out)


@api_provenance
def stochastic_erosion_theory(q0: npt.ArrayLike, p0: npt.ArrayLike, F: float | Sequence[float] | npt.ArrayLike,
                              Omega: float, Psi: float, *, noise: float | Sequence[float] | npt.ArrayLike,
                              epsilon: npt.ArrayLike, xi_max: float, t_eval: npt.ArrayLike, damping: float = 0.0,
                              well: WellLike = None, bottom: tuple[float, float] = (0.0, 0.0),
                              keep_masks: bool = False, **theory_kwargs: Any) -> xr.Dataset:
    """Stochastic erosion profile from the averaged theory: GIM, LIM, IF of {P_escape <= epsilon}
    against sigma and/or F, one :func:`safebasins.theory.escape_probability` solve per (F, noise),
    read by :func:`stochastic_safe_basin` (the plain basin: the theory has no path counts, hence no
    conservative basin).

    Arguments as :func:`stochastic_erosion`, less the ensemble's (``paths``, ``seed``, ``cycles``,
    ``conservative``); ``noise`` >= 0 (at noise 0 the deterministic slow flow's first passages);
    ``well`` any well; ``theory_kwargs``:
    ``cells``, ``steps_per_cycle``, ``advection``, ``noise_time`` of theory.escape_probability.  ``keep_masks`` adds
    ``safe`` and ``P_escape`` over (..., q0, p0).

    Returns
    -------
    xr.Dataset over (F?, noise?, epsilon?, t_eval) with ``GIM``, ``LIM``, ``IF`` and the raw measures;
    attributes: the theory's (model, solver, well, ...) and ``conservative`` saying there is none.
    """
    grid_spacing(q0, p0)
    Fs, F_scalar = _check_sweep("F", F)
    sig, sig_scalar = _check_sweep("noise", noise)
    _check_epsilon(epsilon)
    _check_bool("keep_masks", keep_masks)
    unknown = sorted(set(theory_kwargs) - set(THEORY_KWARGS))
    if unknown:
        raise ValueError(f"unknown keyword(s) {unknown} for the theory's solve: expected some of {THEORY_KWARGS}")
    w = resolve_well(well)

    def solve(Fi: float, s: float) -> xr.Dataset:
        return theory_escape_probability(q0, p0, Fi, Omega, Psi, xi_max, noise=s, t_eval=t_eval, damping=damping,
                                         well=w, grid=True, **theory_kwargs)

    out, attrs = _profile(solve, Fs, F_scalar, sig, sig_scalar, epsilon, t_eval, False, bottom, keep_masks)
    out.attrs = attrs
    return annotate(out)
