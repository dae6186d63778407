"""Kind ``continue_attractors``: the period-1 attractors of a damped well followed across a sweep of F
or of Omega, with their basins' integrity and the Dover cliff
(:func:`safebasins.analysis.continuation.continue_attractors`).  Dataset:
``results/data/extras/<experiment>.nc``.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from safebasins.core.settling import settle_iterations
from safebasins.pipeline import values
from safebasins.pipeline.registry import Block, FigureInputs, Inputs, Job, Kind, Params, Product, dataset_path, register

if TYPE_CHECKING:
    import xarray as xr

    from safebasins.pipeline.registry import ResolveContext
    from safebasins.pipeline.validation import CheckContext

#: the cost estimate of the branches: period-map evaluations per point (Newton's corrections, the event
#: location and the orbit at each swept value: measured 9-10 on the escape equation), trajectory-steps per
#: evaluation (a DOP853 period map and its four central differences at rtol 1e-11 in scipy: measured 0.027 s
#: against 1.0e8 steps/s of the compiled map on one core of the same machine), points per curve over
#: the sweep (out and back through two folds, each pass the IC window's width over step_max in the
#: scaled arclength) and curves (the resonant and the non-resonant branch)
_EVALS_PER_POINT, _STEPS_PER_EVAL, _PASSES, _CURVES = 10, 3.0e6, 3, 2
#: the library's default step_max: the IC window's q-width over this
_STEPS_ACROSS = 20.0
SWEPT = ("F", "Omega")


def build_continuation(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """The basin labels at every swept value, the attractors' branches and their basins' integrity."""
    from safebasins.analysis.continuation import continue_attractors

    sweep = params[params["sweep"]]
    print(f"{params['experiment']}: attractors followed across {params['sweep']} = {sweep[0]:g} .. {sweep[-1]:g} "
          f"({len(sweep)} values) on {params['n_grid']}^2 ICs", flush=True)
    return continue_attractors(params["Omega"], params["F"], values.damping(params), values.base_well(params),
                               Psi=params["Psi"], xi_max=params["xi_max"], n_grid=params["n_grid"],
                               n_iter=params["n_iter"], step_max=params["step_max"], max_points=params["max_points"],
                               steps_per_cycle=params["steps_per_cycle"], threads=job.threads)


@register
class ContinueAttractors(Kind):
    name = "continue_attractors"
    damped = True
    description = ("the period-1 attractors of a damped well followed across a sweep of F or Omega by pseudo-arclength "
                   "continuation (folds, period doublings, leaving the well), with each attractor's basin integrity "
                   "(GIM, LIM) at every swept value and the Dover cliff, where the most of its basin escapes")
    builder = "safebasins.plotting.continuation:figure_continuation"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False,
        "required": ["F", "Omega"],
        "properties": {
            "F": {"description": "forcing amplitude: a value, or the sweep (a range) if Omega is a value",
                  "oneOf": [{"$ref": "#/$defs/forcing"}, {"$ref": "#/$defs/range"}]},
            "Omega": {"description": "forcing frequency: a value, or the sweep (a range) if F is a value",
                      "oneOf": [{"$ref": "#/$defs/frequency"}, {"$ref": "#/$defs/omega_range"}]},
            "Psi": {"$ref": "#/$defs/angle", "default": 0.0},
            "xi_max": {"description": "escape energy; a branch ends where its orbit reaches it (null: the barrier "
                                      "energy)",
                       "oneOf": [{"type": "null"}, {"$ref": "#/$defs/threshold"}], "default": None},
            "n_grid": {"description": "nodes per side of the IC grid over the well's IC window (the basin labels)",
                       "type": "integer", "minimum": 9, "default": 101},
            "n_iter": {"description": "map iterations of the basin labels (null: max(50, 2 SETTLE / (beta T)), "
                                      "transients decayed to exp(-15))",
                       "oneOf": [{"type": "null"}, {"type": "integer", "minimum": 1}], "default": None},
            "step_max": {"description": "largest arclength step in (q, p, kappa lambda) (null: the IC window's "
                                        "q-width / 20)",
                         "oneOf": [{"type": "null"}, {"type": "number", "exclusiveMinimum": 0}], "default": None},
            "max_points": {"description": "points per direction of a branch at most", "type": "integer",
                           "minimum": 3, "default": 400},
            "steps_per_cycle": {"description": "integrator steps per forcing period of the basin labels (null: the "
                                               "run's numerics.steps_per_cycle)",
                                "oneOf": [{"type": "null"}, {"type": "integer", "minimum": 4}], "default": None},
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        if not block["damping"] > 0:
            ctx.fail(f"{key}.damping", "attractors inside the well need damping > 0")
        ranges = [k for k in SWEPT if isinstance(block[k], dict)]
        if len(ranges) != 1:
            ctx.fail(f"{key}.{'Omega' if ranges else 'F'}",
                     "exactly one of F and Omega is swept (a range {start, stop, num} or {start, stop, step}), "
                     f"the other a value; got {'both' if ranges else 'neither'} as a range")
        ctx.check_range(f"{key}.{ranges[0]}", block[ranges[0]], positive=ranges[0] == "Omega")
        if ranges[0] == "F" and block["F"]["start"] < 0:
            ctx.fail(f"{key}.F.start", f"the forcing amplitude must be >= 0, got {block['F']['start']}")

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        (sweep,) = [k for k in SWEPT if isinstance(block[k], dict)]
        spc, xi, n_it, ds = block["steps_per_cycle"], block["xi_max"], block["n_iter"], block["step_max"]
        return dict(sweep=sweep, **{k: values.range_values(block[k]) if k == sweep else float(block[k])
                                    for k in SWEPT},
                    Psi=values.angle(block["Psi"]), xi_max=None if xi is None else float(xi),
                    n_grid=int(block["n_grid"]), n_iter=None if n_it is None else int(n_it),
                    step_max=None if ds is None else float(ds), max_points=int(block["max_points"]),
                    steps_per_cycle=ctx.steps_per_cycle if spc is None else int(spc))

    def cost(self, params: Params) -> int:
        """An estimate: the compiled map of the labels at every swept value (no early escape), and the
        branches' DOP853 period maps in trajectory-steps of the same cost (the number of branches and
        their lengths are known only when they are followed)."""
        Om = values.as_list(params["Omega"])
        n_values = len(values.as_list(params[params["sweep"]]))
        beta = values.damping(params)
        iters = sum(settle_iterations(beta, om, params["n_iter"]) for om in Om) * (n_values if len(Om) == 1 else 1)
        labels = iters * params["n_grid"] ** 2 * params["steps_per_cycle"]
        (q_lo, q_hi), _ = values.base_well(params).ic_window()
        per_pass = _STEPS_ACROSS if params["step_max"] is None else (q_hi - q_lo) / params["step_max"]
        points = min(2 * params["max_points"], _PASSES * math.ceil(per_pass))
        return int(labels + _CURVES * points * _EVALS_PER_POINT * _STEPS_PER_EVAL)

    def products(self, experiment: str, params: Params) -> list[Product]:
        s, A = (params["sweep"],), ("attractor",)
        SA = (params["sweep"], "attractor")
        return [Product(dataset_path("extras", experiment), "extras", build_continuation, heavy=True,
                        title=params["title"] + " (attractors followed across " + params["sweep"] + ")",
                        history=f"safebasins.analysis.continuation.continue_attractors ({experiment})",
                        contract={"parameter": ("point",), "amplitude": ("point",), "stable": ("point",),
                                  "curve": ("point",), "event_kind": ("event",), "event_parameter": ("event",),
                                  "event_amplitude": ("event",), "attractor_class": A, "cliff_low": A,
                                  "cliff_high": A, "cliff_drop": A, "GIM": SA, "LIM": SA, "exists": SA,
                                  "lost_to_escape": SA, "GIM_safe": s, "lost_safe": s,
                                  "basin": (params["sweep"], "q0", "p0")})]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"continuation": dataset_path("extras", experiment)}
