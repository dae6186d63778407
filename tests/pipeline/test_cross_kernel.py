"""Reproduction across machines (marker `pipeline`): the quick config's datasets computed as on
another x86-64 machine are a reproduction of the shared quick run (tests/pipeline/conftest.py)
within the stated tolerances (safebasins.io.reproduction): no dataset "differs" or is missing.

"Another machine" is what changes the last bits between CPUs: another OpenBLAS kernel than the
one this CPU selects (Haswell, or Sandybridge where Haswell is the native one) and numpy's own
SIMD loops without their AVX-512 paths (``exp``, ``arccos``, ... differ from the AVX2 ones; a
no-op on a CPU without AVX-512).  Both are read back in a child process, so a setting the
libraries ignored fails here.  The datasets are built by the rules' own code in two worker
processes (tests/pipeline/rebuild.py), not one process per dataset job."""
from __future__ import annotations

import json
import subprocess
import sys
import time

import pytest

from safebasins.io.reproduction import DIFFERS, IDENTICAL, MISSING, WITHIN, verify_reproduction
from safebasins.pipeline.plan import plan
from tests.pipeline.sandbox import ROOT, make_sandbox, run_snakemake, snakemake_env

pytestmark = pytest.mark.pipeline

#: the quick run's configuration (the Snakefile's config, then --configfile)
CONFIGS = ["config/config.yaml", "config/quick.yaml"]

#: numpy's dispatched AVX-512 targets (numpy 2.x names); the baseline stays
NO_AVX512 = "X86_V4 AVX512_ICL AVX512_SPR"

# numpy's OpenBLAS core name (its own openblas_get_corename) and numpy's SIMD targets in use
PROBE = """
import ctypes, json, numpy
core = ""
paths = sorted({l.split()[-1] for l in open("/proc/self/maps") if "openblas" in l and ".so" in l})
for path in paths:
    lib = ctypes.CDLL(path)
    for sym in ("scipy_openblas_get_corename64_", "scipy_openblas_get_corename", "openblas_get_corename64_",
                "openblas_get_corename"):
        if hasattr(lib, sym) and not core:
            f = getattr(lib, sym)
            f.restype = ctypes.c_char_p
            core = f().decode()
print(json.dumps({"core": core, "simd": numpy.__config__.CONFIG["SIMD Extensions"]["found"]}))
"""


def probe(env) -> dict:
    r = subprocess.run([sys.executable, "-W", "error", "-c", PROBE], env=env, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def test_another_machine_reproduces_the_quick_run(quick, tmp_path):
    native = probe(snakemake_env())
    if not native["core"]:
        pytest.skip("numpy is not linked against OpenBLAS: no kernel to switch")
    other = "Sandybridge" if native["core"].lower() == "haswell" else "Haswell"
    env = snakemake_env(OPENBLAS_CORETYPE=other, NPY_DISABLE_CPU_FEATURES=NO_AVX512)
    emulated = probe(env)
    assert emulated["core"].lower() == other.lower(), f"OPENBLAS_CORETYPE={other} was not honoured: {emulated}"
    assert not set(emulated["simd"]) & set(NO_AVX512.split()), emulated
    ref, r = quick
    if r.returncode != 0:
        pytest.skip("quick run failed")
    wd = make_sandbox(tmp_path / other)
    t0 = time.perf_counter()
    # the parameter files by their rule; the datasets by the rules' own builds in two long-lived
    # workers (tests/pipeline/rebuild.py: one library import per worker, not one per dataset job)
    params = run_snakemake(wd, "-j2", *plan([ROOT / c for c in CONFIGS]).param_files(), env=env)
    assert params.returncode == 0, params.stderr[-4000:]
    run = subprocess.run([sys.executable, "-m", "tests.pipeline.rebuild", str(wd), "2", *CONFIGS], env=env,
                         cwd=ROOT, capture_output=True, text=True, timeout=3600)
    print(f"\nquick datasets under OPENBLAS_CORETYPE={other}, numpy SIMD {emulated['simd']} (native {native}): "
          f"{time.perf_counter() - t0:.1f} s")
    assert run.returncode == 0, run.stderr[-4000:]
    assert set(json.loads(run.stdout.splitlines()[-1])) == set(plan([ROOT / c for c in CONFIGS]).datasets())
    report = verify_reproduction(ref / "results", wd / "results")
    lines = list(report.lines())
    print("\n".join(line for line in lines if not line.startswith("identical")))
    counts = {s: report.count(s) for s in (IDENTICAL, WITHIN, DIFFERS, MISSING)}
    assert report.reproduced, "\n".join(lines)
    assert counts[IDENTICAL] + counts[WITHIN] == len(report.verdicts) > 0, counts
