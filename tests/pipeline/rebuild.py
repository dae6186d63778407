"""Every dataset of a sandbox's configuration built without Snakemake, in a few long-lived worker
processes: the same product builds as the rules (``safebasins.pipeline.runtime.build_dataset``),
in dependency order, with the parameter files the ``parameters`` rule wrote.  A dataset job of
the rules starts a Python that imports the library and numba's engine again (about 5 s on a
2-core Xeon, most of a quick job); here each worker pays that once.

Run as a script in the environment under test (``python -m tests.pipeline.rebuild WD N CONFIG...``,
from the repository root); prints one JSON line: {path: seconds}.
"""
from __future__ import annotations

import json
import multiprocessing
import os
import sys
import time
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait

from safebasins.pipeline.plan import Plan, plan
from safebasins.pipeline.registry import Job
from safebasins.pipeline.runtime import build_dataset, load_params

_PLAN: Plan | None = None


def _init(wd: str, configfiles: list[str]) -> None:
    global _PLAN
    os.chdir(wd)
    _PLAN = plan(configfiles)


def _build(path: str) -> float:
    assert _PLAN is not None
    t0 = time.perf_counter()
    exp = _PLAN.experiment_of(path)
    job = Job(threads=1, backend=_PLAN.config["numerics"]["backend"])
    build_dataset(load_params(exp.params_file), path, _PLAN.product_inputs(path), job,
                  integrate_tasks=bool(_PLAN.integrates_tasks(path)), rule=f"{_PLAN.product(path).stage}_dataset")
    return time.perf_counter() - t0


def rebuild(wd: str, workers: int, configfiles: list[str]) -> dict[str, float]:
    """Build every dataset of the plan of ``configfiles`` (the last overrides, as Snakemake's
    --configfile) under ``wd``/results/data; a dataset starts once the datasets it reads exist.
    Returns the seconds each took.  The first failure is raised."""
    _init(wd, configfiles)
    assert _PLAN is not None
    datasets = set(_PLAN.datasets())
    needs = {p: {x for v in _PLAN.product_inputs(p).values() for x in (v if isinstance(v, (list, tuple)) else [v])
                 if x in datasets} for p in _PLAN.datasets()}
    done: dict[str, float] = {}
    running: dict[Future[float], str] = {}
    ctx = multiprocessing.get_context("spawn")   # no fork of a process whose numba/BLAS threads may run
    with ProcessPoolExecutor(workers, mp_context=ctx, initializer=_init, initargs=(wd, configfiles)) as pool:
        while needs or running:
            for path in [p for p, n in needs.items() if n <= done.keys()]:
                running[pool.submit(_build, path)] = path
                del needs[path]
            if not running:
                raise RuntimeError(f"datasets whose inputs are never built: {sorted(needs)}")
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for fut in finished:
                done[running.pop(fut)] = fut.result()
    return done


if __name__ == "__main__":
    wd, n, *files = sys.argv[1:]
    print(json.dumps(rebuild(wd, int(n), [os.path.join(wd, f) for f in files])))
