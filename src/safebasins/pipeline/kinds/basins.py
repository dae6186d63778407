"""Kinds ``basin_rm`` (Figs 5-9), ``basin_chart`` (Figs 13-17) and ``strobe`` (Fig 18): safe basins.

The analytic product of each is ``basin_<experiment>.nc``: the boundary curves of
:func:`safebasins.theory.safe_basin_boundaries` (dims ``curve``, ``vertex``) and the per-IC
classification ``escapes(q0, p0)`` of :func:`safebasins.theory.slow_flow_escapes` on the
experiment's grid; ``basin_rm`` adds the first integral ``C`` and ``escapes_rm`` on the
resonance-manifold grid ``(gamma_rm, xi_rm)``; ``basin_chart`` stacks the basins over the
scanned parameter (``xi_max`` or ``F``).  ``basin_chart``'s numeric product is the escape chart
gathered from its tiles with the analytic/numeric agreement stored in it; ``strobe``'s is the
classified period map (:func:`safebasins.analysis.period_map.period_map_portrait`).
"""
from __future__ import annotations

import math

import numpy as np

from safebasins.pipeline import values
from safebasins.pipeline.registry import GridChartKind, Kind, Product, dataset_path, register

N_POINTS = {"type": "integer", "minimum": 16, "default": 2000}


def basin_contract(scan=(), manifold=False):
    """Variables of an analytic basin dataset (``scan``: the leading stack dimension, if any)."""
    c = {**{v: (*scan, "curve") for v in ("kind", "C_level")},
         **{v: (*scan, "vertex") for v in ("gamma", "xi", "q0_vertex", "p0_vertex", "curve_index")},
         "escapes": (*scan, "q0", "p0")}
    if manifold:
        c.update(C=("gamma_rm", "xi_rm"), escapes_rm=("gamma_rm", "xi_rm"))
    return c


def chart_contract(scan=()):
    """Variables of a gathered escape chart on a grid."""
    return {"escape_cycle_energy": (*scan, "xi_max", "q0", "p0"),
            "escape_cycle_displacement": (*scan, "q_max", "q0", "p0")}


def _one_basin(params, F, Omega, Psi, xi_max):
    """Boundaries + per-IC analytic escape mask on the experiment's (q0, p0) grid."""
    import xarray as xr

    from safebasins.theory import safe_basin_boundaries, slow_flow_escapes

    qa, pa = values.grid_axes(params["grid"])
    Q, P = np.meshgrid(qa, pa, indexing="ij")
    print(f"{params['experiment']}: basin F={F} Omega={Omega} Psi={Psi} xi_max={xi_max}")
    w = values.well(params)
    b = safe_basin_boundaries(F, Omega, Psi, xi_max, well=w, n_points=params["n_points"])
    esc = slow_flow_escapes(Q, P, F, Omega, Psi, xi_max, well=w)
    b["escapes"] = xr.DataArray(np.asarray(esc, dtype=bool), dims=("q0", "p0"))
    return b.assign_coords(q0=("q0", qa), p0=("p0", pa))


def _basin_attrs(out, params):
    for k in ("F", "Omega", "Psi", "xi_max"):
        if k not in out.dims and k not in out.coords:
            out.attrs[k] = params[k]
    out.attrs["fourier"] = params["fourier"]
    return out


def build_basin_single(params, inputs, job):
    """One analytic basin (Fig 18); with a ``manifold`` grid also C and escapes_rm (Figs 5-9); with
    ``check_cycles`` also the numeric check of its connected parts (:func:`_numeric_check`)."""
    from safebasins.theory import escapes_on_manifold, first_integral

    out = _one_basin(params, params["F"], params["Omega"], params["Psi"], params["xi_max"])
    m = params.get("manifold")
    if m is not None:
        g = np.linspace(-np.pi, np.pi, m["n_gamma"])
        x = np.linspace(0.0, m["xi_top"], m["n_xi"])
        G, X = np.meshgrid(g, x, indexing="ij")
        w = values.well(params)
        C = first_integral(G, X, params["F"], params["Omega"], well=w)
        E = escapes_on_manifold(G, X, params["F"], params["Omega"], params["xi_max"], well=w)
        out = out.assign_coords(gamma_rm=("gamma_rm", g), xi_rm=("xi_rm", x))
        out["C"] = (("gamma_rm", "xi_rm"), np.asarray(C, dtype=float))
        out["escapes_rm"] = (("gamma_rm", "xi_rm"), np.asarray(E, dtype=bool))
    if params.get("check_cycles"):
        out = _numeric_check(out, params, job)
    return _basin_attrs(out, params)


