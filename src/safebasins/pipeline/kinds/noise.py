"""Kinds ``escape_probability`` and ``stochastic_erosion``: escape under noise.

``escape_probability``: the probability of escape within each ``t_eval`` from ``paths`` paths per
initial condition of a (q0, p0) grid (:func:`safebasins.numerics.escape_probability`), at one or
several noise amplitudes sigma (one ensemble each, stacked over ``noise``).  ``stochastic_erosion``:
GIM, LIM and IF of the stochastic safe basin {P_escape <= epsilon} and of the conservative one
against sigma and/or F (:func:`safebasins.analysis.stochastic_erosion`, the same seed at every
point).  Both draw their random numbers from the run's seed plus the experiment's offset.
Where the averaged theory applies, ``escape_probability`` also stores its map
(:func:`safebasins.theory.escape_probability`) with the agreement and ``stochastic_erosion`` its
profile (:func:`safebasins.analysis.stochastic_integrity.stochastic_erosion_theory`), both added by
:mod:`safebasins.analysis.noise_theory` (the CLI's commands call the same functions).
Datasets: ``results/data/extras/<experiment>.nc``.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from safebasins.core.averaged_theory import CELLS, MIN_CELLS, STEPS_PER_CYCLE
from safebasins.core.statistics import certifiable_epsilon, paths_needed
from safebasins.pipeline import values
from safebasins.core.noise_variates import DEFAULT_VARIATES, VARIATES
from safebasins.pipeline.cost import NOISE_STEP_COSTS
from safebasins.pipeline.registry import Block, FigureInputs, Inputs, Job, Kind, Params, Product, dataset_path, register

if TYPE_CHECKING:
    import xarray as xr

    from safebasins.pipeline.registry import ResolveContext
    from safebasins.pipeline.validation import CheckContext

SIGMA = {"type": "number", "minimum": 0}
PROBABILITY = {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1}
TIME = {"type": "number", "minimum": 0}


def _value_or_list(item: dict[str, Any], what: str) -> dict[str, Any]:
    return {"description": what, "oneOf": [item, {"type": "array", "minItems": 1, "items": item}]}


#: the keys both kinds share (the library's defaults)
_COMMON = {
    "F": {"$ref": "#/$defs/forcing"},
    "Omega": {"$ref": "#/$defs/frequency"},
    "Psi": {"$ref": "#/$defs/angle", "default": 0.0},
    "xi_max": {"$ref": "#/$defs/threshold"},
    "grid": {"$ref": "#/$defs/grid"},
    "paths": {"description": "paths per initial condition (at noise 0 one path is integrated: every path is the "
                             "deterministic trajectory)", "type": "integer", "minimum": 1},
    "t_eval": _value_or_list(TIME, "evaluation time(s) in forcing cycles, at most cycles"),
    "cycles": {"description": "horizon in forcing cycles (null: the largest t_eval rounded up)",
               "oneOf": [{"type": "null"}, {"type": "integer", "minimum": 1}], "default": None},
    "noise_time": {"description": "correlation time tau of an Ornstein-Uhlenbeck force (0: white noise); the "
                                  "step 2 pi / (Omega steps_per_cycle) must not exceed it",
                   "type": "number", "minimum": 0, "default": 0.0},
    "correction": {"description": "discrete-monitoring correction of the energy threshold (docs/noise.md)",
                   "enum": ["shift", "none"], "default": "shift"},
    "variates": {"description": "law of the kicks' random numbers: gaussian (Box-Muller) or five-point (0, +-sqrt 2, "
                                "+-2 at 5/8, 1/8, 1/16: the same moments through the fifth, the same weak order 2, "
                                "about three times faster; docs/noise.md)",
                 "enum": list(VARIATES), "default": DEFAULT_VARIATES},
    "steps_per_cycle": {"description": "integrator steps per forcing period (null: the run's "
                                       "numerics.steps_per_cycle)",
                        "oneOf": [{"type": "null"}, {"type": "integer", "minimum": 4}], "default": None},
}


def _check_common(block: Block, key: str, ctx: CheckContext, sweeps: tuple[str, ...]) -> None:
    ctx.check_grid(f"{key}.grid", block["grid"])
    t = values.as_list(block["t_eval"])
    ctx.check_unique(f"{key}.t_eval", t)
    if block["cycles"] is not None:
        ctx.check_t_eval_within(f"{key}.t_eval", t, block["cycles"])
    for name in sweeps:
        v = block[name]
        if isinstance(v, list):
            for i in range(1, len(v)):
                if not v[i] > v[i - 1]:
                    ctx.fail(f"{key}.{name}[{i}]", f"{name} must be strictly increasing, got {v}")
    tau = float(block["noise_time"])
    spc = block["steps_per_cycle"] or ctx.config["numerics"]["steps_per_cycle"]
    h = 2.0 * math.pi / (float(block["Omega"]) * spc)
    if 0 < tau < h:
        ctx.fail(f"{key}.noise_time", f"{tau} is shorter than the step 2 pi / (Omega steps_per_cycle) = {h:.4g}: "
                                      "the coloured noise is not resolved; raise steps_per_cycle or noise_time")


def _resolve_common(block: Block, ctx: ResolveContext) -> Params:
    spc, cyc = block["steps_per_cycle"], block["cycles"]
    return dict(Omega=float(block["Omega"]), Psi=values.angle(block["Psi"]), xi_max=float(block["xi_max"]),
                grid=values.grid(block["grid"]), paths=int(block["paths"]),
                t_eval=[float(x) for x in values.as_list(block["t_eval"])],
                cycles=None if cyc is None else int(cyc), noise_time=float(block["noise_time"]),
                correction=str(block["correction"]), variates=str(block["variates"]), seed=ctx.seed,
                steps_per_cycle=ctx.steps_per_cycle if spc is None else int(spc))


def _cost(params: Params, n_ensembles: int, noisy: int) -> int:
    """paths x ICs x steps of every ensemble (one path per IC at noise 0), each noisy step counted
    with its random numbers (pipeline.cost.NOISE_STEP_COSTS of its variates, in steps of the quartic)."""
    nq, np_ = params["grid"]["n"]
    cycles = params["cycles"] if params["cycles"] is not None else math.ceil(max(params["t_eval"]))
    steps = nq * np_ * cycles * params["steps_per_cycle"]
    per_step = 1.0 + NOISE_STEP_COSTS[params["variates"]] / values.base_well(params).step_cost
    return int(steps * ((n_ensembles - noisy) + noisy * params["paths"] * per_step))


def _ensemble_kwargs(params: Params, job: Job) -> dict[str, Any]:
    return dict(paths=params["paths"], xi_max=params["xi_max"], t_eval=params["t_eval"],
                damping=values.damping(params), well=values.base_well(params), seed=params["seed"],
                cycles=params["cycles"], noise_time=params["noise_time"], correction=params["correction"],
                variates=params["variates"], steps_per_cycle=params["steps_per_cycle"], threads=job.threads)


# --------------------------------------------------------------------------- the averaged theory (both kinds)
#: where the averaged theory applies (the schema's and the docs' words)
THEORY_APPLIES = ("white or Ornstein-Uhlenbeck noise (noise_time short against the slow time; at noise 0 the "
                  "noise-free slow flow), any well (an asymmetric one in its sheared phase) and xi_max below the "
                  "barrier; elsewhere, or with false, the dataset's attribute theory is 'none' and theory_reason "
                  "says why")


def _theory_keys(stores: str) -> dict[str, Any]:
    """The averaged theory's keys (the theory's defaults, safebasins.core.averaged_theory); ``stores``:
    what the kind's dataset gains with it."""
    return {
        "theory": {"description": f"also solve the averaged theory (docs/noise-theory.md) and store {stores}. "
                                  f"It applies to {THEORY_APPLIES}", "type": "boolean", "default": True},
        "theory_cells": {"description": "the theory's polar grid (n_gamma, n_J)", "type": "array", "minItems": 2,
                         "maxItems": 2, "items": {"type": "integer", "minimum": MIN_CELLS}, "default": list(CELLS)},
        "theory_steps_per_cycle": {"description": "the theory's time steps per forcing cycle", "type": "integer",
                                   "minimum": 1, "default": STEPS_PER_CYCLE},
    }


