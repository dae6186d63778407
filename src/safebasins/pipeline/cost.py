"""Cost estimate and cost guard: upper-bound work of every experiment, numeric and analytic.

Each kind's ``cost`` counts the trajectory-steps its numerics integrate if no trajectory
escapes early (the real cost is lower); :func:`analytic_cost` counts the slow-flow evaluations
of its analytic products (IC grid points x basins, resonance-manifold points, F_cr xi nodes
x Omega points x curves).  ``scripts/estimate_cost.py`` prints the table; the Snakefile prints
the totals of the requested targets with the expected time and refuses, before any job runs, a
run above ``numerics.budget_core_hours`` (numerics) or ``numerics.budget_analytic_evaluations``
(analytic) unless ``numerics.allow_expensive: true``.  :func:`job_cost` and :func:`resources`
turn the numeric estimate into each job's ``runtime`` and ``mem_mb`` for a cluster scheduler
(workflow/rules/common.smk, the SLURM profile).
"""
from __future__ import annotations

import functools
import inspect
import math
import importlib
from collections.abc import Callable, Collection
from typing import TYPE_CHECKING, Any

from safebasins.pipeline.validation import fail

if TYPE_CHECKING:
    from safebasins.pipeline.plan import Plan
    from safebasins.pipeline.registry import Experiment, Params

#: trajectory-steps per second and core of the CPU engine on an escape chart of the quartic
#: (benchmarks/bench_escape.py: 1.0e9 on 2 cores of an AMD EPYC Zen 5 with AVX-512, ~4.4 GHz;
#: 2.2e9 dense); other wells count their steps times their step_cost (exp_cost)
RATE_PER_CORE = 5.0e8
#: slow-flow evaluations per second and core, to the order of magnitude (same machine:
#: 2e6 per IC of the quartic, 4e5 of a numeric well, 1e6 per resonance-manifold point, 2e7 per
#: xi node of F_cr)
ANALYTIC_RATE = 1.0e6
#: the random numbers of one step of a noisy ensemble (safebasins.numerics.noise), by the law of
#: its variates (core.noise_variates), in steps of the quartic: added to the well's step_cost
#: (benchmarks/bench_noise.py: the noisy quartic runs at 0.15-0.20 of the deterministic rate with
#: Gaussian variates, a Philox block and a Box-Muller pair a step; at 0.56-0.60 with five-point
#: variates, a Philox block per 16 steps)
NOISE_STEP_COSTS = {"gaussian": 5.0, "five-point": 0.8}


def exp_cost(exp: Experiment) -> int:
    """Upper-bound trajectory-steps of one experiment's numerics, in steps of the quartic (its
    kind's ``cost`` times its well's ``step_cost``, safebasins.wells.base: a transcendental well's
    scalar lanes cost up to 150 quartic steps each); 0 for analytic-only kinds."""
    steps = exp.kind.cost(exp.params)
    return int(steps * _step_cost(exp.params)) if steps else 0


def _step_cost(params: Params) -> float:
    from safebasins import wells

    return wells.from_spec(params["well"]).step_cost


def costs(run: Plan, experiments: Collection[str] | None = None) -> dict[str, int]:
    """Experiment -> upper-bound trajectory-steps of its numerics (``experiments``: the names to
    count, default all)."""
    return {n: exp_cost(e) for n, e in run.experiments.items() if experiments is None or n in experiments}


# ---------------------------------------------------------------------- analytic work
@functools.cache
def _default(func: str, arg: str) -> Any:
    """A library default (``"module:function"``), read from its signature, never restated."""
    mod, _, name = func.partition(":")
    return inspect.signature(getattr(importlib.import_module(mod), name)).parameters[arg].default


def _grid(p: Params) -> int:
    nq, np_ = p["grid"]["n"]
    return int(nq) * int(np_)


def _n(v: Any) -> int:
    """Length of a list-valued parameter (1 for a scalar)."""
    return len(v) if isinstance(v, (list, tuple)) else 1


#: slow-flow evaluations one damped F_cr point costs (an F scan and bisection of damped slow
#: trajectories: about 0.35 s per Omega on one core of the machine of ANALYTIC_RATE, quartic)
DAMPED_FCR_EVALUATIONS = 400_000


