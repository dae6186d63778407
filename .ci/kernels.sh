#!/usr/bin/env bash
# The tests of the wells, theory, numerics and analysis under another OpenBLAS kernel than the one
# this CPU selects, with numpy's SIMD loops limited to AVX2 (make test runs the native kernel and
# numpy's full SIMD): the last bits of LAPACK/BLAS and of numpy's vectorised exp, log, ... differ
# between machines, and no test may depend on them.  OPENBLAS_CORETYPE forces a kernel; before
# each run the kernel actually loaded by numpy's and scipy's OpenBLAS is read back, so a variable
# that the library ignored (a build without DYNAMIC_ARCH, a CPU without the kernel's instructions)
# fails here instead of passing silently.  KERNELS="Sandybridge" by default (the AVX kernel):
# make test's tests/pipeline/test_cross_kernel.py already runs every dataset of the quick
# configuration under Haswell (the AVX2 kernel); KERNELS="Haswell Sandybridge" runs both here.
# The test paths are those below unless KERNEL_TEST_PATHS names others (space-separated).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=.venv/bin/python
KERNELS=${KERNELS:-"Sandybridge"}
# numpy 2.x names of its AVX-512 dispatch targets (a no-op on a CPU without AVX-512)
NO_AVX512="X86_V4 AVX512_ICL AVX512_SPR"
read -r -a DIRS <<< "${KERNEL_TEST_PATHS:-tests/wells tests/theory tests/numerics tests/analysis}"
# Left out here (run by make test under the native kernel): the slowest tests that compare two
# code paths on the same inputs in one process (the CUDA simulator against the CPU engine, for the
# polynomial and the named wells; a numeric well against its expression twin) or the compiled
# engine against scipy's DOP853 on the quartic, whose arithmetic calls no BLAS/LAPACK: a kernel
# changes neither side of them.
DESELECT=(
    tests/numerics/test_cuda_simulator.py::test_cuda_simulator_matches_cpu_engine_bitwise
    tests/numerics/test_cuda_simulator_wells.py::test_named_wells_cuda_simulator_matches_cpu_bitwise
    tests/numerics/test_damping.py::test_damped_chart_matches_dop853_pixel_for_pixel
    tests/numerics/test_other_wells.py::test_numeric_well_equals_expression_bitwise
    tests/theory/test_damped.py::test_batch_decisions_match_per_ic_reference
)

# the core name of every OpenBLAS loaded by numpy and scipy.linalg (threadpoolctl when installed,
# else the library's own openblas_get_corename through ctypes), one per line
read -r -d '' CORES <<'EOF' || true
import ctypes, numpy, scipy.linalg
try:
    import threadpoolctl
    for info in threadpoolctl.threadpool_info():
        if info["internal_api"] == "openblas":
            print(info["filepath"], info["architecture"])
    raise SystemExit
except ImportError:
    pass
paths = sorted({line.split()[-1] for line in open("/proc/self/maps") if "openblas" in line and ".so" in line})
for path in paths:
    lib = ctypes.CDLL(path)
    for sym in ("scipy_openblas_get_corename64_", "scipy_openblas_get_corename", "openblas_get_corename64_",
                "openblas_get_corename"):
        if hasattr(lib, sym):
            f = getattr(lib, sym)
            f.restype = ctypes.c_char_p
            print(path, f().decode())
            break
    else:
        print(path, "?")
EOF

status=0
for kernel in $KERNELS; do
    cores=$(OPENBLAS_CORETYPE=$kernel "$PY" -c "$CORES")
    echo "OPENBLAS_CORETYPE=$kernel:"
    echo "$cores" | sed 's/^/  /'
    if [ -z "$cores" ] || echo "$cores" | awk -v k="$kernel" 'tolower($2) != tolower(k) {bad = 1} END {exit !bad}'; then
        echo "kernels.sh: OPENBLAS_CORETYPE=$kernel was not honoured (loaded kernels above)" >&2
        exit 1
    fi
    start=$(date +%s)
    rc=0
    OPENBLAS_CORETYPE=$kernel NPY_DISABLE_CPU_FEATURES="$NO_AVX512" "$PY" -m pytest -p no:cacheprovider -q -n 2 --dist loadfile --durations=5 "${DESELECT[@]/#/--deselect=}" "${DIRS[@]}" || rc=$?
    echo "kernels.sh: OPENBLAS_CORETYPE=$kernel: exit $rc, wall $(( $(date +%s) - start )) s"
    [ "$rc" -eq 0 ] || status=1
done
exit $status
