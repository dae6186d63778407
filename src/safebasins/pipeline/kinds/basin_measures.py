"""Kind ``basin_measures``: the fractal boundary measures of a damped well's basins over a list of
F (:func:`safebasins.analysis.boundary_measures.boundary_measures`): basin entropy with the log 2
criterion, the fractal test, the Wada test and the uncertainty exponent of the basins of escape
and of each attractor, beside the Melnikov threshold.  Dataset:
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

STEPS = {"type": "array", "minItems": 2, "uniqueItems": True, "items": {"type": "integer", "minimum": 1}}
LABELLED = ("F", "labelling")


def build_measures(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """One stroboscopic map per F, its labels and their measures."""
    from safebasins.analysis.boundary_measures import boundary_measures

    q0, p0 = values.grid_axes(params["grid"])
    print(f"{params['experiment']}: basin measures at F = {params['F']} on {q0.size} x {p0.size} ICs, "
          f"{params['n_iter']} cycles", flush=True)
    m = params["measures"]
    return boundary_measures(params["F"], params["Omega"], params["Psi"], params["xi_max"], q0, p0,
                             damping=values.damping(params), well=values.base_well(params), n_iter=params["n_iter"],
                             box=m["box"], radius=m["radius"], n_balls=m["n_balls"], eps=m["eps"], seed=params["seed"],
                             tol=params["tol"], steps_per_cycle=params["steps_per_cycle"], threads=job.threads)


@register
class BasinMeasures(Kind):
    name = "basin_measures"
    damped = True
    description = ("fractal boundary measures of a damped well's basins (escape and each attractor) over F: basin "
                   "entropy S_b / S_bb with the log 2 criterion, the fractal test, the Wada test and the uncertainty "
                   "exponent, with the Melnikov threshold")
    builder = "safebasins.plotting.basin_measures:figure_basin_measures"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False,
        "required": ["F", "Omega", "xi_max", "grid"],
        "properties": {
            "F": {"type": "array", "minItems": 1, "maxItems": 4, "items": {"$ref": "#/$defs/forcing"}},
            "Omega": {"$ref": "#/$defs/frequency"},
            "Psi": {"$ref": "#/$defs/angle", "default": 0.0},
            "xi_max": {"$ref": "#/$defs/threshold"},
            "grid": {"$ref": "#/$defs/grid"},
            "n_iter": {"description": "map iterations (forcing cycles) for the transients to die out",
                       "type": "integer", "minimum": 10, "default": 150},
            "tol": {"description": "an IC has settled when its iterates repeat within tol (max norm)",
                    "type": "number", "exclusiveMinimum": 0, "default": 1.0e-4},
            "measures": {
                "type": "object", "additionalProperties": False, "default": {},
                "properties": {
                    "box": {"description": "basin entropy box side (grid steps)", "type": "integer", "minimum": 2,
                            "default": 5},
                    "radius": {"description": "fractal test ball radius (grid steps)", "type": "number",
                               "exclusiveMinimum": 0, "default": 8},
                    "n_balls": {"description": "fractal test boundary balls", "type": "integer", "minimum": 100,
                                "default": 1000},
                    "eps": {**STEPS, "description": "uncertainty exponent perturbations (grid steps)",
                            "default": [2, 4, 8, 16]},
                },
            },
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        if not block["damping"] > 0:
            ctx.fail(f"{key}.damping", "attractors inside the well need damping > 0")
        ctx.check_grid(f"{key}.grid", block["grid"])
        ctx.check_unique(f"{key}.F", block["F"])
        m = block["measures"]
        n = block["grid"]["n"]
        side = n if isinstance(n, int) else min(n)
        if m["box"] > side:
            ctx.fail(f"{key}.measures.box", f"{m['box']} is larger than the grid ({side} nodes a side)")
        if side - 1 <= 2 * m["radius"]:
            ctx.fail(f"{key}.measures.radius", f"a ball of radius {m['radius']} does not fit the grid ({side} nodes)")
        if side <= 2 * max(m["eps"]):
            ctx.fail(f"{key}.measures.eps", f"the largest eps ({max(m['eps'])} steps) needs more than "
                                            f"{2 * max(m['eps'])} nodes a side, the grid has {side}")

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        m = block["measures"]
        return dict(F=[float(f) for f in block["F"]], Omega=float(block["Omega"]), Psi=values.angle(block["Psi"]),
                    xi_max=float(block["xi_max"]), grid=values.grid(block["grid"]), n_iter=int(block["n_iter"]),
                    tol=float(block["tol"]), steps_per_cycle=ctx.steps_per_cycle, seed=ctx.seed,
                    measures={"box": int(m["box"]), "radius": float(m["radius"]), "n_balls": int(m["n_balls"]),
                              "eps": [int(e) for e in m["eps"]]})

    def cost(self, params: Params) -> int:
        nq, np_ = params["grid"]["n"]
        return int(len(params["F"]) * nq * np_ * params["n_iter"] * params["steps_per_cycle"])

    def products(self, experiment: str, params: Params) -> list[Product]:
        return [Product(dataset_path("extras", experiment), "extras", build_measures, heavy=True,
                        title=params["title"] + " (boundary measures)",
                        history=f"safebasins.analysis.boundary_measures.boundary_measures ({experiment})",
                        contract={"basin": ("F", "q0", "p0"), "S_bb": LABELLED, "S_bb_err": LABELLED,
                                  "p_value": LABELLED, "alpha": LABELLED, "alpha_err": LABELLED, "W": ("F",),
                                  "wada": ("F",), "F_melnikov": ()})]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"measures": dataset_path("extras", experiment)}