def _fcr(p: Params) -> int:
    # critical_forcing solves each (Omega, curve) on an xi grid of n_grid nodes; a damped curve
    # integrates slow trajectories instead
    per = [DAMPED_FCR_EVALUATIONS if c.get("damping", 0.0) > 0 else _default("safebasins.theory:critical_forcing",
                                                                              "n_grid") for c in p["curves"]]
    return len(p["Omega"]) * sum(per)


#: slow-flow evaluations one IC of a damped analytic basin costs (its slow trajectory is integrated
#: until it settles or escapes: 1e4 ICs of the quartic in 1.3-2.5 s at beta = 0.005-0.01, Fig 14's
#: forcing, on 2 shared cores of the machine of ANALYTIC_RATE)
DAMPED_BASIN_EVALUATIONS = 200


def _basin_ic(p: Params) -> int:
    # the IC grid of an analytic basin: one level-curve test per IC, or a damped slow trajectory
    return _grid(p) * (DAMPED_BASIN_EVALUATIONS if p.get("damping", 0.0) > 0 else 1)


def _xi_true(n_gamma: int, n_xi: int | None = None) -> int:
    # xi_true_analytic: n_gamma x n_xi points per refinement level
    f = "safebasins.analysis.phase_invariant:xi_true_analytic"
    return n_gamma * (n_xi or _default(f, "n_xi")) * _default(f, "levels")


#: kind name -> slow-flow evaluations of its analytic products (resolved params; run for the
#: kinds that read other experiments).  A kind may instead define ``analytic_cost(params)``.
ANALYTIC_COSTS: dict[str, Callable[[Params, Plan | None], int]] = {
    "fcr_theory": lambda p, run: _fcr(p),
    "fcr_compare": lambda p, run: _fcr(p),
    "basin_rm": lambda p, run: _basin_ic(p) + p["manifold"]["n_gamma"] * p["manifold"]["n_xi"] + p["n_points"],
    "basin_chart": lambda p, run: (_basin_ic(p) + p["n_points"]) * _n(p[p["scan"]]),
    "strobe": lambda p, run: _grid(p) + p["n_points"],
    "erosion": lambda p, run: _n(p["fourier"]) * _n(p["F"]) * _n(p["xi_max"]) * _basin_ic(
        {**p, "grid": {"n": [p["analytic_n"]] * 2}} if p["analytic_n"] else p),
    "true_basin": lambda p, run: _n(p["fourier"]) * _n(p["xi_max"]) * (
        _n(p["Psi"]) * (_grid(p) + p["n_points"]) + _xi_true(p["n_gamma"])),
    "integrity_map": lambda p, run: _n(p["Omega"]) * _n(p["F"]) * (_grid(p) + _xi_true(p["n_gamma"], p["n_xi"])),
    "fourier_compare": lambda p, run: _fourier_compare(p, run),
}


def _fourier_compare(p: Params, run: Plan | None) -> int:
    # both first harmonics of the F_cr curves and basins it compares (experiments of the run)
    if run is None:
        raise ValueError("the analytic cost of a fourier_compare experiment needs the run holding the experiments "
                         "it compares")
    return 2 * sum(analytic_cost(run.experiments[n], run) for n in (*p["fcr"], *p["iou"]) if n in run.experiments)


def analytic_cost(exp: Experiment, run: Plan | None = None) -> int:
    """Upper-bound slow-flow evaluations of one experiment's analytic products: its kind's
    ``analytic_cost(params)`` if it has one, else :data:`ANALYTIC_COSTS` (0 for a kind without
    analytic products)."""
    own = getattr(exp.kind, "analytic_cost", None)
    if own is not None:
        return int(own(exp.params))
    f = ANALYTIC_COSTS.get(exp.kind.name)
    return int(f(exp.params, run)) if f is not None else 0


def analytic_costs(run: Plan, experiments: Collection[str] | None = None) -> dict[str, int]:
    """Experiment -> upper-bound slow-flow evaluations (``experiments``: the names, default all)."""
    return {n: analytic_cost(e, run) for n, e in run.experiments.items() if experiments is None or n in experiments}