def _numeric_check(out, params, job):
    """Integrate the analytic-safe ICs of the grid for ``check_cycles`` and store, per connected
    part of the analytic basin, the fraction the numerics keep (safebasins.analysis.confirm)."""
    from safebasins.analysis.confirm import confirm_regions
    from safebasins.numerics import escape_chart

    safe = ~np.asarray(out["escapes"].transpose("q0", "p0").values, bool)
    Q, P = np.meshgrid(out["q0"].values, out["p0"].values, indexing="ij")
    ec = np.full(safe.shape, np.nan)
    if safe.any():
        ch = escape_chart(Q[safe], P[safe], params["F"], params["Omega"], params["Psi"], xi_max=(params["xi_max"],),
                          cycles=params["check_cycles"], steps_per_cycle=params["steps_per_cycle"],
                          threads=job.threads, grid=False, well=values.well(params))
        ec[safe] = np.asarray(ch["escape_cycle_energy"].isel(xi_max=0).values, float)
    lab, size, frac = confirm_regions(safe, ec, params["check_cycles"])
    out["escape_cycle_numeric"] = (("q0", "p0"), ec, {
        "units": "1", "long_name": "numeric escape time of the analytic-safe ICs in forcing cycles, energy criterion "
                                   "(inf: not within check_cycles; NaN: analytic escape, not integrated)"})
    out["region"] = (("q0", "p0"), lab, {"units": "1", "long_name": "connected part of the analytic safe basin "
                                                                   "(0: analytic escape; 1 = largest)"})
    out["region_size"] = ("region_index", size, {"units": "1", "long_name": "grid points of the region"})
    out["region_numeric_safe"] = ("region_index", frac, {
        "units": "1", "long_name": "fraction of the region's ICs that do not escape numerically within check_cycles"})
    out = out.assign_coords(region_index=("region_index", np.arange(1, size.size + 1)))
    out.attrs["check_cycles"] = int(params["check_cycles"])
    print(f"{params['experiment']}: numeric check of {int(safe.sum())} analytic-safe ICs over "
          f"{params['check_cycles']} cycles: regions {size.tolist()}, kept {np.round(frac, 3).tolist()}")
    return out


def build_basin_stack(params, inputs, job):
    """Analytic basins stacked over the scanned parameter (Figs 13-17)."""
    from safebasins.io.datasets import stack

    scan = params["scan"]
    vals = params[scan]
    parts = [_one_basin(params, v if scan == "F" else params["F"], params["Omega"], params["Psi"],
                        v if scan == "xi_max" else params["xi_max"]) for v in vals]
    # per-basin saddle point: always a coordinate along the scanned dimension
    saddle = {k: [float(b.attrs.get(k, np.nan)) for b in parts] for k in ("saddle_gamma", "saddle_xi")}
    out = stack(parts, scan, vals, coords=saddle)
    out.attrs["scan"] = scan
    return _basin_attrs(out, params)


def gather_chart(params, tiles):
    """The escape chart of every task gathered from its tiles (stacked over F for F scans)."""
    from safebasins.io.datasets import stack
    from safebasins.io.gather import task_charts

    charts = task_charts(tiles, len(params["tasks"]))
    if params.get("scan") == "F":
        out = stack(charts, "F", [t["F"] for t in params["tasks"]], pad=())
        out.attrs["scan"] = "F"
    else:
        out = charts[0]
        if "scan" in params:
            out.attrs["scan"] = params["scan"]
    if "t_eval" in params:
        out.attrs["t_eval"] = params["t_eval"]
    out.attrs.setdefault("cycles", params["cycles"])
    return out


