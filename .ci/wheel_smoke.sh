#!/usr/bin/env bash
# Wheel smoke test: the package as a user installs it, away from this checkout.
#
#   .ci/wheel_smoke.sh            (needs the checkout's .venv, made by `make test`, to build)
#
# Builds the sdist and, from it, the wheel (python -m build --no-isolation: the lock's setuptools),
# installs the wheel into a fresh venv in a temp directory with only what its metadata declares
# (those pins and hashes of environment.lock: .ci/lock_subset.py; then `pip check`), and from an
# empty temp directory runs every command: chart (quartic, pendulum, the pendulum written as an
# expression well: the same escapes), fcr, basin, info, check-config on a good and a bad file,
# explore (needs the [explore] extra: first refused naming it, then, with it, started, its page
# fetched, stopped by SIGINT with exit status 130), the CUDA engine (the [cuda] extra, under numba's simulator: escapes equal to the CPU's),
# and, where a read-only bind mount is possible (root), a chart from a read-only install without
# a writable home.  Fails on any error, any warning or traceback text in a command's output, and
# any file a command leaves in the working directory besides its outputs.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD_PY="$ROOT/.venv/bin/python"
PY=${PYTHON:-python3}
[ -x "$BUILD_PY" ] || { echo "wheel_smoke: no $BUILD_PY: run make test (or make .venv/.installed) first" >&2; exit 1; }
START=$SECONDS
T=$(mktemp -d "${TMPDIR:-/tmp}/safebasins-wheel.XXXXXX")
EXPLORE_PID=
cleanup() {
  [ -n "$EXPLORE_PID" ] && kill "$EXPLORE_PID" 2>/dev/null
  [ -n "${RO_PID:-}" ] && wait "$RO_PID" 2>/dev/null
  rm -rf "$T"
}
trap cleanup EXIT
# each line: wall time, and the CPU time (user, system) of the commands so far
log() { times > "$T/cpu"; echo "wheel_smoke [$((SECONDS - START)) s; CPU $(tail -1 "$T/cpu")]: $*"; }
fail() { echo "wheel_smoke: FAILED: $*" >&2; exit 1; }