def params_cost(kind: str, params: Params, numeric: bool = True) -> tuple[int, int]:
    """(trajectory-steps, slow-flow evaluations) of one run of ``kind`` (a registered kind's name)
    with resolved ``params`` (the command line's runs; ``numeric=False``: analytic only)."""
    from safebasins.pipeline.config import load_kinds
    from safebasins.pipeline.registry import KINDS, Experiment

    load_kinds()
    k = KINDS[kind]
    exp = Experiment(name=params.get("experiment", kind), kind=k, key=kind, params=params, figure=None, products=(),
                     tasks=())
    return (exp_cost(exp) if numeric else 0), analytic_cost(exp)


def budgets() -> dict[str, float]:
    """The default budgets of the config schema (its one home): ``budget_core_hours``,
    ``budget_analytic_evaluations``."""
    from safebasins.pipeline.config import SCHEMA_PATH, load_yaml

    props = load_yaml(SCHEMA_PATH)["properties"]["numerics"]["properties"]
    return {k: props[k]["default"] for k in ("budget_core_hours", "budget_analytic_evaluations")}


# ---------------------------------------------------------------------- report and guard
def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def report(run: Plan, cores: int = 1, rate: float = RATE_PER_CORE,
           experiments: Collection[str] | None = None) -> list[str]:
    """One line per experiment with numerics or analytic work, and the totals."""
    c, a = costs(run, experiments), analytic_costs(run, experiments)
    lines = [f"{e:22s} {c[e]:10.3e} steps  <= {_duration(c[e] / rate / cores):>8s}   "
             f"{a[e]:10.3e} slow-flow evaluations  ~ {_duration(a[e] / ANALYTIC_RATE / cores):>8s}"
             for e in c if c[e] or a[e]]
    total, atotal = sum(c.values()), sum(a.values())
    lines.append(f"{'total':22s} {total:10.3e} steps  <= {_duration(total / rate / cores):>8s}   "
                 f"{atotal:10.3e} slow-flow evaluations  ~ {_duration(atotal / ANALYTIC_RATE / cores):>8s}"
                 f"   on {cores} core(s) at {rate:.1e} steps/s and {ANALYTIC_RATE:.0e} evaluations/s per core")
    return lines


def _largest(c: dict[str, int], scale: float, unit: str) -> str:
    top = sorted(c.items(), key=lambda kv: -kv[1])[:3]
    return ", ".join(f"{e} {s / scale:.3g} {unit}" for e, s in top if s)


def guard(run: Plan, cores: int = 1, rate: float = RATE_PER_CORE,
          experiments: Collection[str] | None = None) -> str:
    """The cost summary line of ``experiments`` (default: all); ConfigError naming
    ``numerics.budget_core_hours`` or ``numerics.budget_analytic_evaluations`` if over budget
    (unless ``numerics.allow_expensive``)."""
    c, a = costs(run, experiments), analytic_costs(run, experiments)
    total, atotal = sum(c.values()), sum(a.values())
    core_hours = total / rate / 3600
    num = run.config["numerics"]
    what = ("this configuration" if experiments is None else "the requested targets ("
            + (", ".join(sorted(c)) if len(c) <= 4 else f"{len(c)} experiments") + ")")
    summary = (f"safebasins cost estimate ({what}): at most {total:.2e} trajectory-steps = {core_hours:.3g} "
               f"core-hours, <= {_duration(total / rate / max(cores, 1))} on {cores} core(s) at {rate:.1e} steps/s "
               f"per core; {atotal:.2e} slow-flow evaluations (~{_duration(atotal / ANALYTIC_RATE / max(cores, 1))})")
    if num["allow_expensive"]:
        return summary
    if core_hours > num["budget_core_hours"]:
        fail("numerics.budget_core_hours",
             f"{what} costs up to {core_hours:.3g} core-hours ({total:.2e} trajectory-steps; "
             f"largest: {_largest(c, rate * 3600, 'core-h')}), above the budget of {num['budget_core_hours']:g} "
             "core-hours. Reduce grids, cycles or scans, raise numerics.budget_core_hours, or set "
             "numerics.allow_expensive: true")
    if atotal > num["budget_analytic_evaluations"]:
        fail("numerics.budget_analytic_evaluations",
             f"the analytic products of {what} need {atotal:.2e} slow-flow evaluations "
             f"(largest: {_largest(a, 1, 'evaluations')}; ~{_duration(atotal / ANALYTIC_RATE)} at "
             f"{ANALYTIC_RATE:.0e}/s), above the budget of {num['budget_analytic_evaluations']:.3g}. Reduce Omega "
             "lists, grids, manifold or boundary resolutions, raise numerics.budget_analytic_evaluations, or set "
             "numerics.allow_expensive: true")
    return summary


