"""Cluster resources of the heavy rules (runtime, mem_mb) from the cost estimate: positive, growing
with the cost, and what the workflow hands the scheduler (dry run)."""
from __future__ import annotations

import re

import pytest
import yaml

from safebasins.pipeline.config import REPO_ROOT, merge_config
from safebasins.pipeline.cost import (MEM_BASE_MB, RATE_PER_CORE, RUNTIME_FLOOR_MIN, RUNTIME_SAFETY, exp_cost,
                                      job_cost, resources)
from safebasins.pipeline.plan import load_config, plan
from tests.pipeline.sandbox import run_snakemake

HEAVY_RULES = ("chart_tile", "analytic_dataset", "numeric_dataset", "extras_dataset")
#: Fig 13 made expensive: 24 x 24 ICs x 1e8 cycles x 16 steps, split over 2 tiles (runtime above the floor)
EXPENSIVE = {"numerics": {"tiles": 2, "allow_expensive": True}, "figures": {"fig13": {"cycles": 100_000_000}}}


def _plan(*overrides):
    """The quick configuration's plan, with overrides merged as `--configfile` does."""
    cfg = load_config([REPO_ROOT / "config" / "config.yaml", REPO_ROOT / "config" / "quick.yaml"])
    for extra in overrides:
        merge_config(cfg, extra)
    return plan(cfg)


TILES = {"numerics": {"tiles": 2}}


def _jobs(run):
    """(rule, job_cost keyword) of every heavy job of a plan."""
    jobs = [("chart_tile", {"tile_of": e}) for e in run.chart_experiments()] if run.tiles else []
    jobs += [(f"{run.product(d).stage}_dataset", {"dataset": d}) for d in run.datasets()]
    return jobs


@pytest.mark.parametrize("quick,tiles", [(True, False), (True, True), (False, False)])
def test_resources_positive_for_every_job(quick, tiles):
    run = _plan(*[TILES] * tiles) if quick else plan(REPO_ROOT / "config" / "config.yaml")
    for _, job in _jobs(run):
        steps, points = job_cost(run, **job)
        assert steps >= 0 and points >= 0, job
        res = resources(steps, points, run.threads)
        assert res["runtime"] >= RUNTIME_FLOOR_MIN and res["mem_mb"] >= MEM_BASE_MB, (job, res)
        assert all(isinstance(v, int) for v in res.values())


@pytest.mark.parametrize("tiles", [0, 2])
def test_job_costs_add_up_to_the_estimate(tiles):
    """Tiles (or, with numerics.tiles = 0, the dataset reading the charts) and integrating datasets
    share each experiment's cost; gathering datasets cost 0."""
    run = _plan({"numerics": {"tiles": tiles}})
    assert run.tiles == tiles
    for name, exp in run.experiments.items():
        charts = [p for p in exp.products if p.tiles]
        if exp.tasks and tiles:
            total = job_cost(run, tile_of=name)[0] * len(exp.tasks) * run.tiles
            assert job_cost(run, dataset=charts[0].path)[0] == 0
        elif exp.tasks:
            total = job_cost(run, dataset=charts[0].path)[0]
            assert run.integrates(charts[0].path) and not run.product_inputs(charts[0].path).get("tiles")
            with pytest.raises(ValueError, match="no chart_tile jobs"):
                job_cost(run, tile_of=name)
        else:
            total = sum(job_cost(run, dataset=p.path)[0] for p in exp.products if p.heavy) \
                or sum(job_cost(run, dataset=p.path)[0] for p in exp.products)
        assert total == pytest.approx(exp_cost(exp)), name
    with pytest.raises(ValueError):
        job_cost(run)


def test_resources_scale_with_cost():
    assert resources(0, 0) == {"runtime": RUNTIME_FLOOR_MIN, "mem_mb": MEM_BASE_MB}
    steps = 1e3 * RATE_PER_CORE          # 1000 s on one core
    one, two = resources(steps, 0, threads=1), resources(steps, 0, threads=2)
    assert one["runtime"] == round(RUNTIME_SAFETY * 1000 / 60) and two["runtime"] < one["runtime"]
    assert resources(10 * steps, 0)["runtime"] > one["runtime"]
    assert resources(0, 10**7)["mem_mb"] > resources(0, 10**5)["mem_mb"] > MEM_BASE_MB
    # more cycles -> longer tiles; more tiles -> shorter tiles with fewer trajectories each
    cheap, dear = _plan(TILES), _plan(EXPENSIVE)
    s1, p1 = job_cost(cheap, tile_of="fig13")
    s2, p2 = job_cost(dear, tile_of="fig13")
    assert s2 > 1e5 * s1 and p2 == p1
    assert resources(s2, p2)["runtime"] > RUNTIME_FLOOR_MIN