def _resolve_theory(block: Block) -> Params:
    return dict(theory=bool(block["theory"]), theory_cells=[int(n) for n in block["theory_cells"]],
                theory_steps_per_cycle=int(block["theory_steps_per_cycle"]))


def _theory_settings(params: Params) -> dict[str, Any]:
    # the theory's switch and solver settings (analysis.noise_theory)
    return dict(noise_time=params["noise_time"], theory=params["theory"], cells=tuple(params["theory_cells"]),
                steps_per_cycle=params["theory_steps_per_cycle"])


def _theory_cost(params: Params, solves: int) -> int:
    """The theory's tables and ``solves`` solves on the IC grid
    (safebasins.analysis.noise_theory.theory_evaluations, as the command line counts them)."""
    from safebasins.analysis.noise_theory import theory_evaluations

    nq, np_ = params["grid"]["n"]
    return theory_evaluations(noise=params["noise"], t_eval=params["t_eval"], n_ics=nq * np_, solves=solves,
                              well=values.base_well(params), noise_time=params["noise_time"], theory=params["theory"],
                              cells=tuple(params["theory_cells"]), steps_per_cycle=params["theory_steps_per_cycle"])


# --------------------------------------------------------------------------- escape_probability
def build_escape_probability(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """One ensemble per noise level, stacked over ``noise`` (each the library call's Dataset), with
    the averaged theory's map and the agreement where the theory applies
    (:func:`safebasins.analysis.noise_theory.escape_probability_with_theory`)."""
    import xarray as xr

    from safebasins.analysis.noise_theory import escape_probability_with_theory
    from safebasins.numerics import escape_probability

    q0, p0 = values.grid_axes(params["grid"])
    kw = _ensemble_kwargs(params, job)
    print(f"{params['experiment']}: P_escape of {q0.size} x {p0.size} ICs, {params['paths']} paths, "
          f"noise {params['noise']}", flush=True)
    maps = []
    for s in params["noise"]:
        ds = escape_probability(q0, p0, params["F"], params["Omega"], params["Psi"], noise=s,
                                **{**kw, "paths": kw["paths"] if s > 0 else 1})
        maps.append(ds.expand_dims(noise=[s]).assign_attrs(paths=params["paths"]))
    out = xr.concat(maps, dim="noise", combine_attrs="override", data_vars="all")
    out["noise"].attrs.update(maps[0]["noise"].attrs)
    out.attrs.pop("noise", None)
    out = escape_probability_with_theory(out, params["F"], params["Omega"], params["Psi"], params["xi_max"],
                                         damping=values.damping(params), well=values.base_well(params),
                                         **_theory_settings(params))
    if "P_escape_theory" in out:
        for s in params["noise"]:
            print(f"  sigma = {s:g}: |P_escape_theory - P_escape| mean "
                  f"{float(out['P_escape_mean_abs_difference'].sel(noise=s).mean()):.4f}, max "
                  f"{float(out['P_escape_max_abs_difference'].sel(noise=s).max()):.4f} over the ICs and t_eval",
                  flush=True)
    return out


@register
class EscapeProbability(Kind):
    name = "escape_probability"
    damped = True
    any_well = True
    description = ("the probability of escape under noise within each t_eval over a grid of initial conditions, "
                   "from paths paths per IC, at one or several noise amplitudes sigma of dp = ... + sigma dW, "
                   "with the averaged theory's map and its agreement where the theory applies")
    builder = "safebasins.plotting.noise:figure_escape_probability_levels"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False,
        "required": ["F", "Omega", "xi_max", "grid", "noise", "paths", "t_eval"],
        "properties": {**_COMMON,
                       **_theory_keys("its map P_escape_theory with its agreement with the ensembles: "
                                      "P_escape_mean_abs_difference and P_escape_max_abs_difference (over the ICs, "
                                      "per noise and t_eval), P_escape_mean_abs_difference_uncertain and "
                                      "P_escape_theory_within_wilson (per noise)"),
                       "noise": _value_or_list(SIGMA, "noise amplitude(s) sigma >= 0 (a list: one ensemble each, "
                                                      "strictly increasing)")},
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        _check_common(block, key, ctx, ("noise",))

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        return dict(F=float(block["F"]), noise=[float(x) for x in values.as_list(block["noise"])],
                    **_resolve_theory(block), **_resolve_common(block, ctx))

    def cost(self, params: Params) -> int:
        n = len(params["noise"])
        return _cost(params, n, sum(1 for s in params["noise"] if s > 0))

    def analytic_cost(self, params: Params) -> int:
        return _theory_cost(params, len(params["noise"]))

    def products(self, experiment: str, params: Params) -> list[Product]:
        G = ("noise", "q0", "p0", "t_eval")
        history = "safebasins.numerics.escape_probability"
        if params["theory"]:
            history += (", where it applies safebasins.theory.escape_probability and "
                        "safebasins.analysis.agreement.probability_agreement")
        return [Product(dataset_path("extras", experiment), "extras", build_escape_probability, heavy=True,
                        title=params["title"] + " (escape probability under noise)",
                        history=f"{history} ({experiment})",
                        contract={"P_escape": G, "P_escape_low": G, "P_escape_high": G})]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"probability": dataset_path("extras", experiment)}


