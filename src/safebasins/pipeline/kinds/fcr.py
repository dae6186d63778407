"""Kinds ``fcr_theory`` (Figs 1-4) and ``fcr_compare`` (Figs 10-12): critical forcing F_cr(Omega).

Curves come from list-valued ``xi_max`` / ``xi_ini`` / ``gamma_ini`` (equal lengths or length
1); the analytic product stacks :func:`safebasins.theory.critical_forcing` over ``curve``, the
numeric one :func:`safebasins.numerics.critical_forcing_numeric` (bisection + F scan) for the
IC ``theory.initial_condition(xi_ini, gamma_ini, Psi)``.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from safebasins.pipeline import values
from safebasins.pipeline.registry import (Block, Contract, FigureInputs, Inputs, Job, Kind, Params, Product,
                                          dataset_path, register)

if TYPE_CHECKING:
    import xarray as xr

    from safebasins.pipeline.registry import ResolveContext
    from safebasins.pipeline.validation import CheckContext
    from safebasins.wells.base import Well

_CO = ("curve", "Omega")
ANALYTIC_CONTRACT: Contract = {**{v: _CO for v in ("F_cr", "mechanism", "F_MM_0", "F_MM_pi", "F_SM", "F_SMM")},
                     **{c: ("curve",) for c in ("xi_max", "xi_ini", "gamma_ini", "label")}}
NUMERIC_CONTRACT: Contract = {**{v: _CO for v in ("F_cr", "F_cr_low", "F_cr_high", "F_escape_low", "F_escape_all",
                                         "non_monotone", "F_bracket_used_high", "F_bracket_widenings")},
                    **{c: ("curve",) for c in ("xi_max", "xi_ini", "gamma_ini", "Psi", "label", "q0", "p0")}}

#: the damped theory's variables (theory.critical_forcing with damping > 0: no mechanism branches)
DAMPED_ANALYTIC_CONTRACT: Contract = {**{v: _CO for v in ("F_cr", "F_settle", "F_cr_undamped", "F_min", "xi_attractor",
                                                 "t_escape", "undecided")},
                            **{c: ("curve",) for c in ("xi_max", "xi_ini", "gamma_ini", "label", "damping")}}


def analytic_contract(params: Params) -> Contract:
    """The analytic dataset's contract: the damped theory's when the experiment is damped."""
    return DAMPED_ANALYTIC_CONTRACT if "damping" in params else ANALYTIC_CONTRACT


CURVES_SCHEMA: dict[str, Any] = {
    "Omega": {"$ref": "#/$defs/omega_range"},
    "xi_max": {"$ref": "#/$defs/threshold_list"},
    "xi_ini": {"$ref": "#/$defs/energy_list", "default": 0.0},
    "gamma_ini": {"$ref": "#/$defs/angle_list", "default": 0.0},
    # one value, or one per curve (F_cr(Omega) for several beta); every value > 0 in a list
    "damping": {"$ref": "#/$defs/damping_list", "default": 0.0},
}


def _check_curves(block: Block, key: str, ctx: CheckContext) -> None:
    ctx.check_range(f"{key}.Omega", block["Omega"], positive=True)
    lists = values.curve_lists(block)
    lens = {k: len(v) for k, v in lists.items()}
    n = max(lens.values())
    beta = values.as_list(block["damping"])
    if len(beta) > 1 and not all(b > 0 for b in beta):
        ctx.fail(f"{key}.damping", f"a list of damping values makes one damped curve each: every value must be > 0 "
                                   f"(the undamped theory has other outputs, the mechanism branches), got {beta}")
    for k, m in lens.items():
        if m not in (1, n):
            ctx.fail(f"{key}.{k}", f"has {m} values but another curve list has {n}: lists must have equal length")
    ctx.check_thresholds_below_separatrix(f"{key}.xi_max", block["xi_max"], "analytic F_cr", ctx.well_at(key),
                                          block["damping"])
    full = {k: v * (n // len(v)) for k, v in lists.items()}
    xm, xi = full["xi_max"], full["xi_ini"]
    seen: set[tuple[Any, ...]] = set()
    for i, curve in enumerate(zip(*full.values())):
        if curve in seen:
            ctx.fail(key, f"curve {i} ({', '.join(full)}) = {curve} repeats an earlier curve")
        seen.add(curve)
    for i, (a, b) in enumerate(zip(xm, xi)):
        if b >= a:
            ctx.fail(f"{key}.xi_ini" + (f"[{i}]" if lens["xi_ini"] > 1 else ""),
                     f"initial energy {b} must be below the truncation level xi_max = {a}")


def _bracket(value: list[float] | None, well: Well | dict[str, Any]) -> list[float]:
    """The numeric F bracket of a config: as given, or (null) the well's default."""
    if value is not None:
        return [float(x) for x in value]
    from safebasins.numerics.bisection import default_bracket

    return list(default_bracket(well))


