#!/usr/bin/env bash
# Start a single-node SLURM cluster on localhost (controller and compute node on this machine):
# munged, slurmctld and slurmd as daemons, everything under $SB_SLURM_DIR (default
# /tmp/safebasins-slurm), no external network. Installs Debian's slurm-wlm and munge when missing.
# Waits until the node is idle and a trivial batch job and job step run; on any failure it
# prints the daemons' logs, stops what it started and exits non-zero.
#
#   tests/cluster/slurm_up.sh && export SLURM_CONF=/tmp/safebasins-slurm/etc/slurm.conf
#   ... sinfo / sbatch / snakemake --workflow-profile workflow/profiles/slurm ...
#   tests/cluster/slurm_down.sh
#
# Needs root (daemons and jobs run as root; the test jobs share this machine's file system).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=tests/cluster/slurm_env.sh
source "$HERE/slurm_env.sh"
T0=$(date +%s)

fail() {
    sb_log "ERROR: $*"
    sb_dump_logs
    "$HERE/slurm_down.sh" >/dev/null 2>&1 || true
    exit 1
}

[ "$(id -u)" = 0 ] || { sb_log "ERROR: needs root (starts munged/slurmctld/slurmd)"; exit 1; }

# ------------------------------------------------------------------ install (idempotent)
need=()
for cmd in munged mungekey slurmctld slurmd sbatch sinfo squeue scontrol; do
    command -v "$cmd" >/dev/null 2>&1 || need+=("$cmd")
