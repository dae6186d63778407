"""The quick run every pipeline test module shares: one ``snakemake -j2 --keep-going all`` on the
quick config per test session, also under pytest-xdist (``make test``: -n N --dist loadfile), where
the first worker that asks runs it in the session's shared temporary directory and the others wait
for it (a file lock) and reuse it."""
from __future__ import annotations

import fcntl
import json
import os
import subprocess
import time

import pytest

from tests.pipeline.sandbox import make_sandbox, run_snakemake


@pytest.fixture(scope="session")
def quick(tmp_path_factory):
    """(sandbox, CompletedProcess) of ``snakemake -j2 --keep-going all`` on the quick config."""
    base = tmp_path_factory.getbasetemp()
    shared = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base
    wd, record = shared / "quick", shared / "quick.json"
    with open(shared / "quick.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)         # released when the file closes
        if not record.exists():
            make_sandbox(wd)
            t0 = time.perf_counter()
            # the timeout only stops a hung run: 13 min here, slower CI machines take longer
            r = run_snakemake(wd, "-j2", "--keep-going", "all", timeout=3600)
            print(f"\nquick run (all, -j2): {time.perf_counter() - t0:.1f} s")
            record.write_text(json.dumps({"args": r.args, "returncode": r.returncode, "stdout": r.stdout,
                                          "stderr": r.stderr}))
        rec = json.loads(record.read_text())
    return wd, subprocess.CompletedProcess(rec["args"], rec["returncode"], rec["stdout"], rec["stderr"])
