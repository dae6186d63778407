"""Cost estimate and cost guard: upper-bound trajectory-steps of every experiment.

Each kind's ``cost`` counts the trajectory-steps its numerics integrate if no trajectory
escapes early (the real cost is lower).  ``scripts/estimate_cost.py`` prints the table; the
Snakefile prints the total with the expected time and refuses, before any job runs, a
configuration above ``numerics.budget_core_hours`` unless ``numerics.allow_expensive: true``.
"""
from __future__ import annotations

from safebasins.pipeline.validation import fail

#: trajectory-steps per second and core of the CPU engine on an escape chart (benchmarks/
#: bench_escape.py: 1.0e9 on 2 cores of an AMD EPYC Zen 4 with AVX-512 at 2.6 GHz; 1.35e9 dense)
RATE_PER_CORE = 5.0e8


def costs(run) -> dict[str, int]:
    """Experiment -> upper-bound trajectory-steps of its numerics (0 for analytic-only kinds)."""
    return {n: int(e.kind.cost(e.params)) for n, e in run.experiments.items()}


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