# --------------------------------------------------------------------------- stochastic_erosion
def build_stochastic_erosion(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """The library's profile over (F, noise, epsilon, t_eval), with the averaged theory's GIM, LIM and
    IF (``GIM_theory``, ...) where the theory applies
    (:func:`safebasins.analysis.noise_theory.stochastic_erosion_with_theory`)."""
    from safebasins.analysis import stochastic_erosion
    from safebasins.analysis.noise_theory import stochastic_erosion_with_theory

    q0, p0 = values.grid_axes(params["grid"])
    print(f"{params['experiment']}: stochastic erosion at F {params['F']}, noise {params['noise']} on "
          f"{q0.size} x {p0.size} ICs, {params['paths']} paths", flush=True)
    out = stochastic_erosion(q0, p0, params["F"], params["Omega"], params["Psi"], noise=params["noise"],
                             epsilon=params["epsilon"], conservative=params["conservative"],
                             bottom=tuple(params["bottom"]), **_ensemble_kwargs(params, job))
    return stochastic_erosion_with_theory(out, q0, p0, params["F"], params["Omega"], params["Psi"],
                                          noise=params["noise"], epsilon=params["epsilon"], xi_max=params["xi_max"],
                                          t_eval=params["t_eval"], damping=values.damping(params),
                                          well=values.base_well(params), bottom=tuple(params["bottom"]),
                                          **_theory_settings(params))


@register
class StochasticErosion(Kind):
    name = "stochastic_erosion"
    damped = True
    any_well = True
    description = ("the stochastic erosion profile: GIM, LIM and IF of the stochastic safe basin {P_escape <= "
                   "epsilon} and of the conservative one (upper end of the 95% Wilson interval <= epsilon) against "
                   "the noise amplitude sigma and the forcing F, one ensemble per (F, sigma), all with the same seed")
    builder = "safebasins.plotting.stochastic_erosion:figure_stochastic_erosion"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False,
        "required": ["F", "Omega", "xi_max", "grid", "noise", "paths", "t_eval", "epsilon"],
        "properties": {**_COMMON,
                       "F": _value_or_list({"$ref": "#/$defs/forcing"},
                                           "forcing amplitude(s) (a list, strictly increasing: a dimension F)"),
                       "noise": _value_or_list(SIGMA, "noise amplitude(s) sigma >= 0 (a list, strictly increasing: "
                                                      "a dimension noise)"),
                       "epsilon": _value_or_list(PROBABILITY, "escape-probability level(s) of the safe basin "
                                                              "(strictly increasing)"),
                       "conservative": {"description": "also the conservative basin P_escape_high <= epsilon",
                                        "type": "boolean", "default": True},
                       "bottom": {"description": "centre (q0, p0) of the LIM", "type": "array", "minItems": 2,
                                  "maxItems": 2, "items": {"type": "number"}, "default": [0.0, 0.0]},
                       **_theory_keys("its profile GIM_theory, LIM_theory, IF_theory of the basin {P_escape <= "
                                      "epsilon} (no conservative one: the theory has no path counts), one "
                                      "solve per (F, noise)")},
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        _check_common(block, key, ctx, ("F", "noise", "epsilon"))
        sig = values.as_list(block["noise"])
        if block["conservative"] and any(s > 0 for s in sig):
            eps, floor = min(values.as_list(block["epsilon"])), certifiable_epsilon(int(block["paths"]))
            if eps < floor:
                ctx.fail(f"{key}.paths", f"{block['paths']} paths certify no epsilon below {floor:.4g} (the upper end "
                                         f"of the 95% Wilson interval with no escaped path), epsilon {eps} asks for "
                                         f"paths >= {paths_needed(eps)}; or set conservative: false")

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        F = values.as_list(block["F"])
        return dict(F=[float(x) for x in F] if isinstance(block["F"], list) else float(block["F"]),
                    noise=([float(x) for x in block["noise"]] if isinstance(block["noise"], list)
                           else float(block["noise"])),
                    epsilon=([float(x) for x in block["epsilon"]] if isinstance(block["epsilon"], list)
                             else float(block["epsilon"])),
                    conservative=bool(block["conservative"]), bottom=[float(x) for x in block["bottom"]],
                    **_resolve_theory(block), **_resolve_common(block, ctx))

    def cost(self, params: Params) -> int:
        sig = values.as_list(params["noise"])
        nF = len(values.as_list(params["F"]))
        return _cost(params, nF * len(sig), nF * sum(1 for s in sig if s > 0))

    def analytic_cost(self, params: Params) -> int:
        return _theory_cost(params, len(values.as_list(params["F"])) * len(values.as_list(params["noise"])))

    def products(self, experiment: str, params: Params) -> list[Product]:
        lead = tuple(d for d in ("F", "noise", "epsilon") if isinstance(params[d], list)) + ("t_eval",)
        contract = {k: lead for k in ("GIM", "LIM", "IF")}
        if params["conservative"]:
            contract.update({k + "_conservative": lead for k in ("GIM", "LIM", "IF")})
        history = "safebasins.analysis.stochastic_erosion"
        if params["theory"]:
            history += ", where it applies safebasins.analysis.stochastic_integrity.stochastic_erosion_theory"
        return [Product(dataset_path("extras", experiment), "extras", build_stochastic_erosion, heavy=True,
                        title=params["title"] + " (stochastic erosion profile)",
                        history=f"{history} ({experiment})", contract=contract)]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"erosion": dataset_path("extras", experiment)}
