"""The kinds are declarations: loading the registry (what every Snakemake start and every SLURM
job does when it parses the Snakefile) loads no analysis, engine or theory code; a kind imports
what it computes with when its job runs."""
from __future__ import annotations

import json
import subprocess
import sys

HEAVY = ("safebasins.analysis", "safebasins.numerics", "safebasins.theory", "safebasins.plotting",
         "scipy.stats", "scipy.integrate", "matplotlib")

PROBE = f"""
import json, sys
from safebasins.pipeline.config import load_kinds
from safebasins.pipeline.registry import KINDS
load_kinds([])
print(json.dumps([len(KINDS), [m for m in {HEAVY!r} if m in sys.modules]]))
"""


def test_loading_the_kinds_loads_no_computation() -> None:
    r = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    n_kinds, loaded = json.loads(r.stdout.strip().splitlines()[-1])
    assert n_kinds > 10, n_kinds          # the registry really was loaded
    assert loaded == [], loaded
