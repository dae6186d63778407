# Shared set-up: the run's plan (safebasins.pipeline.plan: config validated before any job,
# naming the offending key; every experiment resolved through the registry of kinds) and the
# target lists and input functions every other rule file uses.
import json
import sys
from pathlib import Path

from safebasins.pipeline.cost import guard as _cost_guard
from safebasins.pipeline.cost import job_cost as _job_cost
from safebasins.pipeline.cost import resources as _job_resources
from safebasins.pipeline.config import load_yaml as _load_yaml
from safebasins.pipeline.plan import plan as _plan
from safebasins.pipeline.registry import STAGES

# the --configfile files re-read strictly: a key given twice is an error naming file, key and line
# (snakemake's own loader keeps the later value silently; the Snakefile checks config/config.yaml)
_OVERLAY_EXPERIMENTS = set()
for _f in workflow.overwrite_configfiles or ():
    _c = _load_yaml(_f)
    if isinstance(_c, dict) and isinstance(_c.get("experiments"), dict):
        _OVERLAY_EXPERIMENTS |= set(_c["experiments"])
RUN = _plan(config)
# what `snakemake experiments` builds: the experiments your --configfile files name under
# `experiments:` (declared or overridden there), else every one of the merged config (README)
TARGET_EXPERIMENTS = [e for e in RUN.experiments.values() if e.key.startswith("experiments.")
                      and (not _OVERLAY_EXPERIMENTS or e.name in _OVERLAY_EXPERIMENTS)]
PARAMS_JSON = {e: json.dumps(p, sort_keys=True) for e, p in RUN.params().items()}
NUM_THREADS = RUN.threads
BACKEND = config["numerics"]["backend"]
EXTENSIONS = config["extensions"]

PARAM_FILES = RUN.param_files()
DATASETS = RUN.datasets()
FIGURES = RUN.figures()


def requested_targets():
    """The targets of the snakemake command line (the workflow is parsed before snakemake passes
    them on: read from sys.argv with snakemake's own parser); [] when there are none or they
    cannot be read (then the default rule counts)."""
    from snakemake.cli import get_argument_parser

    try:
        args, _ = get_argument_parser().parse_known_args(sys.argv[1:])
    except (SystemExit, Exception):
        return []
    return list(args.targets or [])


def cost_guard():
    """Print the cost estimate of what the requested targets build and refuse it above the budgets
    (safebasins.pipeline.cost.guard), before any job runs. Called at the end of the Snakefile, once
    the target rules are defined; a rule target counts as its inputs, no target as the default
    rule. Jobs that an executor spawns (a cluster) do not repeat it."""
    if not workflow.is_main_process:
        return
    files = []
    for t in requested_targets() or [workflow.default_target]:
        if t in workflow._rules:
            files += [f for f in getattr(rules, t).input if isinstance(f, str)]
        else:
            files.append(t)
    exps = RUN.experiments_for(files)
    # (cores: None for `--unlock`, `--report`, `-n` without --cores, where workflow.cores raises)
    print(_cost_guard(RUN, workflow.resource_settings.cores or 1, experiments=exps), file=sys.stderr)


def alternatives(names):
    """Regex matching exactly the given names (never matches if empty)."""
    return "|".join(sorted(names)) if names else "(?!x)x"


def dataset_names(stage):
    return [p.rsplit("/", 1)[1].removesuffix(".nc") for p in RUN.datasets(stage)]


def dataset_path(stage, wildcards):
    return f"{STAGES[stage]}/{wildcards.name}.nc"


def dataset_inputs(stage):
    return lambda wildcards: RUN.product_inputs(dataset_path(stage, wildcards))


def dataset_integrates_tasks(stage):
    """The dataset integrates its experiment's chart tasks itself (numerics.tiles = 0; Plan.integrates_tasks)."""
    return lambda wildcards: RUN.integrates_tasks(dataset_path(stage, wildcards))


def dataset_threads(stage):
    return lambda wildcards: NUM_THREADS if RUN.integrates(dataset_path(stage, wildcards)) else 1


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
