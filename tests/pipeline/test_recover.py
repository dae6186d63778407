"""After a killed run, one command recovers (`make recover`, README "After a killed run"): a run
SIGKILLed mid-job leaves Snakemake's lock and incomplete-file markers; the next run stops
(LockException, or IncompleteFilesException), `--rerun-incomplete` alone still hits the lock and
`make reproduce` says to run `make recover`, which releases the lock, redoes the interrupted jobs
and finishes. A small target of the quick configuration in a sandbox (marker `pipeline`)."""
from __future__ import annotations

import os
import signal
import subprocess
import time

import pytest

from tests.pipeline.sandbox import BIN, ROOT, make_sandbox, run_snakemake, snakemake_cmd, snakemake_env

pytestmark = pytest.mark.pipeline

TARGET = "results/data/numeric/chart_fig13.nc"
QUICK = "--configfile config/quick.yaml"


def _make(wd, goal):
    """`make GOAL` in the sandbox with the checkout's venv; building TARGET of the quick config,
    no report (the other targets of the quick run are not built here)."""
    stamp = wd / ".installed"
    stamp.touch()                            # newer than environment.lock / pyproject.toml: no install
    args = ["make", "-C", str(wd), goal, f"BIN={BIN}", f"STAMP={stamp}", f"TARGETS={TARGET}",
            f"SNAKEMAKE_ARGS={QUICK}", "REPORT=", "JOBS=2"]
    return subprocess.run(args, capture_output=True, text=True, timeout=600, env=snakemake_env())


def _killed_run(wd):
    """Start the run and SIGKILL it (Snakemake and its jobs) once a job has started."""
    proc = subprocess.Popen(snakemake_cmd(wd, "-j2", TARGET), cwd=wd, env=snakemake_env(),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    marks = wd / ".snakemake" / "incomplete"
    deadline = time.time() + 300
    while time.time() < deadline and proc.poll() is None and not (marks.is_dir() and any(marks.iterdir())):
        time.sleep(0.02)
    running = proc.poll() is None
    if running:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=60)
    assert running, "the run finished before it could be killed"


def test_make_recover_after_a_killed_run(tmp_path):
    wd = make_sandbox(tmp_path / "wd")
    for name in ("Makefile", "pyproject.toml"):
        (wd / name).symlink_to(ROOT / name)
    _killed_run(wd)
    assert any((wd / ".snakemake" / "locks").iterdir()) and any((wd / ".snakemake" / "incomplete").iterdir())
    assert not (wd / TARGET).exists()

    # what a user meets: the plain rerun and --rerun-incomplete both stop
    plain = run_snakemake(wd, "-j2", TARGET)
    assert plain.returncode != 0 and ("LockException" in plain.stderr or "IncompleteFilesException" in plain.stderr)
    rerun = run_snakemake(wd, "-j2", "--rerun-incomplete", TARGET)
    assert rerun.returncode != 0 and "LockException" in rerun.stderr, rerun.stderr[-2000:]
    repro = _make(wd, "reproduce")
    assert repro.returncode != 0 and "Run:  make recover" in repro.stdout, repro.stdout + repro.stderr[-2000:]

    # the one command
    rec = _make(wd, "recover")
    assert rec.returncode == 0, rec.stdout[-2000:] + rec.stderr[-4000:]
    assert (wd / TARGET).is_file()
    assert not any((wd / ".snakemake" / "locks").glob("*")) and not any((wd / ".snakemake" / "incomplete").glob("*"))
    assert not list((wd / "results").rglob(".*.tmp"))
    again = run_snakemake(wd, "-j2", TARGET)
    assert again.returncode == 0 and "Nothing to be done" in again.stdout + again.stderr
