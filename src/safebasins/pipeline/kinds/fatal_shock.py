"""Kind ``minimal_fatal_shock``: the smallest kick that drives each period-1 attractor of a damped well
to escape, at shock phases spread over one forcing period, with the LIM centred on the attractor beside
it (:func:`safebasins.analysis.fatal_shock.minimal_fatal_shock`).  Dataset:
``results/data/extras/<experiment>.nc``.
"""
from __future__ import annotations

import math
from typing import Any

from safebasins.pipeline import values
from safebasins.pipeline.registry import Job, Kind, Product, dataset_path, register
from safebasins.pipeline.validation import CheckContext

POSITIVE = {"type": "number", "exclusiveMinimum": 0}
APN = ("attractor", "phase", "norm")
#: the cost estimate's refinement per attractor, phase and norm: k-section rounds of 32 points each
#: to the relative width tol (ceil(log(1/tol) / log 32)) and ~20 Brent evaluations per refined
#: minimum (measured: 12-16 thousand refinement shocks at the defaults, against 27 thousand estimated)
_SECTION_POINTS, _BRENT_EVALS = 32, 20
#: attractors counted by the cost estimate (the resonant and the non-resonant branch)
_ATTRACTORS = 2


def shock_phases(Psi: float, n_phases: int) -> list[float]:
    """The forcing phases ``Omega t + Psi`` of the shocks: ``Psi + 2 pi k / n_phases`` modulo 2 pi,
    k = 0 .. n - 1 (k = 0 is the section t = 0 of the experiment's forcing)."""
    return [(Psi + 2.0 * math.pi * k / n_phases) % (2.0 * math.pi) for k in range(n_phases)]


def build_fatal_shock(params: dict[str, Any], data: dict[str, Any], job: Job) -> Any:
    """The attractors, then the minimal fatal shock of each at each phase, in each norm."""
    from safebasins.analysis.fatal_shock import minimal_fatal_shock

    s = params["search"]
    print(f"{params['experiment']}: minimal fatal shock at F = {params['F']}, {len(params['phases'])} phases, "
          f"{params['cycles']} cycles", flush=True)
    return minimal_fatal_shock(params["F"], params["Omega"], values.damping(params), values.base_well(params),
                               phases=params["phases"], xi_max=params["xi_max"], cycles=params["cycles"],
                               weights=params["weights"], radius_max=params["radius_max"],
                               n_directions=s["n_directions"], n_radii=s["n_radii"], n_refine=s["n_refine"],
                               n_lim=s["n_lim"], n_seeds=s["n_seeds"], tol=s["tol"],
                               steps_per_cycle=params["steps_per_cycle"], threads=job.threads)


