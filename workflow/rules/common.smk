# Shared set-up: configuration validation, resolution into per-experiment parameters,
# target lists and input functions used by every other rule file.
import json
from pathlib import Path

from snakemake.utils import validate

from safebasins import config as sbconfig


# ---------------------------------------------------------------- validation (before any job)
# safebasins.config.validate_config gives one message naming the offending key (and adds the
# checks JSON Schema cannot express); snakemake.utils.validate then fills the schema defaults.
sbconfig.validate_config(config, Path(workflow.basedir) / "workflow" / "schemas" / "config.schema.yaml")
validate(config, "../schemas/config.schema.yaml")

# ---------------------------------------------------------------- resolution
EXP = sbconfig.resolve(config)  # experiment -> resolved parameters (results/params/{e}.yaml)
PARAMS_JSON = {e: json.dumps(p, sort_keys=True) for e, p in EXP.items()}
NUM_THREADS = int(config["numerics"]["threads"])
TILES = int(config["numerics"]["tiles"])


def experiments(*kinds):
    return [e for e, p in EXP.items() if p["kind"] in kinds]


def alternatives(names):
    """Regex matching exactly the given experiment names (never matches if empty)."""
    return "|".join(names) if names else "(?!x)x"


FCR_EXPERIMENTS = experiments("fcr_theory", "fcr_compare")
FCR_NUMERIC_EXPERIMENTS = experiments("fcr_compare")
BASIN_EXPERIMENTS = experiments("basin_rm", "basin_chart", "strobe")
AGREEMENT_EXPERIMENTS = experiments("basin_chart")
FINAL_CHART_EXPERIMENTS = experiments("chart")
# (the extras erosion / true_basin reuse the chart tiles: one task per F / per Psi)
CHART_EXPERIMENTS = experiments("basin_chart", "chart", "criteria", "erosion", "true_basin")
STROBE_EXPERIMENTS = experiments("strobe")
CRITERIA_EXPERIMENTS = experiments("criteria")

PARAM_FILES = [f"results/params/{e}.yaml" for e in EXP]
DATASETS = [f for e, p in EXP.items() for f in sbconfig.dataset_files(e, p["kind"], params=p)]
ANALYTIC_DATASETS = [f for f in DATASETS if "/analytic/" in f]
NUMERIC_DATASETS = [f for f in DATASETS if "/numeric/" in f]


wildcard_constraints:
    experiment=r"fig\d\d|extra_[a-z_]+",
    task=r"\d+",
    tile=r"\d+",
    tiles=r"\d+",


def param_file(wildcards):
    return f"results/params/{wildcards.experiment}.yaml"


def tile_files(experiment):
    """Tile files of every task of a chart experiment (tasks x TILES jobs)."""
    tasks = EXP[experiment]["tasks"]
    return [
        f"results/data/numeric/parts/{experiment}/task{k}_tile{t}of{TILES}.nc"
        for k in range(len(tasks))
        for t in range(TILES)
    ]


def chart_tiles(wildcards):
    return tile_files(wildcards.experiment)
