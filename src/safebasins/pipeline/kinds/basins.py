"""Kinds ``basin_rm`` (Figs 5-9), ``basin_chart`` (Figs 13-17) and ``strobe`` (Fig 18): safe basins.

The analytic product of each is ``basin_<experiment>.nc``: the boundary curves of
:func:`safebasins.theory.safe_basin_boundaries` (dims ``curve``, ``vertex``) and the per-IC
classification ``escapes(q0, p0)`` of :func:`safebasins.theory.slow_flow_escapes` on the
experiment's grid; ``basin_rm`` adds the first integral ``C`` and ``escapes_rm`` on the
resonance-manifold grid ``(gamma_rm, xi_rm)``; ``basin_chart`` stacks the basins over the
scanned parameter (``xi_max`` or ``F``; with damping: the damped slow flow's
classification and the outline of its safe mask, ``kind = "mask_outline"``).  ``basin_chart``'s numeric product is the
escape chart gathered from its tiles with the analytic/numeric agreement stored in it; ``strobe``'s is the
classified period map (:func:`safebasins.analysis.period_map.period_map_portrait`).
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from safebasins import wells
from safebasins.pipeline import values
from safebasins.pipeline.registry import (Block, Build, Contract, FigureInputs, GridChartKind, Inputs, Job, Kind,
                                          Params, Product, dataset_path, register)

if TYPE_CHECKING:
    import xarray as xr

    from safebasins.pipeline.registry import ResolveContext
    from safebasins.pipeline.validation import CheckContext

N_POINTS = {"type": "integer", "minimum": 16, "default": 2000}


def basin_contract(scan: tuple[str, ...] = (), manifold: bool = False) -> Contract:
    """Variables of an analytic basin dataset (``scan``: the leading stack dimension, if any)."""
    c: Contract = {**{v: (*scan, "curve") for v in ("kind", "C_level")},
         **{v: (*scan, "vertex") for v in ("gamma", "xi", "q0_vertex", "p0_vertex", "curve_index")},
         "escapes": (*scan, "q0", "p0")}
    if manifold:
        c.update(C=("gamma_rm", "xi_rm"), escapes_rm=("gamma_rm", "xi_rm"))
    return c


def chart_contract(scan: tuple[str, ...] = ()) -> Contract:
    """Variables of a gathered escape chart on a grid."""
    return {"escape_cycle_energy": (*scan, "xi_max", "q0", "p0"),
            "escape_cycle_displacement": (*scan, "q_max", "q0", "p0")}


def _basin_attrs(out: xr.Dataset, params: Params) -> xr.Dataset:
    for k in ("F", "Omega", "Psi", "xi_max"):
        if k not in out.dims and k not in out.coords:
            out.attrs[k] = params[k]
    out.attrs["fourier"] = params["fourier"]
    return out


def build_basin_single(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """One analytic basin (Fig 18); with a ``manifold`` grid also C and escapes_rm (Figs 5-9); with
    ``check_cycles`` also the numeric check of its connected parts (safebasins.analysis.ic_basins)."""
    from safebasins.analysis import ic_basins

    q0, p0 = values.grid_axes(params["grid"])
    w = values.well(params)
    F, Omega, Psi, xi = params["F"], params["Omega"], params["Psi"], params["xi_max"]
    out = ic_basins.analytic_basin(F, Omega, Psi, xi, q0, p0, well=w, n_points=params["n_points"],
                                   label=params["experiment"])
    m = params.get("manifold")
    if m is not None:
        out = ic_basins.add_resonance_manifold(out, F, Omega, xi, n_gamma=m["n_gamma"], n_xi=m["n_xi"],
                                               xi_top=m["xi_top"], well=w)
    if params.get("check_cycles"):
        out = ic_basins.numeric_check(out, F, Omega, Psi, xi, cycles=params["check_cycles"],
                                      steps_per_cycle=params["steps_per_cycle"], well=w, threads=job.threads,
                                      label=params["experiment"])
    return _basin_attrs(out, params)


def build_basin_stack(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """Analytic basins stacked over the scanned parameter (Figs 13-17); with damping the
    damped slow flow's classification and the outline of its safe mask (analytic_basin)."""
    from safebasins.analysis.ic_basins import analytic_basin_stack

    q0, p0 = values.grid_axes(params["grid"])
    out = analytic_basin_stack(params["scan"], params[params["scan"]], params["F"], params["Omega"], params["Psi"],
                               params["xi_max"], q0, p0, well=values.well(params), n_points=params["n_points"],
                               label=params["experiment"], damping=values.damping(params))
    return _basin_attrs(out, params)