# ------------------------------------------------------------------ build, install
log "python -m build --no-isolation (sdist, then the wheel from it)"
"$BUILD_PY" -m build --no-isolation --outdir "$T/dist" "$ROOT" > "$T/build.log" 2>&1 || { cat "$T/build.log"; fail "build"; }
WHEEL=$(ls "$T"/dist/*.whl)
"$BUILD_PY" -c "import sys, zipfile; sys.exit('safebasins/pipeline/schemas/config.schema.yaml' not in zipfile.ZipFile(sys.argv[1]).namelist())" \
  "$WHEEL" || fail "the wheel lacks the config schema"

log "fresh venv: the wheel's declared dependencies from environment.lock (no extras), pip check"
"$PY" -m venv --without-pip "$T/venv"
V="$T/venv/bin"
# the checkout's pip works on the new venv (pip --python); its output only when it fails; no
# byte-compiling of every installed module (each command's imports write their own .pyc once,
# PYTHONDONTWRITEBYTECODE unset below): 30 s less
pip_in_venv() {
  "$BUILD_PY" -m pip --python "$V/python" --disable-pip-version-check "$@" > "$T/pip.log" 2>&1 || {
    cat "$T/pip.log"; fail "pip $*"; }
}
"$BUILD_PY" "$ROOT/.ci/lock_subset.py" "$WHEEL" < "$ROOT/environment.lock" > "$T/core.lock"
pip_in_venv install -q --no-compile --require-hashes --no-deps -r "$T/core.lock"
pip_in_venv install -q --no-compile --no-deps "$WHEEL"
pip_in_venv check

# ------------------------------------------------------------------ the commands, from an empty directory
W="$T/work"
mkdir "$W" "$T/in"
cd "$W"
export PATH="$V:$PATH" MPLBACKEND=Agg
unset NUMBA_ENABLE_CUDASIM NUMBA_CACHE_DIR PYTHONDONTWRITEBYTECODE

# checked EXPECTED RC OUTPUT_FILE WHAT: the exit status as expected, no warning or traceback text
checked() {
  if [ "$2" != "$1" ]; then cat "$3"; fail "exit status $2 (expected $1): $4"; fi
  if grep -qiE "warning|traceback|deprecat" "$3"; then cat "$3"; fail "warning text in the output of: $4"; fi
}
# run EXPECTED_STATUS CMD...: run, then checked (the output kept for expect)
run() {
  local want=$1 rc=0; shift
  "$@" > "$T/out" 2>&1 || rc=$?
  checked "$want" "$rc" "$T/out" "$*"
}
expect() { grep -qF -- "$1" "$T/out" || { cat "$T/out"; fail "no '$1' in the output of the last command"; }; }
# only_outputs DIR NAME...: DIR holds exactly these files (nothing else written to it)
only_outputs() {
  local dir=$1 have want; shift
  have=$(ls -A "$dir" | sort | tr '\n' ' ')
  want=$(printf '%s\n' "$@" | sort | tr '\n' ' ')
  [ "$have" = "$want" ] || fail "$dir holds [$have], expected [$want]"
}
OUTPUTS=(quartic.nc quartic.png pendulum.nc pendulum.png expression.nc expression.png fcr.nc fcr_numeric.nc fcr.png
         basin.nc basin.png)

# a read-only install without a writable home (root: a read-only bind mount in a mount namespace of
# its own), in the background beside the other commands: a chart, numba's kernels cached in a
# private temp directory (numba alone refuses to define them and the import fails)
RO_PID=
if [ "$(id -u)" = 0 ] && unshare -m true 2>/dev/null; then
  log "read-only install, no writable home: a chart (in the background)"
  SP=$("$V/python" -c "import pathlib, safebasins; print(pathlib.Path(safebasins.__file__).parent)")
  mkdir "$T/ro" "$T/rohome" "$T/rotmp"
  ( cd "$T/ro" && rc=0 && unshare -m sh -c 'mount --bind "$1" "$1" && mount -o remount,ro,bind "$1" "$1" &&
      mount --bind "$2" "$2" && mount -o remount,ro,bind "$2" "$2" && shift 2 && exec "$@"' sh "$SP" "$T/rohome" \
      env -u XDG_CACHE_HOME HOME="$T/rohome" MPLCONFIGDIR="$T/rotmp/mpl" TMPDIR="$T/rotmp" \
      safebasins chart --F 0.01 --Omega 0.9 --Psi pi --xi-max 0.14 --n 4 --cycles 5 -o ro --no-plot \
      > "$T/ro.out" 2>&1 || rc=$?; echo "$rc" > "$T/ro.rc" ) &
  RO_PID=$!
else
  log "read-only install: skipped (needs root and unshare -m for a read-only bind mount)"
fi

log "every module imports with the declared dependencies (the explorer and the CUDA engine: their extras)"
run 0 "$V/python" -c "
import importlib, pkgutil, safebasins
EXTRAS = {'bokeh': 'explore', 'numba.cuda.core': 'cuda'}   # what an extra's absence may leave unimportable
for m in pkgutil.walk_packages(safebasins.__path__, 'safebasins.'):
    if m.name.endswith('.__main__'):
        continue
    try:
        importlib.import_module(m.name)
    except ModuleNotFoundError as exc:
        if exc.name not in EXTRAS:
            raise SystemExit(f'{m.name}: {exc} (not declared in pyproject.toml)')
"
run 0 safebasins --version
expect "$(sed -n 's/^__version__ = "\(.*\)"/\1/p' "$ROOT/src/safebasins/__init__.py")"
log "chart: quartic, pendulum, expression well"
run 0 safebasins chart --F 0.01 --Omega 0.9 --Psi pi --xi-max 0.14,0.18 --n 8 --cycles 20 -o quartic
expect "wrote quartic.nc"
run 0 safebasins chart --well pendulum --F 0.05 --Omega 0.9 --Psi pi --xi-max 1.0 --n 8 --cycles 20 -o pendulum
expect "wrote pendulum.png"
# the pendulum written as an expression: parsed by sympy, the same compiled kernel, the same escapes
run 0 safebasins chart --well "expression:1 - cos(q)" --F 0.05 --Omega 0.9 --Psi pi --xi-max 1.0 --n 8 --cycles 20 -o expression
expect "wrote expression.nc"
run 0 "$V/python" -c "
import numpy as np, xarray as xr
with xr.open_dataset('pendulum.nc') as a, xr.open_dataset('expression.nc') as b:
    assert b.attrs['well'] != a.attrs['well'], (a.attrs['well'], b.attrs['well'])
    assert np.array_equal(a['escape_cycle_energy'].values, b['escape_cycle_energy'].values, equal_nan=True)
"
log "fcr, basin, info"
run 0 safebasins fcr --xi-max 0.15 --Omega-range 0.8,1.0,11 --numeric --numeric-Omega 0.85,0.95,3 --cycles 20 --n-scan 4 --tol 1e-3 -o fcr
expect "numeric F_cr at 3 of 3 Omega"
run 0 safebasins basin --F 0.0876 --Omega 0.92 --xi-max 0.24 --n 8 --n-gamma 24 --n-xi 20 --n-points 64 -o basin
expect "analytic safe:"
run 0 safebasins info pendulum.nc
expect "well: pendulum"
run 0 safebasins info fcr_numeric.nc
only_outputs "$W" "${OUTPUTS[@]}"

log "check-config: a good and a bad file"
printf 'experiments:\n  mine:\n    kind: basin_chart\n    well: pendulum\n    F: 0.05\n    Omega: 0.9\n    Psi: pi\n    xi_max: [1.0]\n    grid: {q0: [-1, 1], p0: [-1, 1], n: 10}\n' > "$T/in/good.yaml"
printf 'figures:\n  fig13: {cycles: [1, 2}\n' > "$T/in/bad.yaml"
run 0 safebasins check-config --base "$ROOT/config/config.yaml" "$T/in/good.yaml"
expect "valid ("
run 1 safebasins check-config --base "$ROOT/config/config.yaml" "$T/in/bad.yaml"
expect "config file $T/in/bad.yaml, line 2, column 24: not valid YAML"

log "without the extras: explore and --backend cuda name the extra to install"
run 1 safebasins explore --no-browser
expect "pip install 'safebasins[explore]'"
run 2 safebasins chart --F 0.01 --Omega 0.9 --Psi pi --xi-max 0.14 --n 4 --cycles 5 --backend cuda -o gpu
expect "pip install 'safebasins[cuda]'"
only_outputs "$W" "${OUTPUTS[@]}"

# ------------------------------------------------------------------ the extras
log "extras explore and cuda from environment.lock, pip check"
"$BUILD_PY" "$ROOT/.ci/lock_subset.py" "$WHEEL" explore cuda < "$ROOT/environment.lock" > "$T/extras.lock"
pip_in_venv install -q --no-compile --require-hashes --no-deps -r "$T/extras.lock"
pip_in_venv check

log "explore: started, its page fetched, stopped by SIGINT"
PORT=$("$V/python" -c "from safebasins.explore.server import free_port; print(free_port('127.0.0.1'))")
# SIGINT at its default action whatever this script inherited (a background job ignores it)
"$V/python" -c "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); \
signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT}); os.execvp(sys.argv[1], sys.argv[1:])" \
  safebasins explore --no-browser --port "$PORT" > "$T/explore.log" 2>&1 &
EXPLORE_PID=$!
"$V/python" - "$PORT" <<'EOF' || { cat "$T/explore.log"; fail "the explorer did not answer"; }
import sys, time, urllib.request
url = f"http://127.0.0.1:{sys.argv[1]}/"
for _ in range(240):
    try:
        with urllib.request.urlopen(url, timeout=30) as r:
            body = r.read().decode()
        break
    except OSError:
        time.sleep(0.5)
else:
    sys.exit(f"{url} did not answer in 120 s")
assert r.status == 200 and "bokeh" in body.lower(), (r.status, body[:300])
EOF
kill -INT "$EXPLORE_PID"
rc=0; wait "$EXPLORE_PID" || rc=$?
EXPLORE_PID=
cp "$T/explore.log" "$T/out"
[ "$rc" = 130 ] || { cat "$T/out"; fail "explore stopped by SIGINT exited $rc, not 130"; }
grep -qiE "warning|traceback|deprecat" "$T/out" && { cat "$T/out"; fail "warning text in the explorer's output"; }

log "CUDA engine under numba's simulator: escapes equal to the CPU engine's"
run 0 env NUMBA_ENABLE_CUDASIM=1 safebasins chart --F 0.01 --Omega 0.9 --Psi pi --xi-max 0.14 --n 4 --cycles 5 --backend cuda -o gpu --no-plot
run 0 safebasins chart --F 0.01 --Omega 0.9 --Psi pi --xi-max 0.14 --n 4 --cycles 5 --backend cpu -o cpu --no-plot
run 0 "$V/python" -c "
import numpy as np, xarray as xr
with xr.open_dataset('gpu.nc') as g, xr.open_dataset('cpu.nc') as c:
    assert np.array_equal(g['escape_cycle_energy'].values, c['escape_cycle_energy'].values, equal_nan=True)
"
rm -f gpu.nc cpu.nc
only_outputs "$W" "${OUTPUTS[@]}"

if [ -n "$RO_PID" ]; then
  log "read-only install: waiting for its chart"
  wait "$RO_PID"
  checked 0 "$(cat "$T/ro.rc")" "$T/ro.out" "the chart from a read-only install"
  grep -qF "wrote ro.nc" "$T/ro.out" || { cat "$T/ro.out"; fail "the read-only install wrote no ro.nc"; }
  only_outputs "$T/ro" ro.nc
  [ -n "$(find "$T/rotmp" -path "*/safebasins-numba-*" -name "*.nbi" -print -quit)" ] ||
    fail "no kernel cache in the private temp directory"
fi

log "passed: the wheel works from an empty directory ($((SECONDS - START)) s)"
