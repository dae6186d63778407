"""Beyond-the-paper kinds (docs/extras.md): ``erosion`` (integrity versus F), ``true_basin``
(phase-invariant safe basin) and ``fourier_compare`` (paper versus exact first harmonic).

Their datasets are ``results/data/extras/<experiment>_<product>.nc``.  Their numerics reuse the chart tiles (one escape
chart per F, per Psi); every threshold and evaluation time is read from the same integration.  ``fourier_compare``
integrates nothing: it re-reads the numeric datasets of other experiments.
"""
from __future__ import annotations

from functools import partial
import math
from typing import TYPE_CHECKING

import numpy as np

from safebasins.pipeline import values
from safebasins.pipeline import well_defaults as WD
from safebasins.pipeline.registry import (Block, FigureInputs, GridChartKind, Inputs, Job, Kind, Params, Product,
                                          dataset_path, register)

if TYPE_CHECKING:
    import xarray as xr

    from safebasins.pipeline.registry import ResolveContext
    from safebasins.pipeline.validation import CheckContext

FOURIER_LIST = {"description": "first-harmonic variants of the analytic products (\"paper\", \"exact\")",
                "oneOf": [{"enum": ["paper", "exact"]},
                          {"type": "array", "minItems": 1, "uniqueItems": True, "items": {"enum": ["paper", "exact"]}}]}
T_EVAL_LIST = {"description": "evaluation times in forcing cycles (each <= cycles), read from one integration",
               "oneOf": [{"type": "number", "minimum": 0},
                         {"type": "array", "minItems": 1, "items": {"type": "number", "minimum": 0}}]}


def _grid_charts(params: Params, blocks: list[list[xr.Dataset]], attr: str) -> list[xr.Dataset]:
    """The chart of every task, each tagged with its task value ``attr`` (F or Psi) and cycles."""
    from safebasins.io.gather import task_charts

    charts = task_charts(blocks)
    for c, t in zip(charts, params["tasks"]):
        c.attrs.update({attr: t[attr], "cycles": params["cycles"]})
    return charts


def _level_crossings(ds: xr.Dataset, level: float) -> xr.Dataset:
    from safebasins.analysis.erosion import level_crossing

    cross = level_crossing(ds, level)
    for m in ("GIM", "LIM", "IF"):
        ds[f"F_{m}"] = cross[m].assign_attrs(units="1", long_name=f"first F at which {m} falls below {level:g}")
    return ds


