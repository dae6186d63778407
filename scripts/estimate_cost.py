"""Upper-bound cost of every numeric experiment in trajectory-steps (no early escape assumed).

    .venv/bin/python scripts/estimate_cost.py [config/config.yaml] [config/quick.yaml ...]

Later files are merged into the first (as `snakemake --configfile`); each kind's cost comes
from the registry (safebasins.pipeline.cost).
"""
import sys

from safebasins.pipeline.config import REPO_ROOT
from safebasins.pipeline.cost import report
from safebasins.pipeline.plan import plan

if __name__ == "__main__":
    for line in report(plan(sys.argv[1:] or [str(REPO_ROOT / "config" / "config.yaml")]), cores=2):
        print(line)
