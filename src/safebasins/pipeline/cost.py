"""Cost estimate: upper-bound trajectory-steps of every experiment (no early escape assumed).

Read by ``scripts/estimate_cost.py``; each kind's ``cost`` gives its count.
"""
from __future__ import annotations

#: trajectory-steps per second of the CPU engine on 2 cores (benchmarks/bench_escape.py:
#: 1.0e9 on an escape chart, 1.35e9 dense, AMD EPYC Zen 4; a conservative round figure)
RATE = 1.5e9


def costs(run) -> dict[str, int]:
    """Experiment -> upper-bound trajectory-steps of its numerics (0 for analytic-only kinds)."""
    return {n: int(e.kind.cost(e.params)) for n, e in run.experiments.items()}


def report(run, rate=RATE) -> list[str]:
    lines = []
    c = costs(run)
    for e, s in c.items():
        if s:
            lines.append(f"{e:18s} {s:10.3e} steps  <= {s / rate:7.1f} s")
    total = sum(c.values())
    lines.append(f"{'total':18s} {total:10.3e} steps  <= {total / rate:7.1f} s at {rate:.1e} steps/s")
    return lines