def build_fcr_analytic(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """One theory.critical_forcing per curve, stacked over ``curve``."""
    from safebasins.analysis.fcr_curves import analytic_fcr_curves

    out = analytic_fcr_curves(params["Omega"], params["curves"], well=values.well(params), label=params["experiment"])
    out.attrs["fourier"] = params["fourier"]
    return out


def build_fcr_numeric(params: Params, data: Inputs, job: Job) -> xr.Dataset:
    """One numerics.critical_forcing_numeric per curve (IC from (xi_ini, gamma_ini, Psi))."""
    from safebasins.analysis.fcr_curves import numeric_fcr_curves

    n = params["numeric"]
    return numeric_fcr_curves(n["Omega"], params["curves"], well=values.well(params), cycles=n["cycles"],
                              tol=n["tol"], F_bracket=n["F_bracket"], criterion=n["criterion"], n_scan=n["n_scan"],
                              steps_per_cycle=n["steps_per_cycle"], threads=job.threads, backend=job.backend,
                              label=params["experiment"])


@register
class FcrTheory(Kind):
    name = "fcr_theory"
    damped = True
    description = "analytic F_cr(Omega) curves; list-valued xi_max / xi_ini / gamma_ini give the curves"
    builder = "safebasins.plotting.fcr:figure_fcr"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "required": ["Omega", "xi_max"],
        "properties": dict(CURVES_SCHEMA),
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        _check_curves(block, key, ctx)

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        return dict(fourier=ctx.fourier, Omega=values.range_values(block["Omega"]),
                    curves=values.curves(block, False))

    def products(self, experiment: str, params: Params) -> list[Product]:
        return [Product(dataset_path("analytic", f"fcr_{experiment}"), "analytic", build_fcr_analytic,
                        title=params["title"], contract=analytic_contract(params),
                        history=f"safebasins.theory.critical_forcing per curve ({experiment})")]

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"analytic": dataset_path("analytic", f"fcr_{experiment}")}


@register
class FcrCompare(Kind):
    name = "fcr_compare"
    damped = True
    description = "analytic F_cr curves (fine Omega) and their numeric counterparts (coarse Omega)"
    builder = "safebasins.plotting.fcr:figure_fcr_comparison"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "required": ["Omega", "xi_max", "numeric"],
        "properties": {
            **CURVES_SCHEMA,
            "Psi": {"$ref": "#/$defs/angle", "default": 0.0},
            "numeric": {
                "type": "object", "additionalProperties": False, "required": ["Omega"],
                "properties": {
                    "Omega": {"$ref": "#/$defs/omega_range"},
                    "cycles": {"$ref": "#/$defs/cycles", "default": 3000},
                    "tol": {"type": "number", "exclusiveMinimum": 0, "default": 5.0e-5},
                    "F_bracket": {"description": "bisection bracket [F_lo, F_hi] of F; null: the well's own, "
                                                 "[0, its static escape force] (numerics.bisection.default_bracket); "
                                                 "its top is doubled (up to 3 times) where it does not escape",
                                  "oneOf": [{"type": "null"},
                                            {"type": "array", "minItems": 2, "maxItems": 2,
                                             "items": {"type": "number", "minimum": 0}}],
                                  "default": None},
                    "n_scan": {"type": "integer", "minimum": 0, "default": 60},
                    "criterion": {"enum": ["energy", "displacement"], "default": "energy"},
                },
            },
        },
    }

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        _check_curves(block, key, ctx)
        num = block["numeric"]
        ctx.check_range(f"{key}.numeric.Omega", num["Omega"], positive=True)
        if num["F_bracket"] is not None:
            lo, hi = num["F_bracket"]
            if not hi > lo:
                ctx.fail(f"{key}.numeric.F_bracket", f"empty bracket [{lo}, {hi}]")

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        nb = block["numeric"]
        return dict(fourier=ctx.fourier, Omega=values.range_values(block["Omega"]), curves=values.curves(block, True),
                    numeric={"Omega": values.range_values(nb["Omega"]), "cycles": int(nb["cycles"]),
                             "tol": float(nb["tol"]), "F_bracket": _bracket(nb["F_bracket"], ctx.well),
                             "n_scan": int(nb["n_scan"]), "criterion": nb["criterion"],
                             "steps_per_cycle": ctx.steps_per_cycle})

    def products(self, experiment: str, params: Params) -> list[Product]:
        return [
            Product(dataset_path("analytic", f"fcr_{experiment}"), "analytic", build_fcr_analytic,
                    title=params["title"], contract={**analytic_contract(params), "Psi": ("curve",)},
                    history=f"safebasins.theory.critical_forcing per curve ({experiment})"),
            Product(dataset_path("numeric", f"fcr_{experiment}"), "numeric", build_fcr_numeric, heavy=True,
                    title=params["title"],
                    contract={**NUMERIC_CONTRACT, **({"damping": ("curve",)} if "damping" in params else {})},
                    history=f"safebasins.numerics.critical_forcing_numeric per curve ({experiment})"),
        ]

    def cost(self, params: Params) -> int:
        n = params["numeric"]
        from safebasins.numerics.bisection import MAX_WIDENINGS

        lo, hi = n["F_bracket"]
        # upper bound: every Omega widened to the last doubling (one ensemble each) and bisected there
        levels = MAX_WIDENINGS + math.ceil(math.log2((hi * 2 ** MAX_WIDENINGS - lo) / n["tol"]))
        return (len(params["curves"]) * len(n["Omega"]) * (levels + n["n_scan"]) * n["cycles"]
                * n["steps_per_cycle"])

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        return {"analytic": dataset_path("analytic", f"fcr_{experiment}"),
                "numeric": dataset_path("numeric", f"fcr_{experiment}")}
