"""Kinds ``criteria`` (Fig 19), ``chart`` (Figs 20-21) and ``area_time`` (Fig 22): escape charts
evaluated with both escape criteria (paper Appendix).

One integration per chart carries every energy (``xi_max``) and displacement (``q_max``)
threshold; every evaluation time ``t_eval <= cycles`` is read from it afterwards.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from safebasins.pipeline import values
from safebasins.pipeline.kinds.basins import chart_contract, gather_chart
from safebasins.pipeline.registry import (Block, ChartICs, FigureInputs, GridChartKind, Inputs, Job, Kind, Params,
                                          Product, dataset_path, params_path, register)

if TYPE_CHECKING:
    import xarray as xr

    from safebasins.pipeline.registry import ResolveContext
    from safebasins.pipeline.validation import CheckContext

Q_MAX = {"type": "number", "exclusiveMinimum": 0, "maximum": 1}


def build_criteria(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """A_E, A_q (safe counts by the energy and displacement criterion) per (F, repeat)
    (safebasins.analysis.agreement.criteria_table)."""
    from safebasins.analysis.agreement import criteria_table
    from safebasins.io.gather import task_charts

    charts = task_charts(data["tiles"])
    out = criteria_table(charts, params["F"], n_ic=params["n_ic"], repeats=params["repeats"], seeds=params["seeds"],
                         cycles=params["cycles"])
    out.attrs.update({k: charts[-1].attrs[k] for k in ("integrator", "steps_per_cycle")})
    out.attrs.update(Omega=params["Omega"], Psi=params["Psi"], xi_max=params["xi_max"], q_max=params["q_max"],
                     n_ic=params["n_ic"], cycles=params["cycles"], box=np.asarray(params["box"], dtype=float).ravel(),
                     criterion_note=("safe = escape_cycle > cycles; A_E energy (H0 > xi_max), A_q displacement "
                                     "(|q| > q_max)"))
    return out


def build_chart(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """The escape chart gathered from its tiles (attributes ``t_eval``, ``cycles``)."""
    return gather_chart(params, data["tiles"])


@register
class Criteria(Kind):
    name = "criteria"
    any_well = False
    description = "energy versus displacement escape criterion: safe counts of seeded random ICs"
    builder = "safebasins.plotting.charts:figure_criteria"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "required": ["F", "Omega", "Psi", "xi_max"],
        "properties": {
            "F": {"oneOf": [{"$ref": "#/$defs/range"},
                            {"type": "array", "minItems": 1, "items": {"$ref": "#/$defs/forcing"}}]},
            "Omega": {"$ref": "#/$defs/frequency"},
            "Psi": {"$ref": "#/$defs/angle"},
            "xi_max": {"$ref": "#/$defs/threshold"},
            "q_max": {"description": "displacement threshold; null = q_max(xi_max) of eq (4)",
                      "oneOf": [{"type": "null"}, Q_MAX], "default": None},
            "n_ic": {"type": "integer", "minimum": 1, "default": 10000},
            "repeats": {"type": "integer", "minimum": 1, "default": 5},
            "box": {"type": "array", "minItems": 2, "maxItems": 2, "items": {"$ref": "#/$defs/interval"},
                    "default": [[-1.0, 1.0], [-1.0, 1.0]]},
            "cycles": {"$ref": "#/$defs/cycles", "default": 3000},
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        ctx.check_interval(f"{key}.box[0]", block["box"][0])
        ctx.check_interval(f"{key}.box[1]", block["box"][1])
        if ctx.tiles > block["n_ic"] * block["repeats"]:
            ctx.fail("numerics.tiles", f"{ctx.tiles} tiles but {key} has only n_ic * repeats ICs")
        if isinstance(block["F"], dict):
            ctx.check_range(f"{key}.F", block["F"])
            if block["F"]["start"] < 0:
                ctx.fail(f"{key}.F.start", f"must be >= 0 (a forcing amplitude), got {block['F']['start']}")
        ctx.check_unique(f"{key}.F", block["F"])

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        from safebasins.wells.quartic import QUARTIC

        Fs = values.values(block["F"])
        xi = float(block["xi_max"])
        qm = float(QUARTIC.q_max(xi)) if block["q_max"] is None else float(block["q_max"])
        reps = int(block["repeats"])
        return dict(F=Fs, Omega=float(block["Omega"]), Psi=values.angle(block["Psi"]), xi_max=xi, q_max=qm,
                    n_ic=int(block["n_ic"]), repeats=reps, seeds=[ctx.seed + r for r in range(reps)],
                    box=values.box(block["box"]), cycles=int(block["cycles"]), steps_per_cycle=ctx.steps_per_cycle,
                    tasks=[{"F": f, "xi_max": [xi], "q_max": [qm]} for f in Fs])

    def chart_ics(self, params: Params) -> ChartICs:
        from safebasins.numerics import random_initial_conditions

        qs, ps = [], []
        for seed in params["seeds"]:
            q, p = random_initial_conditions(params["n_ic"], seed, box=tuple(tuple(b) for b in params["box"]))
            qs.append(np.asarray(q, dtype=float))
            ps.append(np.asarray(p, dtype=float))
        return np.concatenate(qs), np.concatenate(ps), False

    def cost(self, params: Params) -> int:
        return len(params["tasks"]) * params["n_ic"] * params["repeats"] * params["cycles"] * params["steps_per_cycle"]

    def products(self, experiment: str, params: Params) -> list[Product]:
        return [Product(dataset_path("numeric", f"criteria_{experiment}"), "numeric", build_criteria, tiles=True,
                        title=params["title"], contract={"A_E": ("F", "repeat"), "A_q": ("F", "repeat"),
                                                         "rel_diff": ("F", "repeat"), "seed": ("repeat",)},
                        history=f"safebasins.numerics.escape_chart on seeded random ICs ({experiment})")]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"numeric": dataset_path("numeric", f"criteria_{experiment}")}


@register
class Chart(GridChartKind):
    name = "chart"
    description = "escape chart on an IC grid with energy and displacement thresholds (DSB / ESB)"
    builder = "safebasins.plotting.charts:figure_dsb_esb"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "required": ["F", "Omega", "Psi", "xi_max", "grid"],
        "properties": {
            "F": {"$ref": "#/$defs/forcing"},
            "Omega": {"$ref": "#/$defs/frequency"},
            "Psi": {"$ref": "#/$defs/angle"},
            "xi_max": {"$ref": "#/$defs/threshold_list"},
            "q_max": {"oneOf": [Q_MAX, {"type": "array", "items": Q_MAX}], "default": []},
            "grid": {"$ref": "#/$defs/grid"},
            "cycles": {"$ref": "#/$defs/cycles", "default": 3000},
            "t_eval": {"type": "array", "minItems": 1, "items": {"type": "number", "minimum": 0}},
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        ctx.check_grid(f"{key}.grid", block["grid"])
        if "t_eval" in block:
            ctx.check_t_eval_within(f"{key}.t_eval", block["t_eval"], block["cycles"])
        if not values.as_list(block["xi_max"]) and not values.as_list(block["q_max"]):
            ctx.fail(f"{key}.xi_max", "at least one threshold needed")
        for k in ("xi_max", "q_max", "t_eval"):
            ctx.check_unique(f"{key}.{k}", block.get(k))

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        xis = [float(x) for x in values.as_list(block["xi_max"])]
        qms = [float(x) for x in values.as_list(block["q_max"])]
        return dict(F=float(block["F"]), Omega=float(block["Omega"]), Psi=values.angle(block["Psi"]), xi_max=xis,
                    q_max=qms, grid=values.grid(block["grid"]), cycles=int(block["cycles"]),
                    t_eval=[float(t) for t in block.get("t_eval", [block["cycles"]])],
                    steps_per_cycle=ctx.steps_per_cycle,
                    tasks=[{"F": float(block["F"]), "xi_max": xis, "q_max": qms}])

    def products(self, experiment: str, params: Params) -> list[Product]:
        return [Product(dataset_path("numeric", f"chart_{experiment}"), "numeric", build_chart, tiles=True,
                        title=params["title"], contract=chart_contract(),
                        history=f"safebasins.numerics.escape_chart tiles gathered ({experiment})")]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"numeric": dataset_path("numeric", f"chart_{experiment}"), "params": params_path(experiment)}


@register
class AreaTime(Kind):
    name = "area_time"
    description = "safe-basin area versus evaluation time, read from another chart experiment"
    builder = "safebasins.plotting.charts:figure_area_vs_time"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "required": ["source", "t_eval"],
        "properties": {
            "source": {"type": "string", "description": "name of a `chart` experiment"},
            "t_eval": {"$ref": "#/$defs/range"},
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        src = block["source"]
        if ctx.kinds.get(src) != "chart":
            choices = ", ".join(sorted(e for e, k in ctx.kinds.items() if k == "chart"))
            ctx.fail(f"{key}.source", f"{src!r} is not an escape-chart experiment (choose among {choices})")
        ctx.check_range(f"{key}.t_eval", block["t_eval"])
        horizon = ctx.block(src)["cycles"]
        if block["t_eval"]["stop"] > horizon:
            ctx.fail(f"{key}.t_eval.stop",
                     f"{block['t_eval']['stop']} is beyond the horizon of {src} (cycles = {horizon})")

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        return dict(source=block["source"], t_eval=values.range_values(block["t_eval"]))

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"numeric": dataset_path("numeric", f"chart_{params['source']}"), "params": params_path(experiment)}
