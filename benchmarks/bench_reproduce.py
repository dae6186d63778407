"""The whole reproduction: ``snakemake -j2`` from nothing with the default job layout
(``numerics.tiles: 0``: each chart experiment integrates its tasks in the job of the dataset that
reads them) against the per-task layout it replaced (``numerics.tiles: 1``: one ``chart_tile`` job
per chart task), run one after the other in fresh sandboxes by this script.

    .venv/bin/python benchmarks/bench_reproduce.py             # quick config, target all (~4 min)
    .venv/bin/python benchmarks/bench_reproduce.py --full      # paper resolution (~11 min on 2 cores)
    .venv/bin/python benchmarks/bench_reproduce.py --target datasets

Prints per layout the wall time, the number of jobs and the job time per rule group (from
Snakemake's own start/end records in .snakemake/metadata; slot-seconds, at -j2 two slots), checks
that both layouts wrote the same datasets value by value (scripts/compare_results.py), and prints a
``BENCH`` line with the ratio of the wall times.
"""
from __future__ import annotations

import argparse
import collections
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from _report import machine, report  # noqa: E402

SOURCES = ("Snakefile", "config", "workflow", "scripts", "src", "notebooks", "environment.lock", "CITATION.cff")
DATASET_RULES = ("analytic_dataset", "numeric_dataset", "extras_dataset")


def sandbox(path):
    os.makedirs(path)
    for name in SOURCES:
        os.symlink(os.path.join(ROOT, name), os.path.join(path, name))
    return path


def job_times(wd):
    """{rule group: [seconds per job]} from .snakemake/metadata (one record per output file; a job
    is its rule and job hash, from its first start to its last end)."""
    md = os.path.join(wd, ".snakemake", "metadata")
    jobs = {}
    for name in os.listdir(md):
        with open(os.path.join(md, name)) as fh:
            m = json.load(fh)
        key = (m["rule"], m.get("job_hash"))
        s, e = jobs.get(key, (m["starttime"], m["endtime"]))
        jobs[key] = (min(s, m["starttime"]), max(e, m["endtime"]))
    groups = collections.defaultdict(list)
    for (rule, _), (s, e) in jobs.items():
        group = rule if rule in DATASET_RULES + ("chart_tile", "parameters", "archive") else "figures"
        groups[group].append(e - s)
    return groups


def run_layout(wd, tiles, config, target, jobs):
    over = os.path.join(wd, "layout.yaml")
    with open(over, "w") as fh:
        fh.write(f"numerics:\n  tiles: {tiles}\n")
    cmd = [os.path.join(os.path.dirname(sys.executable), "snakemake"), f"-j{jobs}", "-d", wd,
           "-s", os.path.join(wd, "Snakefile"), target, "--configfile", *config, over]
    env = dict(os.environ, PATH=os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", ""))
    t0 = time.perf_counter()
    r = subprocess.run(cmd, cwd=wd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode:
        sys.stderr.write(r.stderr[-4000:])
        raise SystemExit(f"snakemake (tiles {tiles}) failed with exit {r.returncode}")
    return wall, job_times(wd)


def describe(label, wall, groups):
    n = sum(len(v) for v in groups.values())
    slot = sum(sum(v) for v in groups.values())
    print(f"{label}: {wall:.1f} s wall, {n} jobs, {slot:.0f} slot-s of job time")
    for g, v in sorted(groups.items(), key=lambda kv: -sum(kv[1])):
        v = sorted(v)
        print(f"    {g:18s} {len(v):4d} jobs {sum(v):7.1f} s (median {v[len(v) // 2]:.2f} s, max {v[-1]:.1f} s)")
    return n, slot


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--full", action="store_true", help="paper resolution (config/config.yaml alone)")
    ap.add_argument("--target", default="all", help="snakemake target (default: all = make reproduce's)")
    ap.add_argument("--jobs", type=int, default=2, help="snakemake -j (default 2)")
    args = ap.parse_args()
    config = [] if args.full else ["config/quick.yaml"]
    res = {}
    with tempfile.TemporaryDirectory(prefix="bench_reproduce_") as tmp:
        for label, tiles in (("per-task jobs (tiles 1)", 1), ("default (tiles 0)", 0)):
            wd = sandbox(os.path.join(tmp, f"tiles{tiles}"))
            print(f"running {label} ...", flush=True)
            wall, groups = run_layout(wd, tiles, config, args.target, args.jobs)
            res[tiles] = (wall,) + describe(label, wall, groups)
        cmp = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "compare_results.py"),
                              os.path.join(tmp, "tiles1", "results", "data"),
                              os.path.join(tmp, "tiles0", "results", "data"), "--quiet"],
                             capture_output=True, text=True)
        print(cmp.stdout.strip().splitlines()[-1] if cmp.stdout.strip() else cmp.stderr[-2000:])
        if cmp.returncode:
            raise SystemExit("the two layouts wrote different datasets")
    (w1, n1, s1), (w0, n0, s0) = res[1], res[0]
    report(f"make reproduce ({'paper' if args.full else 'quick'} config, -j{args.jobs} {args.target})",
           round(w1 / w0, 2), "wall time per-task chart jobs (tiles 1) / default layout (tiles 0), same datasets",
           f"{w1:.0f} s -> {w0:.0f} s wall; {n1} -> {n0} jobs; {s1:.0f} -> {s0:.0f} slot-s of job time")
    print(f"machine: {machine()}")


if __name__ == "__main__":
    main()