done
if [ ${#need[@]} -gt 0 ]; then
    sb_log "installing slurm-wlm and munge (missing: ${need[*]})"
    export DEBIAN_FRONTEND=noninteractive
    # the packages' own services (munge, slurmctld, slurmd with /etc configuration) must not
    # start: a temporary policy-rc.d where the image has none (Docker images have one)
    policy=/usr/sbin/policy-rc.d own_policy=0
    if [ ! -e "$policy" ]; then
        printf '#!/bin/sh\nexit 101\n' >"$policy" && chmod 0755 "$policy" && own_policy=1
    fi
    apt_log="${TMPDIR:-/tmp}/safebasins-slurm-apt.log"
    # (wait up to 2 min for a dpkg lock held by another apt run; retry a failed download once)
    for attempt in 1 2; do
        if timeout 600 apt-get -o DPkg::Lock::Timeout=120 update -qq >"$apt_log" 2>&1 \
            && timeout 600 apt-get -o DPkg::Lock::Timeout=120 install -y -qq --no-install-recommends \
                slurm-wlm munge >>"$apt_log" 2>&1; then
            break
        fi
        if [ "$attempt" = 2 ]; then
            [ "$own_policy" = 1 ] && rm -f "$policy"
            cat "$apt_log" >&2; sb_log "ERROR: apt-get install slurm-wlm munge failed"; exit 1
        fi
        sb_log "apt-get failed, retrying in 10 s"; sleep 10
    done
    [ "$own_policy" = 1 ] && rm -f "$policy"
    sb_log "installed in $(($(date +%s) - T0)) s"
fi
T1=$(date +%s)

# ------------------------------------------------------------------ clean state
"$HERE/slurm_down.sh" >/dev/null 2>&1 || true      # a leftover cluster of an earlier run
rm -rf "$SB_SLURM_DIR"
mkdir -p "$SB_SLURM_DIR"/{etc,run,log,state,spool,tmp,munge}
chmod 0700 "$SB_SLURM_DIR/munge"
chmod 0755 "$SB_SLURM_DIR"

for port in "$SB_SLURM_CTLD_PORT" "$SB_SLURM_SLURMD_PORT"; do
    if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
        sb_log "ERROR: port $port is already in use (set SB_SLURM_CTLD_PORT / SB_SLURM_SLURMD_PORT)"; exit 1
    fi
done

# The job steps of snakemake-executor-plugin-slurm-jobstep (0.6) run `srun` with every SLURM_*
# variable but a few removed, SLURM_CONF included: that srun reads the default
# /etc/slurm/slurm.conf. Point it at this cluster's file (a link, removed by slurm_down.sh);
# never replace a slurm.conf that is not ours.
SYS_CONF=/etc/slurm/slurm.conf
if [ -e "$SYS_CONF" ] || [ -L "$SYS_CONF" ]; then
    [ "$(readlink "$SYS_CONF" 2>/dev/null)" = "$SLURM_CONF" ] \
        || { sb_log "ERROR: $SYS_CONF exists and is not this test cluster's (a real SLURM installation?)"; exit 1; }
else
    mkdir -p /etc/slurm
    ln -s "$SLURM_CONF" "$SYS_CONF"
fi

# ------------------------------------------------------------------ munge (own key and socket)
MUNGE_SOCKET="$SB_SLURM_DIR/munge/munge.socket.2"
mungekey --create --keyfile="$SB_SLURM_DIR/munge/munge.key" --force >/dev/null 2>&1 \
    || dd if=/dev/urandom of="$SB_SLURM_DIR/munge/munge.key" bs=1024 count=1 status=none
chmod 0400 "$SB_SLURM_DIR/munge/munge.key"
# --force: munged refuses sockets below a world-writable directory such as /tmp otherwise
munged --force --socket="$MUNGE_SOCKET" --key-file="$SB_SLURM_DIR/munge/munge.key" \
    --pid-file="$SB_SLURM_DIR/run/munged.pid" --log-file="$SB_SLURM_DIR/log/munged.log" \
    --seed-file="$SB_SLURM_DIR/munge/munged.seed" \
    || fail "munged did not start"
for _ in $(seq 50); do [ -S "$MUNGE_SOCKET" ] && break; sleep 0.1; done
echo ok | munge --socket="$MUNGE_SOCKET" | unmunge --socket="$MUNGE_SOCKET" >/dev/null 2>&1 \
    || fail "munge credential round trip failed"

# ------------------------------------------------------------------ slurm.conf (this machine's CPUs/memory)
HOST=$( (hostname -s || uname -n) 2>/dev/null | head -n 1 | cut -d. -f1)
CPUS=$(nproc)
# a container's CPU quota (cgroup v2 cpu.max "quota period") lowers that
if read -r quota period 2>/dev/null </sys/fs/cgroup/cpu.max && [ "$quota" != max ] && [ "${period:-0}" -gt 0 ]; then
    qcpus=$(((quota + period - 1) / period))
    [ "$qcpus" -ge 1 ] && [ "$qcpus" -lt "$CPUS" ] && CPUS=$qcpus
fi
# slurmd -C: the memory slurmd itself detects; a node configured with more is drained, so stay below
MEM=$(slurmd -C 2>/dev/null | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' | head -n 1)
[ -n "$MEM" ] || MEM=$(free -m | awk '/^Mem:/ {print $2}')
# and a container's memory limit (cgroup v2 memory.max, bytes)
if read -r memmax 2>/dev/null </sys/fs/cgroup/memory.max && [ "$memmax" != max ]; then
    [ $((memmax / 1048576)) -lt "$MEM" ] && MEM=$((memmax / 1048576))
fi
MEM=$((MEM * 95 / 100))
# the socket/core layout slurmd detects, when it agrees with nproc (else just the CPU count)
HW=$(slurmd -C 2>/dev/null | head -n 1 || true)
TOPO="CPUs=$CPUS"
if [ "$(sed -n 's/.* CPUs=\([0-9]*\).*/\1/p' <<<"$HW")" = "$CPUS" ]; then
    TOPO=$(grep -o 'CPUs=[0-9]* Boards=[0-9]* SocketsPerBoard=[0-9]* CoresPerSocket=[0-9]* ThreadsPerCore=[0-9]*' <<<"$HW" || echo "CPUs=$CPUS")
fi
cat >"$SLURM_CONF" <<EOF
# Single-node test cluster written by tests/cluster/slurm_up.sh (do not edit: rewritten each start)
ClusterName=safebasins
SlurmctldHost=$HOST(127.0.0.1)
SlurmctldPort=$SB_SLURM_CTLD_PORT
SlurmdPort=$SB_SLURM_SLURMD_PORT
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$MUNGE_SOCKET
StateSaveLocation=$SB_SLURM_DIR/state
SlurmdSpoolDir=$SB_SLURM_DIR/spool
SlurmctldPidFile=$SB_SLURM_DIR/run/slurmctld.pid
SlurmdPidFile=$SB_SLURM_DIR/run/slurmd.pid
SlurmctldLogFile=$SB_SLURM_DIR/log/slurmctld.log
SlurmdLogFile=$SB_SLURM_DIR/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
TmpFS=$SB_SLURM_DIR/tmp
# no cgroups, no accounting daemon: works inside containers
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
PropagateResourceLimits=NONE
# CPUs and memory are consumable: several jobs share the node like snakemake -j does locally
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
DefMemPerCPU=1000
# finished jobs stay visible to squeue for 15 min: the profile's status command is squeue
MinJobAge=900
MailProg=/bin/true
ReturnToService=2
SlurmdParameters=config_overrides
SlurmctldTimeout=60
SlurmdTimeout=300
InactiveLimit=0
KillWait=5
Waittime=0
NodeName=$HOST NodeAddr=127.0.0.1 $TOPO RealMemory=$MEM State=UNKNOWN
PartitionName=main Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
sb_log "slurm.conf: node $HOST, $TOPO, RealMemory=$MEM MB, ports $SB_SLURM_CTLD_PORT/$SB_SLURM_SLURMD_PORT"

# ------------------------------------------------------------------ daemons
slurmctld -c -f "$SLURM_CONF" || fail "slurmctld did not start"
for _ in $(seq 100); do timeout 5 scontrol ping 2>/dev/null | grep -q 'is UP' && break; sleep 0.2; done
timeout 5 scontrol ping 2>/dev/null | grep -q 'is UP' || fail "slurmctld does not answer (scontrol ping)"
slurmd -f "$SLURM_CONF" || fail "slurmd did not start"

# ------------------------------------------------------------------ wait for an idle node
deadline=$(($(date +%s) + SB_SLURM_UP_TIMEOUT))
resumed=0
while :; do
    state=$(timeout 10 sinfo -h -N -n "$HOST" -o '%T' 2>/dev/null | head -n 1 || true)
    case "$state" in
        idle) break ;;
        down*|drain*|drained*|fail*)
            # a node seen DOWN before slurmd registered: resume it once
            if [ "$resumed" = 0 ]; then
                resumed=1
                sb_log "node state '$state': resuming it"
                timeout 10 scontrol update NodeName="$HOST" State=RESUME 2>&1 || true
            fi ;;
    esac
    [ "$(date +%s)" -lt "$deadline" ] || fail "node not idle after ${SB_SLURM_UP_TIMEOUT}s (state '${state:-none}')"
    sb_pid slurmd >/dev/null || fail "slurmd died"
    sb_pid slurmctld >/dev/null || fail "slurmctld died"
    sleep 0.5
done

# ------------------------------------------------------------------ smoke test: a batch job with a job step
# (its srun without SLURM_CONF, as the jobstep plugin runs it)
# (polled every 0.2 s: `sbatch --wait` polls with growing sleeps and costs several seconds)
out="$SB_SLURM_DIR/tmp/smoke.out"
jobid=$(timeout 30 sbatch --parsable -J smoke -o "$out" -t 1 --mem 100 -c 1 -D "$SB_SLURM_DIR/tmp" \
    --wrap 'env -u SLURM_CONF srun -n1 hostname && echo SMOKE-OK') || fail "sbatch of the smoke job failed"
deadline=$(($(date +%s) + 60))
while :; do
    jstate=$(timeout 10 squeue -h -j "$jobid" --states=all -o %T 2>/dev/null || true)
    case "$jstate" in
        COMPLETED) break ;;
        FAILED|CANCELLED*|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|BOOT_FAIL|DEADLINE|PREEMPTED)
            cat "$out" >&2 2>/dev/null || true; fail "smoke job $jobid ended $jstate" ;;
    esac
    [ "$(date +%s)" -lt "$deadline" ] || fail "smoke job $jobid not done after 60 s (state '${jstate:-none}')"
    sleep 0.2
done
grep -q SMOKE-OK "$out" 2>/dev/null || { cat "$out" >&2 2>/dev/null || true; fail "smoke job produced no output"; }
timeout 60 srun -n1 -t 1 --mem 100 true || fail "srun smoke test failed"

sb_log "cluster up in $(($(date +%s) - T1)) s (SLURM_CONF=$SLURM_CONF)"
