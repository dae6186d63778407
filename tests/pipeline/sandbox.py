"""A sandbox view of the repository for workflow tests (symlinks, so the checkout's results/
stays untouched) and a Snakemake runner."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(sys.executable).parent
SANDBOX_ITEMS = ("Snakefile", "config", "workflow", "scripts", "src", "notebooks", "environment.lock",
                 "CITATION.cff")


def make_sandbox(path: Path) -> Path:
    path.mkdir(parents=True, exist_ok=True)
    for name in SANDBOX_ITEMS:
        if not (path / name).exists():
            (path / name).symlink_to(ROOT / name)
    return path


def snakemake_cmd(wd: Path, *args, configfiles=("config/quick.yaml",)) -> list[str]:
    # targets/options first: --configfile takes every following word
    cmd = [str(BIN / "snakemake"), "-d", str(wd), "-s", str(wd / "Snakefile"), *map(str, args)]
    if configfiles:
        cmd += ["--configfile", *map(str, configfiles)]
    return cmd


def snakemake_env(**extra):
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    env.update(extra)
    return env


def run_snakemake(wd: Path, *args, configfiles=("config/quick.yaml",), timeout=1200, env=None):
    return subprocess.run(snakemake_cmd(wd, *args, configfiles=configfiles), capture_output=True, text=True,
                          timeout=timeout, env=env or snakemake_env(), cwd=wd)