def gather_chart(params: Params, blocks: list[list[xr.Dataset]]) -> xr.Dataset:
    """The escape chart of every task gathered from its tiles (stacked over F for F scans)."""
    from safebasins.io.gather import gather_chart as gather, task_charts

    return gather(task_charts(blocks), cycles=params["cycles"], scan=params.get("scan"),
                  F=[t["F"] for t in params["tasks"]], t_eval=params.get("t_eval"))


def build_chart_agreement(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """Gathered chart + IoU and pixel agreement with the analytic basin, per scanned value
    (safebasins.analysis.agreement.chart_agreement at t_eval = cycles)."""
    from safebasins.analysis.agreement import chart_agreement

    return chart_agreement(gather_chart(params, data["tiles"]), data["basin"], params["cycles"], params["scan"])


def strobe_candidates(params: Params) -> tuple[NDArray[np.float64], NDArray[np.float64], list[str]]:
    """Candidate ICs of the period map in priority order: the ``line`` of ICs (if any), then the
    seeded random ones in ``box``; and their origin labels."""
    from safebasins.numerics import random_initial_conditions

    qr, pr = random_initial_conditions(params["n_candidates"], params["seed"],
                                       box=tuple(tuple(b) for b in params["box"]))
    line = params.get("line")
    if line:
        ql = np.linspace(line["q0"][0], line["q0"][1], line["n"])
        pl = np.linspace(line["p0"][0], line["p0"][1], line["n"])
    else:
        ql = pl = np.zeros(0)
    origin = ["line"] * ql.size + ["random"] * np.asarray(qr).size
    return np.r_[ql, np.asarray(qr, float)], np.r_[pl, np.asarray(pr, float)], origin


def build_strobe(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """Stroboscopic map of the first ``n_trajectories`` non-escaping candidates (the line of ICs
    first, then seeded random ones), classified, each kept orbit with both criteria's escape
    cycles (safebasins.analysis.period_map.portrait_with_criteria)."""
    from safebasins.analysis.period_map import portrait_with_criteria

    q0, p0, origin = strobe_candidates(params)
    c = params["classification"]
    out = portrait_with_criteria(q0, p0, origin, params["F"], params["Omega"], params["Psi"],
                                 criterion=params["criterion"], xi_max=params["xi_max"], q_max=params["q_max"],
                                 n_keep=params["n_trajectories"], n_iter=params["n_iter"],
                                 steps_per_cycle=params["steps_per_cycle"], threads=job.threads,
                                 min_digits=c["min_digits"], max_period=c["max_period"])
    cand = np.asarray(out["candidate"].values)
    n_line = int(params["line"]["n"]) if params.get("line") else 0
    print(f"{out.attrs['n_non_escaping']} of {q0.size} candidates never escape in {params['n_iter']} iterations "
          f"({params['criterion']} criterion); kept {out.sizes['sample']}: {out.attrs['n_main']} main island, "
          f"{out.attrs['n_chain']} island chains (periods {out['chain_period'].values.tolist()}), "
          f"{out.attrs['n_chaotic']} chaotic", flush=True)
    out.attrs.update(seed=params["seed"], n_random=params["n_candidates"], n_line=n_line,
                     n_line_kept=int(sum(origin[i] == "line" for i in cand)),
                     box=np.asarray(params["box"], float).ravel(), F=params["F"], Omega=params["Omega"],
                     Psi=params["Psi"], xi_max=params["xi_max"], q_max=params["q_max"], criterion=params["criterion"],
                     n_iter=params["n_iter"],
                     fraction_non_escaping=out.attrs["n_non_escaping"] / out.attrs["n_candidates"])
    if n_line:
        out.attrs["line"] = np.asarray([*params["line"]["q0"], *params["line"]["p0"]], float)
    return out


def _basin_product(experiment: str, params: Params, build: Build, contract: Contract) -> Product:
    return Product(dataset_path("analytic", f"basin_{experiment}"), "analytic", build, title=params["title"],
                   contract=contract,
                   history=(f"safebasins.theory.slow_flow_escapes (damped slow flow) + mask outline ({experiment})"
                            if values.damping(params) > 0 else
                            f"safebasins.theory.safe_basin_boundaries + slow_flow_escapes ({experiment})"))


@register
class BasinRM(Kind):
    name = "basin_rm"
    description = "one analytic safe basin on the resonance manifold and on the (q0, p0) plane"
    builder = "safebasins.plotting.basins:figure_rm_basin"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "required": ["F", "Omega", "xi_max", "grid"],
        "properties": {
            "F": {"$ref": "#/$defs/forcing"},
            "Omega": {"$ref": "#/$defs/frequency"},
            "Psi": {"$ref": "#/$defs/angle", "default": 0.0},
            "xi_max": {"$ref": "#/$defs/threshold"},
            "grid": {"$ref": "#/$defs/grid"},
            "manifold": {
                "type": "object", "additionalProperties": False, "default": {},
                "properties": {
                    "n_gamma": {"type": "integer", "minimum": 2, "default": 361},
                    "n_xi": {"type": "integer", "minimum": 2, "default": 250},
                    "xi_top": {"description": "top xi of the panel; null: the well's own, 0.9996 E_b "
                                              "(safebasins.wells.Well.manifold_top; 0.2499 for the quartic)",
                               "oneOf": [{"type": "null"}, {"$ref": "#/$defs/energy"}], "default": None},
                },
            },
            "n_points": N_POINTS,
            "check_cycles": {"description": "integrate the analytic-safe ICs of the grid this many forcing cycles "
                                            "(energy criterion) and store, per connected part of the analytic "
                                            "basin, the fraction that stays (0: no check)",
                             "type": "integer", "minimum": 0, "default": 0},
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        ctx.check_grid(f"{key}.grid", block["grid"])
        ctx.check_thresholds_below_separatrix(f"{key}.xi_max", block["xi_max"], "an analytic safe basin",
                                              ctx.well_at(key), block.get("damping", 0.0))
        if block["manifold"]["xi_top"] is not None and block["manifold"]["xi_top"] <= 0:
            ctx.fail(f"{key}.manifold.xi_top", "must be > 0")

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        man = block["manifold"]
        return dict(fourier=ctx.fourier, F=float(block["F"]), Omega=float(block["Omega"]),
                    Psi=values.angle(block["Psi"]), xi_max=float(block["xi_max"]), grid=values.grid(block["grid"]),
                    n_points=int(block["n_points"]),
                    manifold={"n_gamma": int(man["n_gamma"]), "n_xi": int(man["n_xi"]),
                              "xi_top": float(wells.from_spec(ctx.well).manifold_top if man["xi_top"] is None
                                              else man["xi_top"])},
                    check_cycles=int(block["check_cycles"]), steps_per_cycle=ctx.steps_per_cycle)

    def cost(self, params: Params) -> int:
        nq, np_ = params["grid"]["n"]
        return nq * np_ * params["check_cycles"] * params["steps_per_cycle"]

    def products(self, experiment: str, params: Params) -> list[Product]:
        contract = basin_contract(manifold=True)
        if params["check_cycles"]:
            contract.update(escape_cycle_numeric=("q0", "p0"), region=("q0", "p0"), region_size=("region_index",),
                            region_numeric_safe=("region_index",))
        return [_basin_product(experiment, params, build_basin_single, contract)]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"analytic": dataset_path("analytic", f"basin_{experiment}")}


@register
class BasinChart(GridChartKind):
    name = "basin_chart"
    description = ("numeric escape chart with its analytic counterpart; exactly one of F / xi_max may be a "
                   "list (the scanned parameter: one chart serves every xi_max, one chart per F)")
    damped = True  # the damped slow flow's basin (outline of its mask) against the damped numerics
    builder = "safebasins.plotting.charts:figure_nested_basins"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "required": ["F", "Omega", "Psi", "xi_max", "grid"],
        "properties": {
            "F": {"oneOf": [{"$ref": "#/$defs/forcing"},
                            {"type": "array", "minItems": 1, "items": {"$ref": "#/$defs/forcing"}}]},
            "Omega": {"$ref": "#/$defs/frequency"},
            "Psi": {"$ref": "#/$defs/angle"},
            "xi_max": {"$ref": "#/$defs/threshold_list"},
            "grid": {"$ref": "#/$defs/grid"},
            "cycles": {"$ref": "#/$defs/cycles", "default": 3000},
            "n_points": N_POINTS,
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        ctx.check_grid(f"{key}.grid", block["grid"])
        ctx.check_thresholds_below_separatrix(f"{key}.xi_max", block["xi_max"], "an analytic safe basin",
                                              ctx.well_at(key), block.get("damping", 0.0))
        if isinstance(block["F"], list) and isinstance(block["xi_max"], list):
            ctx.fail(f"{key}.F", "only one of F and xi_max may be a list (the scanned parameter)")
        ctx.check_unique(f"{key}.F", block["F"])
        ctx.check_unique(f"{key}.xi_max", block["xi_max"])

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        scan = "F" if isinstance(block["F"], list) else "xi_max"
        Fs = [float(f) for f in values.as_list(block["F"])]
        xis = [float(x) for x in values.as_list(block["xi_max"])]
        return dict(fourier=ctx.fourier, scan=scan, F=Fs if scan == "F" else Fs[0],
                    xi_max=xis if scan == "xi_max" else xis[0], Omega=float(block["Omega"]),
                    Psi=values.angle(block["Psi"]), grid=values.grid(block["grid"]), cycles=int(block["cycles"]),
                    n_points=int(block["n_points"]), steps_per_cycle=ctx.steps_per_cycle,
                    tasks=[{"F": f, "xi_max": xis, "q_max": []} for f in Fs])

    def products(self, experiment: str, params: Params) -> list[Product]:
        scan = (params["scan"],)
        basin = _basin_product(experiment, params, build_basin_stack, basin_contract(scan))
        stack = scan if params["scan"] == "F" else ()  # one chart serves every xi_max; one per F
        return [basin, Product(dataset_path("numeric", f"chart_{experiment}"), "numeric", build_chart_agreement,
                               tiles=True, title=params["title"], inputs={"basin": basin.path},
                               contract={**chart_contract(stack), "iou": scan, "pixel_agreement": scan},
                               history=(f"safebasins.numerics.escape_chart tiles gathered + analytic/numeric "
                                        f"agreement ({experiment})"))]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"analytic": dataset_path("analytic", f"basin_{experiment}"),
                "numeric": dataset_path("numeric", f"chart_{experiment}")}


@register
class Strobe(Kind):
    name = "strobe"
    any_well = False
    description = ("stroboscopic map of non-escaping trajectories (a line of ICs, then seeded random ones), "
                   "classified into main-island tori, island chains and chaotic orbits, with the analytic basin")
    builder = "safebasins.plotting.maps:figure_period_map"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "required": ["F", "Omega", "Psi", "xi_max", "grid"],
        "properties": {
            "F": {"$ref": "#/$defs/forcing"},
            "Omega": {"$ref": "#/$defs/frequency"},
            "Psi": {"$ref": "#/$defs/angle"},
            "xi_max": {"$ref": "#/$defs/threshold"},
            "grid": {"$ref": "#/$defs/grid"},
            "n_trajectories": {"type": "integer", "minimum": 1, "default": 100},
            "n_candidates": {"type": "integer", "minimum": 1, "default": 2000},
            "n_iter": {"type": "integer", "minimum": 5, "default": 3000},
            "box": {"type": "array", "minItems": 2, "maxItems": 2, "items": {"$ref": "#/$defs/interval"}},
            "criterion": {"description": "escape criterion of the map: energy (H0 > xi_max or |q| > 1) or "
                                         "displacement (|q| > q_max(xi_max), eq 4)",
                          "enum": ["energy", "displacement"], "default": "energy"},
            "line": {"description": "a segment of n ICs from (q0[0], p0[0]) to (q0[1], p0[1]), drawn before the "
                                    "random ones (null: none)",
                     "oneOf": [{"type": "null"},
                               {"type": "object", "additionalProperties": False, "required": ["q0", "p0", "n"],
                                "properties": {"q0": {"$ref": "#/$defs/interval"}, "p0": {"$ref": "#/$defs/interval"},
                                               "n": {"type": "integer", "minimum": 1}}}],
                     "default": None},
            "classification": {
                "description": "orbit classification (safebasins.analysis.period_map)",
                "type": "object", "additionalProperties": False, "default": {},
                "properties": {
                    "min_digits": {"description": "chaotic below this many converged digits of the rotation number",
                                   "type": "number", "exclusiveMinimum": 0, "default": 5.0},
                    "max_period": {"description": "longest island-chain period looked for",
                                   "type": "integer", "minimum": 2, "default": 40},
                },
            },
            "n_points": N_POINTS,
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        ctx.check_grid(f"{key}.grid", block["grid"])
        ctx.check_thresholds_below_separatrix(f"{key}.xi_max", block["xi_max"], "an analytic safe basin",
                                              ctx.well_at(key), block.get("damping", 0.0))
        if "box" in block:
            ctx.check_interval(f"{key}.box[0]", block["box"][0])
            ctx.check_interval(f"{key}.box[1]", block["box"][1])
        n_line = block["line"]["n"] if block.get("line") else 0
        if block["n_trajectories"] > block["n_candidates"] + n_line:
            ctx.fail(f"{key}.n_trajectories", f"{block['n_trajectories']} trajectories requested but only "
                                              f"n_candidates + line.n = {block['n_candidates'] + n_line} drawn")

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        from safebasins.wells.quartic import QUARTIC

        xi = float(block["xi_max"])
        qm = float(QUARTIC.q_max(xi))
        bx = block.get("box") or [[-qm, qm], [-math.sqrt(2 * xi), math.sqrt(2 * xi)]]
        line = block.get("line")
        if line:
            line = {"q0": [float(v) for v in line["q0"]], "p0": [float(v) for v in line["p0"]], "n": int(line["n"])}
        cl = block["classification"]
        return dict(fourier=ctx.fourier, F=float(block["F"]), Omega=float(block["Omega"]),
                    Psi=values.angle(block["Psi"]), xi_max=xi, q_max=qm, criterion=str(block["criterion"]),
                    grid=values.grid(block["grid"]),
                    n_points=int(block["n_points"]), n_trajectories=int(block["n_trajectories"]),
                    n_candidates=int(block["n_candidates"]), n_iter=int(block["n_iter"]), box=values.box(bx),
                    line=line or None, seed=ctx.seed, steps_per_cycle=ctx.steps_per_cycle,
                    classification={"min_digits": float(cl["min_digits"]), "max_period": int(cl["max_period"])})

    def cost(self, params: Params) -> int:
        n_line = params["line"]["n"] if params.get("line") else 0
        return (params["n_candidates"] + n_line) * params["n_iter"] * params["steps_per_cycle"]

    def products(self, experiment: str, params: Params) -> list[Product]:
        return [_basin_product(experiment, params, build_basin_single, basin_contract()),
                Product(dataset_path("numeric", f"strobe_{experiment}"), "numeric", build_strobe, heavy=True,
                        title=params["title"],
                        contract={"q": ("sample", "iteration"), "p": ("sample", "iteration"),
                                  "escaped": ("sample",), "escape_cycle": ("sample",), "origin": ("sample",),
                                  "rotation_number": ("sample",), "birkhoff_digits": ("sample",),
                                  "period": ("sample",), "orbit_class": ("sample",), "chain_index": ("sample",),
                                  "escape_cycle_energy": ("sample",), "escape_cycle_displacement": ("sample",),
                                  "chain_period": ("chain",), "chain_winding": ("chain",),
                                  "chain_n_orbits": ("chain",), "chain_q": ("chain", "island"),
                                  "chain_p": ("chain", "island")},
                        history=(f"safebasins.numerics.stroboscopic_map + safebasins.analysis.period_map."
                                 f"period_map_portrait ({experiment})"))]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"analytic": dataset_path("analytic", f"basin_{experiment}"),
                "numeric": dataset_path("numeric", f"strobe_{experiment}")}