# ---------------------------------------------------------------------- cluster resources
#: Per-job resources for a cluster scheduler (``resources: runtime=, mem_mb=`` of the heavy rules in
#: workflow/rules, read by the SLURM profile; a local run ignores them). Runtime: the job's
#: upper-bound steps at RATE_PER_CORE on its threads, times RUNTIME_SAFETY (slower cluster CPUs,
#: start-up, numba compilation), at least RUNTIME_FLOOR_MIN minutes. Memory: MEM_BASE_MB (Python,
#: numba, xarray; 200-300 MB RSS measured per job) plus MEM_PER_POINT_BYTES per trajectory or grid
#: point the job holds.
RUNTIME_SAFETY = 3.0
RUNTIME_FLOOR_MIN = 15
MEM_BASE_MB = 1000
MEM_PER_POINT_BYTES = 2048


def _grid_points(params: Params) -> int:
    """Points of the experiment's initial-condition grid (0 if it has none)."""
    grid = params.get("grid")
    return int(grid["n"][0]) * int(grid["n"][1]) if isinstance(grid, dict) and "n" in grid else 0


def job_cost(run: Plan, *, tile_of: str | None = None, dataset: str | None = None) -> tuple[float, int]:
    """(upper-bound trajectory-steps, points held) of one job.

    ``tile_of=experiment``: one ``chart_tile`` job, the experiment's cost split evenly over its
    tasks x ``numerics.tiles`` tiles; it holds its trajectories (chart tasks integrate
    ``params["cycles"]`` cycles of ``params["steps_per_cycle"]`` steps).  ``dataset=path``: one
    dataset job, holding its experiment's grid once per chart task.  A chart experiment
    integrates in its tiles, so its datasets only gather (0 steps), or with ``numerics.tiles`` = 0
    in the one dataset that reads its charts (the whole cost); an experiment without chart tasks
    integrates in its heavy products (in each product if none is heavy).
    """
    if (tile_of is None) == (dataset is None):
        raise ValueError("job_cost: give exactly one of tile_of= and dataset=")
    if tile_of is not None:
        if not run.tiles:
            raise ValueError("job_cost: numerics.tiles is 0, there are no chart_tile jobs")
        exp = run.experiments[tile_of]
        n_jobs = len(exp.tasks) * run.tiles
        steps = exp_cost(exp) / n_jobs
        return steps, math.ceil(steps / (int(exp.params["cycles"]) * int(exp.params["steps_per_cycle"])))
    assert dataset is not None  # (exactly one of tile_of, dataset: checked above)
    exp, prod = run.experiment_of(dataset), run.product(dataset)
    points = _grid_points(exp.params) * max(len(exp.tasks), 1)
    heavy = [p for p in exp.products if p.heavy]
    if run.integrates_tasks(dataset):
        return float(exp_cost(exp)), points
    if exp.tasks or (heavy and not prod.heavy):
        return 0.0, points
    return exp_cost(exp) / max(len(heavy), 1), points


def resources(steps: float, points: int, threads: int = 1, rate: float = RATE_PER_CORE) -> dict[str, int]:
    """``{"runtime": minutes, "mem_mb": MB}`` of a job integrating ``steps`` trajectory-steps on
    ``threads`` cores and holding ``points`` trajectories or grid points."""
    minutes = RUNTIME_SAFETY * steps / (rate * max(int(threads), 1)) / 60
    return {"runtime": max(RUNTIME_FLOOR_MIN, math.ceil(minutes)),
            "mem_mb": math.ceil(MEM_BASE_MB + points * MEM_PER_POINT_BYTES / 2**20)}
