#!/usr/bin/env bash
# CI check of the SLURM profile (make test-cluster): start a single-node SLURM on localhost
# (slurm_up.sh), run the same targets of the quick configuration twice into two fresh sandboxes,
# once locally (snakemake -j2) and once through the SLURM executor with workflow/profiles/slurm,
# and compare every dataset value by value (scripts/compare_results.py). The cluster is always
# stopped (trap); on failure the daemons' logs, the SLURM logs of failed jobs and the tails of
# both snakemake logs are printed. Exit status non-zero on any failure.
#
# Targets (CI's time budget: the whole quick `datasets` target takes ~3 min locally and ~8 min
# through SLURM on 2 cores, where every SLURM job starts Snakemake twice): Fig 13 (analytic basin
# + numeric chart gathered from tiles with its agreement), Fig 10 (analytic + numeric F_cr, the
# numeric one a heavy dataset without tiles) and the integrity map (extras, tiles = F blocks),
# with numerics.tiles = 2: 8 chart tiles, each its own SLURM job, and the three dataset groups of
# the profile. SB_CLUSTER_TARGETS=datasets runs every dataset of the quick configuration instead.
#
# Needs root (installs slurm-wlm and munge with apt-get when missing). Environment:
#   SB_CLUSTER_TARGETS  snakemake targets (default: the subset above)
#   SB_CLUSTER_TILES    numerics.tiles of both runs (default 2)
#   SB_CLUSTER_CONFIG   config file merged over config/config.yaml (default config/quick.yaml)
#   SB_CLUSTER_WORK  sandboxes and logs (default /tmp/safebasins-cluster-check, wiped at start)
#   SB_SLURM_DIR     the cluster's files (default /tmp/safebasins-slurm)
#   SB_VENV          the Python environment (default .venv of this checkout)
#   SB_RUN_TIMEOUT   seconds allowed to each snakemake run (default 600; then it is stopped)
#   SB_KEEP_CLUSTER=1  leave the cluster running afterwards (for debugging)
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
# shellcheck source=tests/cluster/slurm_env.sh
source "$HERE/slurm_env.sh"
BIN="${SB_VENV:-$ROOT/.venv}/bin"
PROFILE="$ROOT/workflow/profiles/slurm"
WORK=${SB_CLUSTER_WORK:-/tmp/safebasins-cluster-check}
LOCAL="$WORK/local"
SLURM="$WORK/slurm"
TILES=${SB_CLUSTER_TILES:-2}
TARGETS=${SB_CLUSTER_TARGETS:-"results/data/analytic/basin_fig13.nc results/data/numeric/chart_fig13.nc
  results/data/analytic/fcr_fig10.nc results/data/numeric/fcr_fig10.nc
  results/data/extras/integrity_map_analytic.nc results/data/extras/integrity_map_numeric.nc"}
export PATH="$BIN:$PATH"   # the jobs inherit it (sbatch --export=ALL): same venv python everywhere

log() { printf '[cluster-check %s] %s\n' "$(date +%H:%M:%S)" "$*" >&2; }
now() { date +%s; }
run_failed() {
    if [ "$2" = 124 ] || [ "$2" = 137 ]; then log "$1 run timed out after ${RUN_TIMEOUT} s"; else log "$1 run failed (exit $2)"; fi
}

RUN_TIMEOUT=${SB_RUN_TIMEOUT:-600}
STATUS=1
CLUSTER_UP=0
RUN_PID=
# run_in DIR ARGS...: snakemake ARGS in sandbox DIR, log DIR.log, stopped after RUN_TIMEOUT s (SIGTERM:
# Snakemake cancels its SLURM jobs; SIGKILL 30 s later). In the background, so that a signal to this
# script is handled at once (on_exit stops the run).
run_in() {
    local dir=$1 rc=0
    shift
    (cd "$dir" && exec timeout -k 30 "$RUN_TIMEOUT" "$BIN/snakemake" -d "$dir" -s "$dir/Snakefile" "$@") >"$dir.log" 2>&1 &
    RUN_PID=$!
    wait "$RUN_PID" || rc=$?
    RUN_PID=
    return "$rc"
}
on_exit() {
    local rc=$?
    set +e   # diagnostics and shutdown must run to the end, whatever fails in them
    [ "$STATUS" = 0 ] && rc=0
    if [ -n "$RUN_PID" ] && kill -0 "$RUN_PID" 2>/dev/null; then
        log "stopping the running snakemake (pid $RUN_PID)"
        kill -TERM "$RUN_PID" 2>/dev/null
        for _ in $(seq 300); do kill -0 "$RUN_PID" 2>/dev/null || break; sleep 0.1; done
        kill -KILL "$RUN_PID" 2>/dev/null
    fi
    if [ "$rc" != 0 ]; then
        log "FAILED (exit $rc): diagnostics follow"
        for f in "$LOCAL.log" "$SLURM.log"; do
            [ -f "$f" ] && { echo "======== $f (last 60 lines) ========" >&2; tail -n 60 "$f" >&2; }
        done
        # the plugin keeps the SLURM logs of failed jobs only
        find "$SLURM/.snakemake/slurm_logs" -name '*.log' -type f 2>/dev/null | head -n 10 | while read -r f; do
            echo "======== $f ========" >&2; tail -n 40 "$f" >&2
        done
        [ "$CLUSTER_UP" = 1 ] && sb_dump_logs   # (slurm_up.sh prints them itself when it fails)
    fi
    if [ "${SB_KEEP_CLUSTER:-0}" = 1 ]; then
        log "cluster left running (SB_KEEP_CLUSTER=1): SLURM_CONF=$SLURM_CONF; stop it with $HERE/slurm_down.sh"
    else
        "$HERE/slurm_down.sh" || true
    fi
    exit "$rc"
}
# one check at a time on this machine (a second one would stop the first one's cluster); the lock
# goes with this process, so a killed check never blocks the next one
exec 9>"$SB_SLURM_DIR.lock"
flock -n 9 || { log "another cluster check holds $SB_SLURM_DIR.lock: not starting"; exit 1; }
trap on_exit EXIT
trap 'exit 130' INT TERM

[ -x "$BIN/snakemake" ] || { log "no $BIN/snakemake: run 'make test' (creates .venv) first"; exit 1; }

T0=$(now)
"$HERE/slurm_up.sh" 9>&-   # (the daemons must not inherit the lock)
CLUSTER_UP=1
T_UP=$(($(now) - T0))

rm -rf "$WORK"
mkdir -p "$WORK"
# the sandboxes of the workflow tests (symlinks to this checkout; tests/pipeline/sandbox.py)
(cd "$ROOT" && "$BIN/python" -c 'import sys; from pathlib import Path; from tests.pipeline.sandbox import make_sandbox
for p in sys.argv[1:]: make_sandbox(Path(p))' "$LOCAL" "$SLURM")
printf 'numerics: {tiles: %d}\n' "$TILES" >"$WORK/tiles.yaml"
CONFIGS="${SB_CLUSTER_CONFIG:-config/quick.yaml} $WORK/tiles.yaml"

# targets before --configfile (it takes every following word)
# ($TARGETS and $CONFIGS unquoted: split into words on purpose)
log "local run: snakemake -j2 <$(wc -w <<<"$TARGETS") targets> --configfile $CONFIGS (tiles $TILES, log $LOCAL.log)"
T1=$(now)
run_in "$LOCAL" -j2 $TARGETS --configfile $CONFIGS || { run_failed local $?; exit 1; }
T_LOCAL=$(($(now) - T1))
log "local run done in ${T_LOCAL} s"

# --cores: the node's CPUs bound a group job's width (see the profile)
NODE_CPUS=$(sinfo -h -o %c | head -n 1)
log "SLURM run: snakemake --workflow-profile workflow/profiles/slurm --cores $NODE_CPUS <same targets> (log $SLURM.log)"
T2=$(now)
run_in "$SLURM" --workflow-profile "$PROFILE" --cores "$NODE_CPUS" $TARGETS --configfile $CONFIGS \
    || { run_failed SLURM $?; exit 1; }
T_SLURM=$(($(now) - T2))
n_sub=$(grep -c 'has been submitted with SLURM jobid' "$SLURM.log" || true)
log "SLURM run done in ${T_SLURM} s (${n_sub} SLURM jobs)"

# every job really went through SLURM: the slurmctld log has one completion per submitted job
n_done=$(grep -c '_job_complete: JobId=[0-9]* done' "$SB_SLURM_DIR/log/slurmctld.log" || true)
[ "$n_sub" -gt 0 ] || { log "no job was submitted to SLURM"; exit 1; }
[ "$n_done" -ge "$n_sub" ] || { log "slurmctld saw $n_done completed jobs, snakemake submitted $n_sub"; exit 1; }

log "comparing results/data (local vs SLURM)"
"$BIN/python" "$ROOT/scripts/compare_results.py" --parts "$LOCAL/results/data" "$SLURM/results/data" \
    || { log "datasets differ between the local and the SLURM run"; exit 1; }
n_files=$(find "$SLURM/results/data" -name '*.nc' -type f | wc -l)
[ "$n_files" -gt 0 ] || { log "no dataset written"; exit 1; }
# the chart tiles ran as independent SLURM jobs: one job per tile file
n_tiles=$(find "$SLURM/results/data/numeric/parts" -name '*.nc' -type f 2>/dev/null | wc -l)
n_tile_jobs=$(grep 'has been submitted with SLURM jobid' "$SLURM.log" | grep -c 'slurm_logs/rule_chart_tile/' || true)
[ "$n_tile_jobs" = "$n_tiles" ] || { log "$n_tiles chart tiles but $n_tile_jobs rule_chart_tile SLURM jobs"; exit 1; }

STATUS=0
log "OK: ${n_files} netCDF files identical (${n_tiles} tiles, each its own SLURM job); cluster up ${T_UP} s, local run ${T_LOCAL} s, SLURM run ${T_SLURM} s, total $(($(now) - T0)) s"
