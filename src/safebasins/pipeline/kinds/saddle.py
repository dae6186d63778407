"""Kind ``hilltop_saddle``: the hilltop saddle's stable and unstable manifolds over escape charts of a
damped well at a few F, with the numeric F of their first tangency beside the Melnikov threshold
(:func:`safebasins.analysis.saddle_chart.saddle_chart`).  Dataset:
``results/data/extras/<experiment>.nc``.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from safebasins.pipeline import values
from safebasins.pipeline.registry import Block, FigureInputs, Inputs, Job, Kind, Params, Product, dataset_path, register

if TYPE_CHECKING:
    import xarray as xr

    from safebasins.pipeline.registry import ResolveContext
    from safebasins.pipeline.validation import CheckContext

POSITIVE = {"type": "number", "exclusiveMinimum": 0}


def build_saddle(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """Escape charts, manifolds and orbit at each F; the tangency once."""
    from safebasins.analysis.saddle_chart import saddle_chart

    q0, p0 = values.grid_axes(params["grid"])
    m, t = params["manifolds"], params["tangency"]
    print(f"{params['experiment']}: hilltop saddle's manifolds at F = {params['F']} over {q0.size} x {p0.size} ICs"
          + (", and their first tangency" if t["enabled"] else ""), flush=True)
    tangency = None if not t["enabled"] else dict(xtol=t["xtol"], ds_max=t["ds_max"], rtol=t["rtol"])
    return saddle_chart(params["F"], params["Omega"], params["Psi"], params["xi_max"], q0, p0,
                        damping=values.damping(params), well=values.base_well(params), cycles=params["cycles"],
                        steps_per_cycle=params["steps_per_cycle"], threads=job.threads,
                        manifolds=dict(iterations=m["iterations"], ds_max=m["ds_max"], rtol=m["rtol"]),
                        tangency=tangency)


@register
class HilltopSaddle(Kind):
    name = "hilltop_saddle"
    damped = True
    description = ("the hilltop saddle of a damped well: its stable and unstable manifolds on the stroboscopic map "
                   "drawn over escape charts at a few F, and the F of their first tangency beside the Melnikov "
                   "threshold")
    builder = "safebasins.plotting.saddle:figure_hilltop_saddle"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False,
        "required": ["F", "Omega", "xi_max", "grid"],
        "properties": {
            "F": {"type": "array", "minItems": 1, "maxItems": 3, "items": {"$ref": "#/$defs/forcing"}},
            "Omega": {"$ref": "#/$defs/frequency"},
            "Psi": {"$ref": "#/$defs/angle", "default": 0.0},
            "xi_max": {"$ref": "#/$defs/threshold"},
            "grid": {"$ref": "#/$defs/grid"},
            "cycles": {"$ref": "#/$defs/cycles", "default": 500},
            "manifolds": {
                "type": "object", "additionalProperties": False, "default": {},
                "properties": {
                    "iterations": {"description": "map iterates of the fundamental segment (null: to the well's "
                                                  "scale, plus one)",
                                   "type": ["integer", "null"], "minimum": 1, "default": None},
                    "ds_max": {**POSITIVE, "description": "longest manifold segment", "default": 0.02},
                    "rtol": {**POSITIVE, "description": "DOP853 relative tolerance", "default": 1.0e-10},
                },
            },
            "tangency": {
                "type": "object", "additionalProperties": False, "default": {},
                "properties": {
                    "enabled": {"description": "compute the F of the first tangency (Brent, a few minutes)",
                                "type": "boolean", "default": True},
                    "xtol": {**POSITIVE, "description": "tolerance of the tangency's F", "default": 1.0e-6},
                    "ds_max": {**POSITIVE, "description": "longest manifold segment", "default": 0.02},
                    "rtol": {**POSITIVE, "description": "DOP853 relative tolerance", "default": 1.0e-9},
                },
            },
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        if not block["damping"] > 0:
            ctx.fail(f"{key}.damping", "attractors inside the well and a tangency at F > 0 need damping > 0")
        ctx.check_grid(f"{key}.grid", block["grid"])
        ctx.check_unique(f"{key}.F", block["F"])

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        m, t = block["manifolds"], block["tangency"]
        return dict(F=[float(f) for f in block["F"]], Omega=float(block["Omega"]), Psi=values.angle(block["Psi"]),
                    xi_max=float(block["xi_max"]), grid=values.grid(block["grid"]), cycles=int(block["cycles"]),
                    steps_per_cycle=ctx.steps_per_cycle,
                    manifolds={"iterations": None if m["iterations"] is None else int(m["iterations"]),
                               "ds_max": float(m["ds_max"]), "rtol": float(m["rtol"])},
                    tangency={"enabled": bool(t["enabled"]), "xtol": float(t["xtol"]), "ds_max": float(t["ds_max"]),
                              "rtol": float(t["rtol"])})

    def cost(self, params: Params) -> int:
        nq, np_ = params["grid"]["n"]
        return int(len(params["F"]) * nq * np_ * params["cycles"] * params["steps_per_cycle"])

    def products(self, experiment: str, params: Params) -> list[Product]:
        return [Product(dataset_path("extras", experiment), "extras", build_saddle, heavy=True,
                        title=params["title"] + " (hilltop saddle)",
                        history=f"safebasins.analysis.saddle_chart.saddle_chart ({experiment})",
                        contract={"escape_cycle": ("F", "q0", "p0"), "q0_vertex": ("F", "vertex"),
                                  "p0_vertex": ("F", "vertex"), "curve_index": ("F", "vertex"),
                                  "kind": ("F", "curve"), "side": ("F", "curve"), "q_fixed": ("F", "saddle"),
                                  "p_fixed": ("F", "saddle"), "F_melnikov": (), "F_tangency": ()})]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"saddle": dataset_path("extras", experiment)}