def build_erosion_analytic(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """GIM / LIM / IF versus F from the slow flow on the chart grid, per first-harmonic variant
    (with damping: the damped slow flow, every IC's trajectory followed)."""
    from safebasins.analysis.erosion import erosion_profile_analytic

    n = params.get("analytic_n")
    q0, p0 = values.grid_axes(dict(params["grid"], n=[n, n]) if n else params["grid"])
    beta = values.damping(params)
    print(f"{params['experiment']}: {len(params['F'])} F x {len(params['xi_max'])} xi_max x {params['fourier']} "
          f"on {q0.size} x {p0.size} ICs" + (f", damping {beta}" if beta > 0 else ""))
    ds = erosion_profile_analytic(params["F"], params["Omega"], params["Psi"], params["xi_max"], q0, p0,
                                  fourier=params["fourier"], well=values.base_well(params), damping=beta)
    ds = _level_crossings(ds, params["level"])
    ds.attrs.update(level=params["level"], xi_max=params["xi_max"], grid_n=np.array([q0.size, p0.size]))
    return ds


def build_erosion_numeric(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """GIM / LIM / IF versus (F, xi_max, t_eval) from one escape chart per F (integrated with the
    experiment's damping by the chart tiles; the profile carries the charts' ``damping``)."""
    from safebasins.analysis.erosion import profile_from_charts

    ds = profile_from_charts(_grid_charts(params, data["tiles"], "F"), params["t_eval"], stack_dim="F")
    ds = _level_crossings(ds, params["level"])
    ds.attrs.update(level=params["level"], xi_max=params["xi_max"], cycles=params["cycles"])
    return ds


def build_true_basin_analytic(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """Per-phase analytic basins, their intersection and the all-phase basin H0 < xi_true."""
    from safebasins.analysis.phase_invariant import true_safe_basin_analytic

    from safebasins.analysis.phase_invariant import phase_boundaries

    q0, p0 = values.grid_axes(params["grid"])
    print(f"{params['experiment']}: F={params['F']} Omega={params['Omega']} xi_max={params['xi_max']} "
          f"{len(params['Psi'])} phases {params['fourier']}")
    w = values.base_well(params)
    ds = true_safe_basin_analytic(params["F"], params["Omega"], params["xi_max"], q0, p0, params["Psi"],
                                  fourier=params["fourier"], n_gamma=params["n_gamma"], well=w)
    b = phase_boundaries(params["F"], params["Omega"], params["xi_max"], params["Psi"], fourier=params["fourier"],
                         n_points=params["n_points"], well=w)
    return ds.merge(b.assign_coords({c: ds[c] for c in b.coords if c in ds.coords}))


def build_true_basin_numeric(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """Intersection over Psi of the numeric safe basins (one escape chart per Psi)."""
    from safebasins.analysis.phase_invariant import true_safe_basin_from_charts

    return true_safe_basin_from_charts(_grid_charts(params, data["tiles"], "Psi"), params["t_eval"])


def _fourier_source(what: str, source: str) -> str:
    """The numeric dataset of experiment ``source`` that a fourier_compare product reads."""
    return dataset_path("numeric", f"{'fcr' if what == 'fcr' else 'chart'}_{source}")


def build_fourier(params: Params, data: Inputs, job: Job, *, what: str, source: str) -> xr.Dataset:
    """Paper vs exact first harmonic against the numerics of experiment ``source``."""
    from safebasins.analysis import fourier_compare as fc

    src = data["source"]
    if what == "fcr":
        ds = fc.fcr_fourier_comparison_from_numeric(src)
        if "curve" in ds.dims:  # per-curve parameters of the source (attributes would conflict across curves)
            names = ("label", "xi_max", "xi_ini", "gamma_ini", "Psi")
            ds = ds.assign_coords({c: ("curve", src[c].values) for c in names
                                   if c in src.coords and src[c].dims == ("curve",)})
    else:
        ds = fc.iou_fourier_comparison(src, params["t_eval"])
    ds.attrs.update(source_experiment=source, source_file=_fourier_source(what, source),
                    source_config_hash=src.attrs.get("config_hash", "none"))
    return ds


def _check_grid_block(block: Block, key: str, ctx: CheckContext) -> None:
    ctx.check_grid(f"{key}.grid", block["grid"])
    ctx.check_thresholds_below_separatrix(f"{key}.xi_max", block["xi_max"], "the analytic criterion", ctx.well_at(key),
                                          block.get("damping", 0.0))
    ctx.check_t_eval_within(f"{key}.t_eval", block["t_eval"], block["cycles"])
    for k in ("xi_max", "t_eval"):
        ctx.check_unique(f"{key}.{k}", block[k])


def _analytic_numeric_inputs(experiment: str) -> dict[str, str]:
    """Figure inputs of a kind with an analytic and a numeric product."""
    return {"analytic": dataset_path("extras", f"{experiment}_analytic"),
            "numeric": dataset_path("extras", f"{experiment}_numeric")}


@register
class Erosion(GridChartKind):
    name = "erosion"
    description = "GIM / LIM / IF versus F; one escape chart per F serves every xi_max and t_eval"
    damped = True
    builder = "safebasins.plotting.extras:figure_erosion"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "default": {},
        "properties": {
            "F": WD.nullable({"oneOf": [{"$ref": "#/$defs/range"},
                                        {"type": "array", "minItems": 2, "items": {"$ref": "#/$defs/forcing"}}]},
                             "31 values from 0 to 0.39 of the well's static escape force (the quartic: 0 to 0.15)"),
            "Omega": WD.nullable({"$ref": "#/$defs/frequency"}, "0.9 of the well's linear frequency"),
            "Psi": {"$ref": "#/$defs/angle", "default": "pi"},
            "xi_max": WD.nullable({"$ref": "#/$defs/threshold_list"}, "0.72 and 0.88 of the barrier energy"),
            "grid": WD.nullable({"$ref": "#/$defs/grid"}, "121 x 121 nodes on 0.85 x 0.93 of the well's IC window "
                                                         "(the quartic: q0 in [-0.85, 0.85], p0 in [-0.7, 0.7])"),
            "cycles": {"$ref": "#/$defs/cycles", "default": 1000},
            "t_eval": {**T_EVAL_LIST, "default": [10, 50, 200, 1000]},
            "fourier": WD.nullable(FOURIER_LIST, "[paper, exact] for the quartic, [exact] for other wells"),
            "level": {"description": "integrity level whose first crossing in F is reported (F at GIM = level, ...)",
                      "type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1, "default": 0.5},
            "analytic_n": {"description": "ICs per axis of the analytic (slow-flow) profile on the grid's window "
                                          "(null: the chart grid); finer than the chart: smooth analytic curves "
                                          "(with damping > 0 each IC's damped slow trajectory is integrated, "
                                          "hundreds of times the cost: a coarser grid, e.g. null)",
                           "oneOf": [{"type": "null"}, {"type": "integer", "minimum": 3}], "default": 481},
        },
    }

    well_defaults = {"F": WD.force_range(0.15, 31), "Omega": WD.frequency(0.9), "xi_max": WD.energies([0.18, 0.22]),
                     "grid": WD.window((-0.85, 0.85), (-0.70, 0.70), 121), "fourier": WD.fourier(["paper", "exact"])}

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        _check_grid_block(block, key, ctx)
        if isinstance(block["F"], dict):
            ctx.check_range(f"{key}.F", block["F"])
            if block["F"]["start"] < 0:
                ctx.fail(f"{key}.F.start", f"must be >= 0 (a forcing amplitude), got {block['F']['start']}")
        ctx.check_unique(f"{key}.F", block["F"])

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        Fs = values.values(block["F"])
        xis = [float(x) for x in values.as_list(block["xi_max"])]
        return dict(fourier=[str(f) for f in values.as_list(block["fourier"])], F=Fs, Omega=float(block["Omega"]),
                    Psi=values.angle(block["Psi"]), xi_max=xis, grid=values.grid(block["grid"]),
                    cycles=int(block["cycles"]), t_eval=[float(t) for t in values.as_list(block["t_eval"])],
                    level=float(block["level"]), steps_per_cycle=ctx.steps_per_cycle,
                    analytic_n=None if block["analytic_n"] is None else int(block["analytic_n"]),
                    tasks=[{"F": f, "xi_max": xis, "q_max": []} for f in Fs])


    def products(self, experiment: str, params: Params) -> list[Product]:
        return [
            Product(dataset_path("extras", f"{experiment}_analytic"), "extras", build_erosion_analytic, heavy=True,
                    title=params["title"] + " (analytic)",
                    contract={**{m: ("fourier", "F", "xi_max") for m in ("GIM", "LIM", "IF")},
                              **{f"F_{m}": ("fourier", "xi_max") for m in ("GIM", "LIM", "IF")}},
                    history=f"safebasins.analysis.erosion.erosion_profile_analytic ({experiment})"),
            Product(dataset_path("extras", f"{experiment}_numeric"), "extras", build_erosion_numeric, tiles=True,
                    title=params["title"] + " (numeric)",
                    contract={**{m: ("F", "xi_max", "t_eval") for m in ("GIM", "LIM", "IF")},
                              **{f"F_{m}": ("xi_max", "t_eval") for m in ("GIM", "LIM", "IF")}},
                    history=(f"safebasins.numerics.escape_chart per F + safebasins.analysis.erosion."
                             f"profile_from_charts ({experiment})")),
        ]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return _analytic_numeric_inputs(experiment)


@register
class TrueBasin(GridChartKind):
    name = "true_basin"
    description = "intersection over n_psi equispaced forcing phases of the safe basins (one chart per phase)"
    builder = "safebasins.plotting.extras:figure_true_basin"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "default": {},
        "properties": {
            "F": WD.nullable({"$ref": "#/$defs/forcing"}, "0.026 of the well's static escape force (the quartic: "
                                                          "0.01)"),
            "Omega": WD.nullable({"$ref": "#/$defs/frequency"}, "0.9 of the well's linear frequency"),
            "xi_max": WD.nullable({"$ref": "#/$defs/threshold_list"}, "0.72 of the barrier energy"),
            "n_psi": {"type": "integer", "minimum": 1, "default": 16},
            "grid": WD.nullable({"$ref": "#/$defs/grid"}, "121 x 121 nodes on 0.72 x 0.84 of the well's IC window "
                                                         "(the quartic: q0 in [-0.72, 0.72], p0 in [-0.63, 0.63])"),
            "cycles": {"$ref": "#/$defs/cycles", "default": 1000},
            "t_eval": {**T_EVAL_LIST, "default": [50, 1000]},
            "fourier": WD.nullable(FOURIER_LIST, "[paper, exact] for the quartic, [exact] for other wells"),
            "n_gamma": {"description": "gamma resolution of the continuous-phase energy radius xi_true",
                        "type": "integer", "minimum": 8, "default": 512},
            "n_points": {"description": "samples in xi per branch of each per-phase analytic boundary curve",
                         "type": "integer", "minimum": 16, "default": 400},
        },
    }

    well_defaults = {"F": WD.force(0.01), "Omega": WD.frequency(0.9), "xi_max": WD.energy(0.18),
                     "grid": WD.window((-0.72, 0.72), (-0.63, 0.63), 121), "fourier": WD.fourier(["paper", "exact"])}

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        _check_grid_block(block, key, ctx)

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        xis = [float(x) for x in values.as_list(block["xi_max"])]
        n = int(block["n_psi"])
        psis = [float(np.round(2 * math.pi * k / n, 12)) for k in range(n)]
        return dict(fourier=[str(f) for f in values.as_list(block["fourier"])], F=float(block["F"]),
                    Omega=float(block["Omega"]), xi_max=xis, Psi=psis, grid=values.grid(block["grid"]),
                    cycles=int(block["cycles"]), t_eval=[float(t) for t in values.as_list(block["t_eval"])],
                    n_gamma=int(block["n_gamma"]), n_points=int(block["n_points"]), steps_per_cycle=ctx.steps_per_cycle,
                    tasks=[{"F": float(block["F"]), "Psi": ps, "xi_max": xis, "q_max": []} for ps in psis])


    def products(self, experiment: str, params: Params) -> list[Product]:
        return [
            Product(dataset_path("extras", f"{experiment}_analytic"), "extras", build_true_basin_analytic, heavy=True,
                    title=params["title"] + " (analytic)",
                    contract={"safe": ("Psi", "fourier", "xi_max", "q0", "p0"),
                              "true_safe": ("fourier", "xi_max", "q0", "p0"), "xi_true": ("fourier", "xi_max"),
                              "GIM_true": ("fourier", "xi_max"), "contained": ("fourier", "xi_max"),
                              **{v: ("Psi", "fourier", "xi_max", "vertex")
                                 for v in ("boundary_q0", "boundary_p0", "boundary_curve")}},
                    history=f"safebasins.analysis.phase_invariant.true_safe_basin_analytic ({experiment})"),
            Product(dataset_path("extras", f"{experiment}_numeric"), "extras", build_true_basin_numeric, tiles=True,
                    title=params["title"] + " (numeric)",
                    contract={"safe": ("Psi", "xi_max", "t_eval", "q0", "p0"),
                              "true_safe": ("xi_max", "t_eval", "q0", "p0"), "GIM_true": ("xi_max", "t_eval"),
                              "contained": ("xi_max", "t_eval")},
                    history=(f"safebasins.numerics.escape_chart per Psi + safebasins.analysis.phase_invariant."
                             f"true_safe_basin_from_charts ({experiment})")),
        ]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return _analytic_numeric_inputs(experiment)


@register
class FourierCompare(Kind):
    name = "fourier_compare"
    any_well = False
    description = ("paper vs exact first harmonic against existing numerics (nothing is re-integrated): "
                   "F_cr of the listed fcr_compare experiments, safe-basin IoU of the listed basin_chart ones")
    builder = "safebasins.plotting.extras:figure_fourier"
    SOURCES = {"fcr": ("fcr_compare", "numeric F_cr"), "iou": ("basin_chart", "escape chart with analytic counterpart")}
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "default": {},
        "properties": {
            "fcr": {"type": "array", "items": {"type": "string"}, "default": ["fig10", "fig11", "fig12"]},
            "iou": {"type": "array", "items": {"type": "string"},
                    "default": ["fig13", "fig14", "fig15", "fig16", "fig17"]},
            "t_eval": {"description": "evaluation time of the numeric basins (null = each chart's horizon)",
                       "oneOf": [{"type": "null"}, {"type": "number", "exclusiveMinimum": 0}], "default": None},
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        for what, (kind, label) in self.SOURCES.items():
            seen: set[str] = set()
            for i, name in enumerate(block[what]):
                if ctx.kinds.get(name) != kind:
                    choices = ", ".join(sorted(e for e, k in ctx.kinds.items() if k == kind))
                    ctx.fail(f"{key}.{what}[{i}]", f"{name!r} has no {label} dataset (choose among {choices})")
                if name in seen:
                    ctx.fail(f"{key}.{what}[{i}]", f"{name!r} listed twice")
                seen.add(name)
        if block["t_eval"] is not None:
            for name in block["iou"]:
                horizon = ctx.block(name)["cycles"]
                if block["t_eval"] > horizon:
                    ctx.fail(f"{key}.t_eval", f"{block['t_eval']} is beyond the horizon of {name} (cycles = {horizon})")

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        return dict(fcr=list(block["fcr"]), iou=list(block["iou"]),
                    t_eval=None if block["t_eval"] is None else float(block["t_eval"]))

    def products(self, experiment: str, params: Params) -> list[Product]:
        out: list[Product] = []
        for what, label in (("fcr", "F_cr"), ("iou", "safe-basin IoU")):
            for source in params[what]:
                out.append(Product(
                    dataset_path("extras", f"{experiment}_{what}_{source}"), "extras",
                    partial(build_fourier, what=what, source=source), heavy=True,
                    title=f"{params['title']}: {label} of {source}",
                    inputs={"source": _fourier_source(what, source)},
                    contract=({"rel_error": ("curve", "fourier", "Omega"), "rms_rel_error": ("curve", "fourier")}
                              if what == "fcr" else {"mean_iou": ("fourier",)}),
                    history=f"safebasins.analysis.fourier_compare on the numerics of {source} ({experiment})"))
        return out

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"fcr": [dataset_path("extras", f"{experiment}_fcr_{e}") for e in params["fcr"]],
                "iou": [dataset_path("extras", f"{experiment}_iou_{e}") for e in params["iou"]]}