def build_chart_agreement(params, inputs, job):
    """Gathered chart + IoU and pixel agreement with the analytic basin, per scanned value.

    numeric safe = escape_cycle_energy > t_eval (= cycles); analytic safe = not escapes.
    """
    from safebasins.analysis.agreement import mask_agreement
    from safebasins.analysis.safe import is_safe
    from safebasins.io.datasets import load

    chart = gather_chart(params, inputs["tiles"])
    basin = load(inputs["basin"])
    cycles, scan = params["cycles"], params["scan"]
    numeric_safe = is_safe(chart["escape_cycle_energy"], cycles)
    if scan == "F":
        numeric_safe = numeric_safe.isel(xi_max=0, drop=True)
    analytic_safe = ~basin["escapes"].astype(bool).reset_coords(drop=True)  # no saddle_* coords in the chart
    numeric_safe = numeric_safe.reset_coords(drop=True)
    for ax in ("q0", "p0"):
        a, n = np.asarray(analytic_safe[ax].values), np.asarray(numeric_safe[ax].values)
        if a.shape != n.shape or not np.allclose(a, n, rtol=0, atol=1e-12):
            raise ValueError(f"analytic and numeric grids differ along {ax}")
    a, n = np.asarray(analytic_safe[scan].values, float), np.asarray(numeric_safe[scan].values, float)
    if a.shape != n.shape or not np.allclose(a, n, rtol=1e-12, atol=0):
        raise ValueError(f"analytic and numeric {scan} values differ: {a} vs {n}")
    analytic_safe = analytic_safe.assign_coords({c: numeric_safe[c] for c in ("q0", "p0", scan)})
    analytic_safe = analytic_safe.transpose(*numeric_safe.dims)
    iou, pixel = mask_agreement(analytic_safe, numeric_safe)
    out = chart.copy()
    # fresh attributes (the CF table fills them): arithmetic would pass on those of its operands
    out["iou"] = iou.drop_attrs(deep=False)
    out["pixel_agreement"] = pixel.drop_attrs(deep=False)
    out["safe_analytic"] = analytic_safe.sum(("q0", "p0")).astype(np.int64).drop_attrs(deep=False)
    out["safe_numeric"] = numeric_safe.sum(("q0", "p0")).astype(np.int64).drop_attrs(deep=False)
    out.attrs.update(
        agreement_t_eval=cycles,
        agreement_definition=("numeric safe = escape_cycle_energy > t_eval (= cycles); analytic safe = not "
                              "escapes (slow_flow_escapes); iou = |A and N| / |A or N|; pixel_agreement = "
                              "mean(A == N) over the (q0, p0) grid"),
        iou_mean=float(iou.mean()), iou_min=float(iou.min()),
        pixel_agreement_mean=float(pixel.mean()), pixel_agreement_min=float(pixel.min()),
    )
    for v, a_, px in zip(np.atleast_1d(iou[scan].values), np.atleast_1d(iou.values), np.atleast_1d(pixel.values)):
        print(f"{scan} = {v}: IoU = {a_:.4f}, pixel agreement = {px:.4f}")
    return out


def strobe_candidates(params):
    """Candidate ICs of the period map in priority order: the ``line`` of ICs (if any), then the
    seeded random ones in ``box``; and their origin labels."""
    from safebasins.numerics import random_initial_conditions

    qr, pr = random_initial_conditions(params["n_candidates"], params["seed"], box=tuple(tuple(b) for b in params["box"]))
    line = params.get("line")
    if line:
        ql = np.linspace(line["q0"][0], line["q0"][1], line["n"])
        pl = np.linspace(line["p0"][0], line["p0"][1], line["n"])
    else:
        ql = pl = np.zeros(0)
    origin = ["line"] * ql.size + ["random"] * np.asarray(qr).size
    return np.r_[ql, np.asarray(qr, float)], np.r_[pl, np.asarray(pr, float)], origin


