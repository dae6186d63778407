"""Kind ``integrity_map``: GIM, LIM and IF of the safe basin over the control plane (Omega, F)
(beyond the paper; :mod:`safebasins.analysis.integrity_map`).

The analytic map classifies every IC of every control point with the slow flow (seconds) and
adds the phase-invariant basin in closed form.  The numeric map needs one escape chart per
control point: its tasks are the Omega values and the tiles of a task are blocks of F values,
so `numerics.tiles` spreads a map over many independent jobs (cluster, GPU); each tile job
integrates its block of control points in one ensemble and keeps only the integrity measures.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from safebasins.pipeline import values
from safebasins.pipeline import well_defaults as WD
from safebasins.pipeline.registry import Block, FigureInputs, Inputs, Job, Kind, Params, Product, dataset_path, register

if TYPE_CHECKING:
    from safebasins.pipeline.registry import ResolveContext
    from safebasins.pipeline.validation import CheckContext

MEASURES = ("GIM", "LIM", "IF")


def build_analytic(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    from safebasins.analysis.integrity_map import erosion_front, integrity_map_analytic

    q0, p0 = values.grid_axes(params["grid"])
    print(f"{params['experiment']}: analytic map {len(params['Omega'])} x {len(params['F'])}", flush=True)
    ds = integrity_map_analytic(params["Omega"], params["F"], params["Psi"], params["xi_max"], q0, p0,
                                fourier=params["fourier"], n_gamma=params["n_gamma"], n_xi=params["n_xi"],
                                well=values.well(params))
    fronts = erosion_front(ds, params["level"], measures=(*MEASURES, "GIM_true", "LIM_true"))
    ds.update(fronts)
    ds.attrs.update(level=params["level"])
    return ds


def build_numeric(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """Tiles (one Omega x a block of F each) gathered; numeric - analytic difference; fronts."""
    from safebasins.analysis.integrity_map import erosion_front
    from safebasins.io.gather import TILE_ATTRS

    rows = [xr.concat(block, dim="F") for block in data["tiles"]]
    ds = xr.concat(rows, dim="Omega").transpose("Omega", "F", "t_eval")
    ds = ds[list(MEASURES)]
    analytic = data["analytic"]
    for k in MEASURES:
        ds[f"{k}_diff"] = (ds[k] - analytic[k]).assign_attrs(
            units="1", long_name=f"{k} numeric - analytic (slow flow)")
    ds.update(erosion_front(ds, params["level"]))
    for k in TILE_ATTRS:  # one tile's bookkeeping, not the map's (as gather_tiles drops it)
        ds.attrs.pop(k, None)
    ds.attrs.update(level=params["level"], Psi=params["Psi"], xi_max=params["xi_max"], cycles=params["cycles"],
                    steps_per_cycle=params["steps_per_cycle"])
    return ds


@register
class IntegrityMap(Kind):
    name = "integrity_map"
    description = ("GIM, LIM and IF of the safe basin over a grid of (Omega, F) for one xi_max and Psi, slow flow "
                   "(and its all-phase basin) versus numerics, their difference and the erosion fronts")
    builder = "safebasins.plotting.integrity_maps:figure_integrity_map"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "required": ["Omega", "F"],
        "properties": {
            "Omega": {"$ref": "#/$defs/omega_range"},
            "F": {"$ref": "#/$defs/range"},
            "Psi": {"$ref": "#/$defs/angle", "default": "pi"},
            "xi_max": WD.nullable({"$ref": "#/$defs/threshold"}, "0.72 of the barrier energy (the quartic: 0.18)"),
            "grid": WD.nullable({"$ref": "#/$defs/grid"}, "61 x 61 nodes on 0.72 x 0.84 of the well's IC window "
                                                         "(the quartic: q0 in [-0.72, 0.72], p0 in [-0.63, 0.63])"),
            "cycles": {"$ref": "#/$defs/cycles", "default": 500},
            "t_eval": {"type": "array", "minItems": 1, "items": {"type": "number", "minimum": 0},
                       "description": "evaluation times (default: the horizon)"},
            "fourier": WD.nullable({"enum": ["paper", "exact"]}, "paper for the quartic, exact for other wells"),
            "level": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1, "default": 0.5},
            "n_gamma": {"type": "integer", "minimum": 8, "default": 128},
            "n_xi": {"type": "integer", "minimum": 8, "default": 64},
        },
    }
    well_defaults = {"xi_max": WD.energy(0.18), "grid": WD.window((-0.72, 0.72), (-0.63, 0.63), 61),
                     "fourier": WD.fourier("paper")}

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        ctx.check_grid(f"{key}.grid", block["grid"])
        ctx.check_range(f"{key}.Omega", block["Omega"], positive=True)
        ctx.check_range(f"{key}.F", block["F"])
        if block["F"]["start"] < 0:
            ctx.fail(f"{key}.F.start", f"must be >= 0 (a forcing amplitude), got {block['F']['start']}")
        ctx.check_thresholds_below_separatrix(f"{key}.xi_max", block["xi_max"], "the analytic map", ctx.well_at(key))
        if "t_eval" in block:
            ctx.check_t_eval_within(f"{key}.t_eval", block["t_eval"], block["cycles"])
            ctx.check_unique(f"{key}.t_eval", block["t_eval"])
        n_F = len(values.range_values(block["F"]))
        if ctx.tiles > n_F:
            ctx.fail("numerics.tiles", f"{ctx.tiles} tiles but {key}.F has only {n_F} values")

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        Om, Fs = values.range_values(block["Omega"]), values.range_values(block["F"])
        xi = float(block["xi_max"])
        return dict(Omega=Om, F=Fs, Psi=values.angle(block["Psi"]), xi_max=xi, grid=values.grid(block["grid"]),
                    cycles=int(block["cycles"]),
                    t_eval=[float(t) for t in block.get("t_eval", [block["cycles"]])], fourier=block["fourier"],
                    level=float(block["level"]), n_gamma=int(block["n_gamma"]), n_xi=int(block["n_xi"]),
                    steps_per_cycle=ctx.steps_per_cycle,
                    tasks=[{"Omega": om, "F": Fs, "xi_max": [xi], "q_max": []} for om in Om])

    def compute_tile(self, params: Params, task: int, tile: int, tiles: int, job: Job) -> xr.Dataset:
        """Control points (Omega_task, F in block ``tile``): one ensemble, integrity per t_eval."""
        from safebasins.analysis.integrity_map import integrity_from_batch
        from safebasins.numerics import escape_chart_batch

        t = params["tasks"][task]
        Fs = np.asarray(t["F"])[values.tile_slice(len(t["F"]), tiles, tile)]
        q0, p0 = values.grid_axes(params["grid"])
        print(f"{params['experiment']} Omega={t['Omega']} F={Fs.tolist()} on {q0.size}x{p0.size} ICs, "
              f"{params['cycles']} cycles ({job.backend})", flush=True)
        charts = escape_chart_batch(q0, p0, Fs, np.full(Fs.size, t["Omega"]), params["Psi"], xi_max=tuple(t["xi_max"]),
                                    cycles=params["cycles"], steps_per_cycle=params["steps_per_cycle"],
                                    threads=job.threads, backend=job.backend, well=values.base_well(params))
        m = integrity_from_batch(charts, params["t_eval"])
        return m.swap_dims(control="F").drop_vars("control").assign_coords(Omega=t["Omega"])

    def cost(self, params: Params) -> int:
        nq, np_ = params["grid"]["n"]
        return len(params["Omega"]) * len(params["F"]) * nq * np_ * params["cycles"] * params["steps_per_cycle"]

    def products(self, experiment: str, params: Params) -> list[Product]:
        analytic = dataset_path("extras", f"{experiment}_analytic")
        map_dims, front_dims = ("Omega", "F", "t_eval"), ("Omega", "t_eval")
        return [
            Product(analytic, "extras", build_analytic, title=params["title"] + " (analytic)",
                    history=f"safebasins.analysis.integrity_map.integrity_map_analytic ({experiment})",
                    contract={**{k: ("Omega", "F") for k in (*MEASURES, "GIM_true", "LIM_true", "xi_true")},
                              "F_GIM": ("Omega",)}),
            Product(dataset_path("extras", f"{experiment}_numeric"), "extras", build_numeric, tiles=True,
                    inputs={"analytic": analytic}, title=params["title"] + " (numeric)",
                    history=(f"safebasins.numerics.escape_chart_batch per block of control points + "
                             f"safebasins.analysis.integrity_map ({experiment})"),
                    contract={**{k: map_dims for k in MEASURES}, **{f"{k}_diff": map_dims for k in MEASURES},
                              "F_GIM": front_dims, "F_LIM": front_dims}),
        ]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"analytic": dataset_path("extras", f"{experiment}_analytic"),
                "numeric": dataset_path("extras", f"{experiment}_numeric")}

    def default_figure_text(self, experiment: str, params: Params) -> tuple[str, str]:
        caption = ("Integrity over the control plane: GIM and LIM of the safe basin for xi_max = "
                   f"{params['xi_max']:g}, Psi = {values.fmt(params['Psi'], angle=True)}, on a "
                   f"{len(params['Omega'])} x {len(params['F'])} grid of (Omega, F), "
                   f"{params['grid']['n'][0]} x {params['grid']['n'][1]} ICs per point, {params['cycles']} cycles.")
        look = ("Top: slow-flow (analytic) maps and, dashed, the all-phase basin's erosion front; middle: numeric maps "
                "at the last evaluation time; bottom: numeric minus analytic. Lines: the erosion fronts (F at which "
                "the measure falls to the level) of the slow flow and of the numerics. The slow flow overestimates "
                "integrity where the difference is negative.")
        return caption, look
