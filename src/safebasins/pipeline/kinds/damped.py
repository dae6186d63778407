"""Kind ``tangency``: basin erosion of a damped well across the Melnikov tangency.

One escape chart per F on an IC grid (tiles, one integration for every t_eval) gives GIM / LIM /
IF versus F of the long-time basins, the Melnikov threshold and the basins at two F
(:func:`safebasins.analysis.tangency.tangency_profile`); seeded paired ICs give the uncertainty
exponent alpha(F) of the basin boundary
(:func:`safebasins.analysis.tangency.fractality_profile`).  Datasets:
``results/data/extras/<experiment>_profile.nc`` and ``<experiment>_fractality.nc``.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from safebasins.pipeline import values
from safebasins.pipeline.registry import (Block, FigureInputs, GridChartKind, Inputs, Job, Params, Product,
                                          dataset_path, register)

if TYPE_CHECKING:
    import xarray as xr

    from safebasins.pipeline.registry import ResolveContext
    from safebasins.pipeline.validation import CheckContext

F_LIST = {"type": "array", "minItems": 2, "items": {"$ref": "#/$defs/forcing"}}
EPS = {"type": "array", "minItems": 2, "uniqueItems": True, "items": {"type": "number", "exclusiveMinimum": 0}}


def build_profile(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """GIM / LIM / IF versus F (every t_eval), F_melnikov and the kept basins."""
    from safebasins.analysis.tangency import tangency_profile
    from safebasins.io.gather import task_charts

    charts = task_charts(data["tiles"])
    for c, t in zip(charts, params["tasks"]):
        c.attrs.update(F=t["F"], cycles=params["cycles"])
    return tangency_profile(charts, params["t_eval"], keep_F=params["basins_F"], level=params["level"])


def build_fractality(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """The uncertainty exponent alpha(F) of the basin boundary (seeded paired ICs)."""
    from safebasins.analysis.tangency import fractality_profile

    f = params["fractality"]
    print(f"{params['experiment']}: uncertainty exponent at F = {f['F']} ({f['n']} base points, eps = {f['eps']})",
          flush=True)
    return fractality_profile(f["F"], params["Omega"], params["Psi"], params["xi_max"], f["box"],
                              damping=values.damping(params), eps=f["eps"], n=f["n"], cycles=params["cycles"],
                              seed=params["seed"], well=values.base_well(params),
                              steps_per_cycle=params["steps_per_cycle"], threads=job.threads, backend=job.backend)


@register
class Tangency(GridChartKind):
    name = "tangency"
    damped = True
    description = ("basin erosion of a damped well across the Melnikov tangency: integrity versus F of long-time "
                   "basins, the boundary's uncertainty exponent alpha(F) and the basins before and after it")
    builder = "safebasins.plotting.tangency:figure_tangency"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False,
        "required": ["F", "Omega", "xi_max", "grid", "basins_F", "fractality"],
        "properties": {
            "F": {"oneOf": [{"$ref": "#/$defs/range"}, F_LIST]},
            "Omega": {"$ref": "#/$defs/frequency"},
            "Psi": {"$ref": "#/$defs/angle", "default": 0.0},
            "xi_max": {"$ref": "#/$defs/threshold"},
            "grid": {"$ref": "#/$defs/grid"},
            "cycles": {"$ref": "#/$defs/cycles", "default": 500},
            "t_eval": {"type": "array", "minItems": 1, "items": {"type": "number", "minimum": 0},
                       "default": [50, 500]},
            "level": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1, "default": 0.5},
            "basins_F": {"description": "F values (among F) whose long-time basins are kept and drawn",
                         "type": "array", "minItems": 1, "maxItems": 3, "items": {"$ref": "#/$defs/forcing"}},
            "fractality": {
                "type": "object", "additionalProperties": False, "required": ["F", "box"],
                "properties": {
                    "F": F_LIST,
                    "box": {"type": "array", "minItems": 2, "maxItems": 2, "items": {"$ref": "#/$defs/interval"}},
                    "n": {"type": "integer", "minimum": 100, "default": 20000},
                    "eps": {**EPS, "default": [1.0e-2, 3.0e-3, 1.0e-3, 3.0e-4, 1.0e-4]},
                },
            },
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        if not block["damping"] > 0:
            ctx.fail(f"{key}.damping", "the Melnikov tangency needs damping > 0 (undamped manifolds always "
                                       "intersect)")
        ctx.check_grid(f"{key}.grid", block["grid"])
        if isinstance(block["F"], dict):
            ctx.check_range(f"{key}.F", block["F"])
        ctx.check_unique(f"{key}.F", block["F"])
        ctx.check_unique(f"{key}.t_eval", block["t_eval"])
        ctx.check_t_eval_within(f"{key}.t_eval", block["t_eval"], block["cycles"])
        Fs = values.values(block["F"])
        for i, f in enumerate(block["basins_F"]):
            if not any(abs(f - x) <= 1e-12 * max(1.0, abs(f)) for x in Fs):
                ctx.fail(f"{key}.basins_F[{i}]", f"{f} is not one of the F values {Fs}")
        frac = block["fractality"]
        for i in (0, 1):
            ctx.check_interval(f"{key}.fractality.box[{i}]", frac["box"][i])
        ctx.check_unique(f"{key}.fractality.F", frac["F"])

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        Fs = values.values(block["F"])
        xi = float(block["xi_max"])
        frac = block["fractality"]
        basins = [next(x for x in Fs if abs(f - x) <= 1e-12 * max(1.0, abs(f))) for f in block["basins_F"]]
        return dict(F=Fs, Omega=float(block["Omega"]), Psi=values.angle(block["Psi"]), xi_max=xi,
                    grid=values.grid(block["grid"]), cycles=int(block["cycles"]),
                    t_eval=[float(t) for t in block["t_eval"]], level=float(block["level"]), basins_F=basins,
                    steps_per_cycle=ctx.steps_per_cycle, seed=ctx.seed,
                    fractality={"F": [float(f) for f in frac["F"]], "box": values.box(frac["box"]),
                                "n": int(frac["n"]), "eps": [float(e) for e in frac["eps"]]},
                    tasks=[{"F": f, "xi_max": [xi], "q_max": []} for f in Fs])

    def cost(self, params: Params) -> int:
        f = params["fractality"]
        paired = len(f["F"]) * f["n"] * (1 + 2 * len(f["eps"])) * params["cycles"] * params["steps_per_cycle"]
        return super().cost(params) + paired

    def products(self, experiment: str, params: Params) -> list[Product]:
        return [
            Product(dataset_path("extras", f"{experiment}_profile"), "extras", build_profile, tiles=True,
                    title=params["title"] + " (integrity profile)",
                    contract={**{m: ("F", "xi_max", "t_eval") for m in ("GIM", "LIM", "IF")},
                              "F_melnikov": (), "safe": ("F_basin", "xi_max", "q0", "p0")},
                    history=(f"safebasins.numerics.escape_chart per F (damped) + safebasins.analysis.tangency."
                             f"tangency_profile ({experiment})")),
            Product(dataset_path("extras", f"{experiment}_fractality"), "extras", build_fractality, heavy=True,
                    title=params["title"] + " (uncertainty exponent)",
                    contract={"alpha": ("F",), "alpha_err": ("F",), "fraction": ("F", "eps"), "F_melnikov": ()},
                    history=f"safebasins.analysis.tangency.fractality_profile ({experiment})"),
        ]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"profile": dataset_path("extras", f"{experiment}_profile"),
                "fractality": dataset_path("extras", f"{experiment}_fractality")}