def _dry_run_resources(text):
    """output path -> (rule, {resource: value}) of every job block of `snakemake -n` output."""
    jobs, rule, output = {}, None, None
    for line in text.splitlines():
        m = re.match(r"^(?:local)?rule (\w+):$", line)
        if m:
            rule, output = m.group(1), None
            continue
        m = re.match(r"^\s+output: (\S+?),?$", line) or re.match(r"^\s+output: (\S+?), ", line)
        if m and rule:
            output = m.group(1)
            continue
        m = re.match(r"^\s+resources: (.*)$", line)
        if m and rule and output:
            jobs[output] = (rule, dict(kv.split("=", 1) for kv in m.group(1).split(", ")))
    return jobs


def test_dry_run_hands_the_cost_resources_to_the_scheduler(sandbox):
    over = sandbox / "expensive.yaml"
    over.write_text(yaml.safe_dump(EXPENSIVE))
    r = run_snakemake(sandbox, "-n", "datasets", configfiles=("config/quick.yaml", over))
    assert r.returncode == 0, r.stderr[-3000:]
    jobs = _dry_run_resources(r.stdout + r.stderr)
    run = _plan(EXPENSIVE)
    seen, expensive_tiles = set(), 0
    for output, (rule, res) in jobs.items():
        if rule not in HEAVY_RULES:
            continue
        if rule == "chart_tile":
            job = {"tile_of": output.split("/")[4]}
        else:
            job = {"dataset": output}
        expected = resources(*job_cost(run, **job), run.threads)
        assert int(res["runtime"]) == expected["runtime"] and int(res["mem_mb"]) == expected["mem_mb"], output
        seen.add(rule)
        if output.startswith("results/data/numeric/parts/fig13/"):
            assert int(res["runtime"]) > RUNTIME_FLOOR_MIN
            expensive_tiles += 1
    assert seen == set(HEAVY_RULES) and expensive_tiles == 2


def test_well_step_cost_scales_the_estimate():
    """A well's steps count times its step cost (quartic 1, polynomial classes, arithmetic
    expressions, libm-calling codes whose lanes run scalar): measured per-step times (bench_wells)
    are below these bounds, and the cost estimate and the cluster runtimes follow them."""
    from safebasins import wells
    from safebasins.wells.base import (STEP_COST_ARITHMETIC, STEP_COST_ELEMENTARY, STEP_COST_POLY4,
                                       STEP_COST_POLY8, STEP_COST_TRANSCENDENTAL)

    assert wells.resolve_well(None).step_cost == 1.0
    assert wells.resolve_well("cubic").step_cost == STEP_COST_POLY4
    assert wells.resolve_well({"polynomial": [0, 0, 0.5, 0, -0.2, 0, 0.01]}).step_cost == STEP_COST_POLY8
    assert wells.resolve_well({"expression": "q**2/2 - q**3/3"}).step_cost == STEP_COST_ARITHMETIC
    for name in ("pendulum", "sech2", "morse"):
        assert wells.resolve_well(name).step_cost == STEP_COST_ELEMENTARY
    assert wells.resolve_well({"expression": "atan(q)**2 - q**4/4"}).step_cost == STEP_COST_TRANSCENDENTAL
    # (measured, SRKN6b 1 thread, AMD EPYC AVX-512: 1.29, 3.07, 1.19 and 42-130 quartic steps)
    assert STEP_COST_POLY4 >= 1.29 and STEP_COST_POLY8 >= 3.07 and STEP_COST_ARITHMETIC >= 1.19
    assert STEP_COST_TRANSCENDENTAL >= 130 and STEP_COST_ELEMENTARY >= 37.5
    run = plan(REPO_ROOT / "config" / "config.yaml")
    for name, factor in (("fig13", 1.0), ("cubic_basins_xi", STEP_COST_POLY4),
                         ("pendulum_basins", STEP_COST_ELEMENTARY), ("sech2_fcr", STEP_COST_ELEMENTARY)):
        exp = run.experiments[name]
        assert exp_cost(exp) == int(exp.kind.cost(exp.params) * factor), name
