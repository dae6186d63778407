# Shared set-up: the run's plan (safebasins.pipeline.plan: config validated before any job,
# naming the offending key; every experiment resolved through the registry of kinds) and the
# target lists and input functions every other rule file uses.
import json
import sys
from pathlib import Path

from safebasins.pipeline.cost import guard as _cost_guard
from safebasins.pipeline.cost import job_cost as _job_cost
from safebasins.pipeline.cost import resources as _job_resources
from safebasins.pipeline.plan import plan as _plan
from safebasins.pipeline.registry import STAGES

RUN = _plan(config)
# (cores: None for `--unlock`, `--report`, `-n` without --cores, where workflow.cores raises)
print(_cost_guard(RUN, workflow.resource_settings.cores or 1), file=sys.stderr)
PARAMS_JSON = {e: json.dumps(p, sort_keys=True) for e, p in RUN.params().items()}
NUM_THREADS = RUN.threads
BACKEND = config["numerics"]["backend"]
EXTENSIONS = config["extensions"]

PARAM_FILES = RUN.param_files()
DATASETS = RUN.datasets()
FIGURES = RUN.figures()


def alternatives(names):
    """Regex matching exactly the given names (never matches if empty)."""
    return "|".join(sorted(names)) if names else "(?!x)x"


def dataset_names(stage):
    return [p.rsplit("/", 1)[1].removesuffix(".nc") for p in RUN.datasets(stage)]


def dataset_path(stage, wildcards):
    return f"{STAGES[stage]}/{wildcards.name}.nc"


def dataset_inputs(stage):
    return lambda wildcards: RUN.product_inputs(dataset_path(stage, wildcards))


def dataset_threads(stage):
    return lambda wildcards: NUM_THREADS if RUN.product(dataset_path(stage, wildcards)).heavy else 1


def job_resources(stage=None):
    """`resources: **job_resources(stage)` of a heavy rule: runtime (minutes) and mem_mb of each
    job from the cost estimate (safebasins.pipeline.cost.job_cost / resources), for a cluster
    scheduler (workflow/profiles/slurm); a local run ignores them. stage None: chart tiles."""

    # (threads from the plan, not snakemake's `threads` argument: that would need --cores to
    # evaluate, and `--unlock` / `--report` run without it)
    def resource(key):
        def of_job(wildcards):
            if stage is None:
                job, threads = {"tile_of": wildcards.experiment}, NUM_THREADS
            else:
                job, threads = {"dataset": dataset_path(stage, wildcards)}, dataset_threads(stage)(wildcards)
            return _job_resources(*_job_cost(RUN, **job), threads)[key]

        return of_job

    return {"runtime": resource("runtime"), "mem_mb": resource("mem_mb")}


def figure_targets(category):
    return [p for f in FIGURES if f.category == category for p in (f.png, f.pdf)]


wildcard_constraints:
    experiment=alternatives(RUN.experiments),
    task=r"\d+",
    tile=r"\d+",
    tiles=r"\d+",


def param_file(wildcards):
    return f"results/params/{wildcards.experiment}.yaml"
