"""Cost estimate and cost guard: upper-bound trajectory-steps of every experiment.

Each kind's ``cost`` counts the trajectory-steps its numerics integrate if no trajectory
escapes early (the real cost is lower).  ``scripts/estimate_cost.py`` prints the table; the
Snakefile prints the total with the expected time and refuses, before any job runs, a
configuration above ``numerics.budget_core_hours`` unless ``numerics.allow_expensive: true``.
:func:`job_cost` and :func:`resources` turn the same estimate into each job's ``runtime`` and
``mem_mb`` for a cluster scheduler (workflow/rules/common.smk, the SLURM profile).
"""
from __future__ import annotations

import math

from safebasins.pipeline.validation import fail

#: trajectory-steps per second and core of the CPU engine on an escape chart (benchmarks/
#: bench_escape.py: 1.0e9 on 2 cores of an AMD EPYC Zen 4 with AVX-512 at 2.6 GHz; 1.35e9 dense)
RATE_PER_CORE = 5.0e8


def exp_cost(exp) -> int:
    """Upper-bound trajectory-steps of one experiment's numerics (its kind's ``cost``; 0 for
    analytic-only kinds)."""
    return int(exp.kind.cost(exp.params))


def costs(run) -> dict[str, int]:
    """Experiment -> upper-bound trajectory-steps of its numerics."""
    return {n: exp_cost(e) for n, e in run.experiments.items()}


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def report(run, cores=1, rate=RATE_PER_CORE) -> list[str]:
    """One line per experiment with numerics, and the total."""
    c = costs(run)
    lines = [f"{e:18s} {s:10.3e} steps  <= {_duration(s / rate / cores):>8s}" for e, s in c.items() if s]
    total = sum(c.values())
    lines.append(f"{'total':18s} {total:10.3e} steps  <= {_duration(total / rate / cores):>8s} on {cores} core(s) "
                 f"at {rate:.1e} steps/s per core")
    return lines


def guard(run, cores=1, rate=RATE_PER_CORE) -> str:
    """The cost summary line; ConfigError naming ``numerics.budget_core_hours`` if over budget."""
    c = costs(run)
    total = sum(c.values())
    core_hours = total / rate / 3600
    num = run.config["numerics"]
    summary = (f"safebasins cost estimate: at most {total:.2e} trajectory-steps = {core_hours:.3g} core-hours, "
               f"<= {_duration(total / rate / max(cores, 1))} on {cores} core(s) at {rate:.1e} steps/s per core")
    if core_hours > num["budget_core_hours"] and not num["allow_expensive"]:
        top = sorted(c.items(), key=lambda kv: -kv[1])[:3]
        names = ", ".join(f"{e} {s / rate / 3600:.3g} core-h" for e, s in top if s)
        fail("numerics.budget_core_hours",
             f"this configuration costs up to {core_hours:.3g} core-hours ({total:.2e} trajectory-steps; "
             f"largest: {names}), above the budget of {num['budget_core_hours']:g} core-hours. Reduce grids, "
             "cycles or scans, raise numerics.budget_core_hours, or set numerics.allow_expensive: true")
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


def _grid_points(params) -> int:
    """Points of the experiment's initial-condition grid (0 if it has none)."""
    grid = params.get("grid")
    return int(grid["n"][0]) * int(grid["n"][1]) if isinstance(grid, dict) and "n" in grid else 0


def job_cost(run, *, tile_of: str | None = None, dataset: str | None = None) -> tuple[float, int]:
    """(upper-bound trajectory-steps, points held) of one job.

    ``tile_of=experiment``: one ``chart_tile`` job, the experiment's cost split evenly over its
    tasks x ``numerics.tiles`` tiles; it holds its trajectories (chart tasks integrate
    ``params["cycles"]`` cycles of ``params["steps_per_cycle"]`` steps).  ``dataset=path``: one
    dataset job, holding its experiment's grid once per chart task.  A chart experiment
    integrates in its tiles, so its datasets only gather (0 steps); an experiment without chart
    tasks integrates in its heavy products (in each product if none is heavy).
    """
    if (tile_of is None) == (dataset is None):
        raise ValueError("job_cost: give exactly one of tile_of= and dataset=")
    if tile_of is not None:
        exp = run.experiments[tile_of]
        n_jobs = len(exp.tasks) * run.tiles
        steps = exp_cost(exp) / n_jobs
        return steps, math.ceil(steps / (int(exp.params["cycles"]) * int(exp.params["steps_per_cycle"])))
    exp, prod = run.experiment_of(dataset), run.product(dataset)
    points = _grid_points(exp.params) * max(len(exp.tasks), 1)
    heavy = [p for p in exp.products if p.heavy]
    if exp.tasks or (heavy and not prod.heavy):
        return 0.0, points
    return exp_cost(exp) / max(len(heavy), 1), points


def resources(steps: float, points: int, threads: int = 1, rate: float = RATE_PER_CORE) -> dict[str, int]:
    """``{"runtime": minutes, "mem_mb": MB}`` of a job integrating ``steps`` trajectory-steps on
    ``threads`` cores and holding ``points`` trajectories or grid points."""
    minutes = RUNTIME_SAFETY * steps / (rate * max(int(threads), 1)) / 60
    return {"runtime": max(RUNTIME_FLOOR_MIN, math.ceil(minutes)),
            "mem_mb": math.ceil(MEM_BASE_MB + points * MEM_PER_POINT_BYTES / 2**20)}
