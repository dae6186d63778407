"""The quick run every pipeline test module shares: one ``snakemake -j2 --keep-going all`` on the
quick config per test session, in the session's shared temporary directory (also under
pytest-xdist: ``make test`` runs -n N --dist loadfile).  Whoever asks first runs it under a file
lock and records it; the others wait for the lock and reuse the record.

tests/conftest.py starts it in the background (``python -m tests.pipeline.quick_run DIR``) as soon
as a collected test needs it, so that the workers go on with other tests meanwhile instead of one
of them idling on the lock; the ``quick`` fixture (tests/pipeline/conftest.py) then only waits.
"""
from __future__ import annotations

import fcntl
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from tests.pipeline.sandbox import ROOT, make_sandbox, run_snakemake

__all__ = ["FIXTURE", "shared_dir", "build", "start_in_background", "stop_background"]

#: the fixture's name (a collected test that uses it starts the run)
FIXTURE = "quick"
_PID = "quick.pid"


def shared_dir(basetemp: Path) -> Path:
    """The directory the session's processes share: an xdist worker's basetemp is a child of the
    controller's."""
    return basetemp.parent if os.environ.get("PYTEST_XDIST_WORKER") else basetemp


def build(shared: Path) -> subprocess.CompletedProcess[str]:
    """The quick run's CompletedProcess: run once (under the lock) and recorded in ``shared``."""
    wd, record = shared / "quick", shared / "quick.json"
    with open(shared / "quick.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)         # released when the file closes
        if not record.exists():
            make_sandbox(wd)
            t0 = time.perf_counter()
            # the timeout only stops a hung run: 13 min here, slower CI machines take longer
            r = run_snakemake(wd, "-j2", "--keep-going", "all", timeout=3600)
            print(f"\nquick run (all, -j2): {time.perf_counter() - t0:.1f} s")
            tmp = record.with_suffix(".tmp")
            tmp.write_text(json.dumps({"args": r.args, "returncode": r.returncode, "stdout": r.stdout,
                                       "stderr": r.stderr}))
            tmp.replace(record)
        rec = json.loads(record.read_text())
    return subprocess.CompletedProcess(rec["args"], rec["returncode"], rec["stdout"], rec["stderr"])


def start_in_background(shared: Path) -> None:
    """Starts :func:`build` in a process of its own session (its pid in ``shared``), unless the
    record is already there."""
    if (shared / "quick.json").exists():
        return
    proc = subprocess.Popen([sys.executable, "-m", "tests.pipeline.quick_run", str(shared)], cwd=ROOT,
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    (shared / f"{_PID}.{proc.pid}").write_text(str(proc.pid))


def stop_background(shared: Path) -> None:
    """Ends the background runs still going (a session stopped before the tests that needed it)."""
    done = (shared / "quick.json").exists()
    for f in shared.glob(f"{_PID}.*"):
        if not done:
            try:
                os.killpg(int(f.read_text()), signal.SIGTERM)
            except (ProcessLookupError, PermissionError, ValueError):
                pass
        f.unlink(missing_ok=True)


if __name__ == "__main__":
    try:
        build(Path(sys.argv[1]))
    finally:
        (Path(sys.argv[1]) / f"{_PID}.{os.getpid()}").unlink(missing_ok=True)