def build_strobe(params, inputs, job):
    """Stroboscopic map of the first ``n_trajectories`` non-escaping candidates (the line of ICs
    first, then seeded random ones), classified (:func:`safebasins.analysis.period_map.
    period_map_portrait`: main-island tori, island chains, chaotic orbits); under the
    displacement criterion each kept orbit also gets its energy-criterion escape cycle."""
    from safebasins.analysis.period_map import period_map_portrait
    from safebasins.numerics import escape_chart

    q0, p0, origin = strobe_candidates(params)
    energy = params["criterion"] == "energy"
    thresholds = dict(xi_max=params["xi_max"]) if energy else dict(q_max=params["q_max"])
    c = params["classification"]
    out = period_map_portrait(q0, p0, params["F"], params["Omega"], params["Psi"], n_keep=params["n_trajectories"],
                              n_iter=params["n_iter"], steps_per_cycle=params["steps_per_cycle"], threads=job.threads,
                              min_digits=c["min_digits"], max_period=c["max_period"], **thresholds)
    cand = np.asarray(out["candidate"].values)
    out["origin"] = ("sample", np.array([origin[i] for i in cand]), {"long_name": "where the IC comes from (line | random)"})
    # the other criterion on the same ICs (one escape chart of the kept ICs, paired samples)
    other = escape_chart(np.asarray(out["q0"].values, float), np.asarray(out["p0"].values, float), params["F"],
                         params["Omega"], params["Psi"], xi_max=(params["xi_max"],), q_max=(params["q_max"],),
                         cycles=params["n_iter"], steps_per_cycle=params["steps_per_cycle"], threads=job.threads,
                         grid=False)
    out["escape_cycle_energy"] = ("sample", np.asarray(other["escape_cycle_energy"].isel(xi_max=0).values, float),
                                  {"units": "1", "long_name": "escape time in forcing cycles, energy criterion "
                                                              "H0 > xi_max (inf: no escape)"})
    out["escape_cycle_displacement"] = ("sample", np.asarray(other["escape_cycle_displacement"].isel(q_max=0).values, float),
                                        {"units": "1", "long_name": "escape time in forcing cycles, displacement "
                                                                    "criterion |q| > q_max (inf: no escape)"})
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


def _basin_product(experiment, params, build, contract):
    return Product(dataset_path("analytic", f"basin_{experiment}"), "analytic", build, title=params["title"],
                   contract=contract,
                   history=f"safebasins.theory.safe_basin_boundaries + slow_flow_escapes ({experiment})")


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
                    "xi_top": {"$ref": "#/$defs/energy", "default": 0.2499},
                },
            },
            "n_points": N_POINTS,
            "check_cycles": {"description": "integrate the analytic-safe ICs of the grid this many forcing cycles "
                                            "(energy criterion) and store, per connected part of the analytic "
                                            "basin, the fraction that stays (0: no check)",
                             "type": "integer", "minimum": 0, "default": 0},
        },
    }

    def check(self, block, key, ctx):
        ctx.check_grid(f"{key}.grid", block["grid"])
        ctx.check_thresholds_below_separatrix(f"{key}.xi_max", block["xi_max"], "an analytic safe basin", ctx.well_at(key))
        if block["manifold"]["xi_top"] <= 0:
            ctx.fail(f"{key}.manifold.xi_top", "must be > 0")

    def resolve(self, block, ctx):
        man = block["manifold"]
        return dict(fourier=ctx.fourier, F=float(block["F"]), Omega=float(block["Omega"]),
                    Psi=values.angle(block["Psi"]), xi_max=float(block["xi_max"]), grid=values.grid(block["grid"]),
                    n_points=int(block["n_points"]),
                    manifold={"n_gamma": int(man["n_gamma"]), "n_xi": int(man["n_xi"]), "xi_top": float(man["xi_top"])},
                    check_cycles=int(block["check_cycles"]), steps_per_cycle=ctx.steps_per_cycle)

    def cost(self, params):
        nq, np_ = params["grid"]["n"]
        return nq * np_ * params["check_cycles"] * params["steps_per_cycle"]

    def products(self, experiment, params):
        contract = basin_contract(manifold=True)
        if params["check_cycles"]:
            contract.update(escape_cycle_numeric=("q0", "p0"), region=("q0", "p0"), region_size=("region_index",),
                            region_numeric_safe=("region_index",))
        return [_basin_product(experiment, params, build_basin_single, contract)]

    def figure_inputs(self, experiment, params):
        return {"analytic": dataset_path("analytic", f"basin_{experiment}")}


