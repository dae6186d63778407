#!/usr/bin/env bash
# Stop the single-node test cluster of slurm_up.sh: cancel every job, `scontrol shutdown`
# (slurmctld and slurmd), then munged; a daemon still running after 5 s gets SIGTERM, after 15 s
# more SIGKILL (by the pid in its pid file, checked against the process name).
#   tests/cluster/slurm_down.sh            # stop
#   tests/cluster/slurm_down.sh --logs     # print cluster state and daemon logs first
# Idempotent: exits 0 when nothing is running. The work directory stays (logs); slurm_up.sh
# wipes it on the next start.
set -uo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=tests/cluster/slurm_env.sh
source "$HERE/slurm_env.sh"

[ "${1:-}" = "--logs" ] && sb_dump_logs

# wait until the process is gone, up to $3 tenths of a second; return 1 if it is still there
wait_pid() {
    local pid=$1 n
    for n in $(seq "$2"); do kill -0 "$pid" 2>/dev/null || return 0; sleep 0.1; done
    return 1
}
# $1 name, $2 pid: wait 5 s (after scontrol shutdown / SIGTERM), SIGTERM, wait 15 s, SIGKILL
stop_daemon() {
    wait_pid "$2" 50 && return 0
    sb_log "$1 ($2) still running: SIGTERM"
    kill -TERM "$2" 2>/dev/null || true
    wait_pid "$2" 150 && return 0
    sb_log "$1 ($2) still running: SIGKILL"
    kill -KILL "$2" 2>/dev/null || true
    wait_pid "$2" 20 || true
}

if pid=$(sb_pid slurmctld); then
    # cancel every job (the test jobs are the only ones on this cluster), give them a moment
    timeout 15 scancel --full --quiet --user root 2>/dev/null || true
    timeout 15 scancel --quiet --state=PENDING 2>/dev/null || true
    for _ in $(seq 50); do
        [ -z "$(timeout 10 squeue -h -t PENDING,RUNNING,COMPLETING,SUSPENDED -o %i 2>/dev/null)" ] && break
        sleep 0.2
    done
fi

# `scontrol shutdown`: the controller saves its state and tells slurmd to exit; then make sure
# (SIGTERM, after 15 s SIGKILL) and stop munged last
if sb_pid slurmctld >/dev/null; then
    timeout 10 scontrol shutdown >/dev/null 2>&1 || true
fi
for daemon in slurmd slurmctld munged; do
    if pid=$(sb_pid "$daemon"); then
        [ "$daemon" = munged ] && { kill -TERM "$pid" 2>/dev/null || true; }
        stop_daemon "$daemon" "$pid"
    fi
    rm -f "$SB_SLURM_DIR/run/$daemon.pid"
done
# job processes left behind (slurmstepd outlives slurmd; a job that ignored scancel): they are
# this cluster's only if their environment names its slurm.conf (slurmd/slurmctld were started
# with SLURM_CONF exported) and they are a slurmstepd or carry a SLURM_JOB_ID
for p in /proc/[0-9]*; do
    pid=${p#/proc/}
    [ "$pid" = "$$" ] && continue
    env_of=$(tr '\0' '\n' 2>/dev/null <"$p/environ") || continue
    grep -qxF "SLURM_CONF=$SLURM_CONF" <<<"$env_of" || continue
    if grep -q '^SLURM_JOB_ID=' <<<"$env_of" || [ "$(cat "$p/comm" 2>/dev/null)" = slurmstepd ]; then
        sb_log "killing leftover job process $pid ($(tr '\0' ' ' 2>/dev/null <"$p/cmdline" | cut -c1-80))"
        kill -KILL "$pid" 2>/dev/null || true
    fi
done
rm -f "$SB_SLURM_DIR/munge/munge.socket.2"* 2>/dev/null
# the /etc/slurm/slurm.conf link of slurm_up.sh (only if it is that link)
[ "$(readlink /etc/slurm/slurm.conf 2>/dev/null)" = "$SLURM_CONF" ] && rm -f /etc/slurm/slurm.conf
sb_log "cluster stopped"
exit 0
