# Shared settings of the single-node test cluster (sourced by slurm_up.sh, slurm_down.sh and
# run_cluster_check.sh). Everything lives under $SB_SLURM_DIR; the SLURM commands find the
# cluster through $SLURM_CONF (no file under /etc/slurm is written or read).
SB_SLURM_DIR=${SB_SLURM_DIR:-/tmp/safebasins-slurm}
SB_SLURM_CTLD_PORT=${SB_SLURM_CTLD_PORT:-16817}   # non-default ports: never collide with a system SLURM
SB_SLURM_SLURMD_PORT=${SB_SLURM_SLURMD_PORT:-16818}
SB_SLURM_UP_TIMEOUT=${SB_SLURM_UP_TIMEOUT:-90}    # seconds to wait for the node to become idle
export SB_SLURM_DIR
export SLURM_CONF="$SB_SLURM_DIR/etc/slurm.conf"

sb_log() { printf '[slurm %s] %s\n' "$(date +%H:%M:%S)" "$*" >&2; }

# Print the daemons' logs and the cluster state (on failure, or when asked).
sb_dump_logs() {
    local f
    sb_log "---------------- cluster state and daemon logs ($SB_SLURM_DIR/log) ----------------"
    if [ -f "$SLURM_CONF" ] && command -v sinfo >/dev/null 2>&1; then
        timeout 10 sinfo -N -l 2>&1 || true
        timeout 10 scontrol show node 2>&1 || true
        timeout 10 squeue --states=all -o '%i %j %T %r %M %N' 2>&1 | tail -n 40 || true
    fi
    for f in "$SB_SLURM_DIR"/log/*.log; do
        [ -f "$f" ] || continue
        echo "======== $f (last 80 lines) ========" >&2
        tail -n 80 "$f" >&2 || true
    done
}

# pid of a daemon (munged, slurmctld, slurmd) of this cluster, if it is alive: from its pid file,
# else (pid file lost) the process of that name whose command line names this cluster's files
sb_pid() {
    local pidfile="$SB_SLURM_DIR/run/$1.pid" pid p
    if [ -f "$pidfile" ]; then
        pid=$(tr -dc '0-9' <"$pidfile")
        # a stale pid file whose pid now belongs to another program is not ours
        if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null && [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "$1" ]; then
            echo "$pid"; return 0
        fi
    fi
    for p in /proc/[0-9]*; do
        [ "$(cat "$p/comm" 2>/dev/null)" = "$1" ] || continue
        if tr '\0' ' ' 2>/dev/null <"$p/cmdline" | grep -qF "$SB_SLURM_DIR/"; then
            echo "${p#/proc/}"; return 0
        fi
    done
    return 1
}