@register
class BasinChart(GridChartKind):
    name = "basin_chart"
    description = ("numeric escape chart with its analytic counterpart; exactly one of F / xi_max may be a "
                   "list (the scanned parameter: one chart serves every xi_max, one chart per F)")
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

    def check(self, block, key, ctx):
        ctx.check_grid(f"{key}.grid", block["grid"])
        ctx.check_thresholds_below_separatrix(f"{key}.xi_max", block["xi_max"], "an analytic safe basin", ctx.well_at(key))
        if isinstance(block["F"], list) and isinstance(block["xi_max"], list):
            ctx.fail(f"{key}.F", "only one of F and xi_max may be a list (the scanned parameter)")
        ctx.check_unique(f"{key}.F", block["F"])
        ctx.check_unique(f"{key}.xi_max", block["xi_max"])

    def resolve(self, block, ctx):
        scan = "F" if isinstance(block["F"], list) else "xi_max"
        Fs = [float(f) for f in values.as_list(block["F"])]
        xis = [float(x) for x in values.as_list(block["xi_max"])]
        return dict(fourier=ctx.fourier, scan=scan, F=Fs if scan == "F" else Fs[0],
                    xi_max=xis if scan == "xi_max" else xis[0], Omega=float(block["Omega"]),
                    Psi=values.angle(block["Psi"]), grid=values.grid(block["grid"]), cycles=int(block["cycles"]),
                    n_points=int(block["n_points"]), steps_per_cycle=ctx.steps_per_cycle,
                    tasks=[{"F": f, "xi_max": xis, "q_max": []} for f in Fs])

    def products(self, experiment, params):
        scan = (params["scan"],)
        basin = _basin_product(experiment, params, build_basin_stack, basin_contract(scan))
        stack = scan if params["scan"] == "F" else ()  # one chart serves every xi_max; one per F
        return [basin, Product(dataset_path("numeric", f"chart_{experiment}"), "numeric", build_chart_agreement,
                               tiles=True, title=params["title"], inputs={"basin": basin.path},
                               contract={**chart_contract(stack), "iou": scan, "pixel_agreement": scan},
                               history=(f"safebasins.numerics.escape_chart tiles gathered + analytic/numeric "
                                        f"agreement ({experiment})"))]

    def figure_inputs(self, experiment, params):
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

    def check(self, block, key, ctx):
        ctx.check_grid(f"{key}.grid", block["grid"])
        ctx.check_thresholds_below_separatrix(f"{key}.xi_max", block["xi_max"], "an analytic safe basin", ctx.well_at(key))
        if "box" in block:
            ctx.check_interval(f"{key}.box[0]", block["box"][0])
            ctx.check_interval(f"{key}.box[1]", block["box"][1])
        n_line = block["line"]["n"] if block.get("line") else 0
        if block["n_trajectories"] > block["n_candidates"] + n_line:
            ctx.fail(f"{key}.n_trajectories", f"{block['n_trajectories']} trajectories requested but only "
                                              f"n_candidates + line.n = {block['n_candidates'] + n_line} drawn")

    def resolve(self, block, ctx):
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

    def cost(self, params):
        n_line = params["line"]["n"] if params.get("line") else 0
        return (params["n_candidates"] + n_line) * params["n_iter"] * params["steps_per_cycle"]

    def products(self, experiment, params):
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

    def figure_inputs(self, experiment, params):
        return {"analytic": dataset_path("analytic", f"basin_{experiment}"),
                "numeric": dataset_path("numeric", f"strobe_{experiment}")}