@register
class MinimalFatalShock(Kind):
    name = "minimal_fatal_shock"
    damped = True
    description = ("the minimal fatal shock of a damped well's attractors: the smallest kick (energy norm, and a "
                   "weighted norm if given) that leads from each period-1 attractor to escape, at shock phases over "
                   "one forcing period, with the LIM centred on the attractor beside it")
    builder = "safebasins.plotting.fatal_shock:figure_fatal_shock"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False,
        "required": ["F", "Omega", "xi_max"],
        "properties": {
            "F": {"$ref": "#/$defs/forcing"},
            "Omega": {"$ref": "#/$defs/frequency"},
            "Psi": {"$ref": "#/$defs/angle", "default": 0.0},
            "xi_max": {"$ref": "#/$defs/threshold"},
            "n_phases": {"description": "shock phases Omega t + Psi = Psi + 2 pi k / n_phases over one forcing "
                                        "period (k = 0: the section t = 0)",
                         "type": "integer", "minimum": 1, "default": 8},
            "cycles": {"$ref": "#/$defs/cycles", "default": 20},
            "weights": {"description": "(w_q, w_p) of a weighted norm sqrt(w_q dq^2 + w_p dp^2) beside the energy "
                                       "norm (null: the energy norm only)",
                        "oneOf": [{"type": "null"},
                                  {"type": "array", "minItems": 2, "maxItems": 2, "items": POSITIVE}],
                        "default": None},
            "radius_max": {"description": "largest energy-norm shock searched (null: 1.5 sqrt(2 xi_max))",
                           "oneOf": [{"type": "null"}, POSITIVE], "default": None},
            "steps_per_cycle": {"description": "integrator steps per forcing period of the escape test (null: the "
                                               "run's numerics.steps_per_cycle); the energy is checked after each "
                                               "step, so a coarse step misses grazing escapes and the MFS comes out "
                                               "high",
                                "oneOf": [{"type": "null"}, {"type": "integer", "minimum": 4}], "default": None},
            "search": {
                "type": "object", "additionalProperties": False, "default": {},
                "properties": {
                    "n_directions": {"description": "directions of the polar grid of shocks", "type": "integer",
                                     "minimum": 8, "default": 64},
                    "n_radii": {"description": "radii of the polar grid of shocks", "type": "integer", "minimum": 2,
                                "default": 48},
                    "n_refine": {"description": "local minima over the direction refined by Brent", "type": "integer",
                                 "minimum": 1, "default": 3},
                    "n_lim": {"description": "nodes per side of the LIM's Cartesian grid centred on the attractor "
                                             "(odd: the attractor is a node)",
                              "type": "integer", "minimum": 3, "default": 101},
                    "n_seeds": {"description": "seeds per side of the grid iterated to find the attractors",
                                "type": "integer", "minimum": 1, "default": 7},
                    "tol": {"description": "relative width of the final radius bracket", "type": "number",
                            "exclusiveMinimum": 0, "exclusiveMaximum": 0.1, "default": 1.0e-9},
                },
            },
        },
    }

    def check(self, block: dict[str, Any], key: str, ctx: CheckContext) -> None:
        if not block["damping"] > 0:
            ctx.fail(f"{key}.damping", "attractors inside the well need damping > 0")
        if block["search"]["n_lim"] % 2 == 0:
            ctx.fail(f"{key}.search.n_lim", f"must be odd (the attractor a node of the LIM grid), got "
                                            f"{block['search']['n_lim']}")

    def resolve(self, block: dict[str, Any], ctx: Any) -> dict[str, Any]:
        s, w, r = block["search"], block["weights"], block["radius_max"]
        spc = block["steps_per_cycle"]
        return dict(F=float(block["F"]), Omega=float(block["Omega"]), Psi=values.angle(block["Psi"]),
                    xi_max=float(block["xi_max"]),
                    phases=shock_phases(values.angle(block["Psi"]), int(block["n_phases"])),
                    cycles=int(block["cycles"]), weights=None if w is None else [float(x) for x in w],
                    radius_max=None if r is None else float(r),
                    steps_per_cycle=ctx.steps_per_cycle if spc is None else int(spc),
                    search={"n_directions": int(s["n_directions"]), "n_radii": int(s["n_radii"]),
                            "n_refine": int(s["n_refine"]), "n_lim": int(s["n_lim"]), "n_seeds": int(s["n_seeds"]),
                            "tol": float(s["tol"])})

    def cost(self, params: dict[str, Any]) -> int:
        """An estimate (the number of attractors is known only when they are found): per attractor,
        phase and norm the polar and LIM grids and the refinement, each shock integrated over the whole
        horizon (the seeds' settling iterations, a few per cent of it, are left out)."""
        s = params["search"]
        rounds = max(1, math.ceil(math.log(1.0 / s["tol"]) / math.log(_SECTION_POINTS)))
        refine = (s["n_directions"] * _SECTION_POINTS * rounds
                  + s["n_refine"] * _BRENT_EVALS * (s["n_radii"] + _SECTION_POINTS * rounds))
        shocks = s["n_directions"] * s["n_radii"] + s["n_lim"] ** 2 + refine
        norms = 1 if params["weights"] is None else 2
        per_shock = params["cycles"] * params["steps_per_cycle"]
        return int(_ATTRACTORS * len(params["phases"]) * norms * shocks * per_shock)

    def products(self, experiment: str, params: dict[str, Any]) -> list[Product]:
        return [Product(dataset_path("extras", experiment), "extras", build_fatal_shock, heavy=True,
                        title=params["title"] + " (minimal fatal shock)",
                        history=f"safebasins.analysis.fatal_shock.minimal_fatal_shock ({experiment})",
                        contract={"mfs": APN, "mfs_safe": APN, "mfs_grid": APN, "lim": APN, "shock_dq": APN,
                                  "shock_dp": APN, "escape_cycle": APN, "lim_spacing": ("norm",),
                                  "q_attractor": ("attractor", "phase"), "p_attractor": ("attractor", "phase"),
                                  "multiplier_modulus": ("attractor",), "response_amplitude": ("attractor",)})]

    def figure_inputs(self, experiment: str, params: dict[str, Any]) -> dict[str, str]:
        return {"shock": dataset_path("extras", experiment)}
