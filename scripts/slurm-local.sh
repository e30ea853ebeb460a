#!/usr/bin/env bash
# A one-node Slurm cluster on this machine for the length of one command:
#
#   scripts/slurm-local.sh COMMAND [ARGS...]
#
# installs Debian's slurmctld, slurmd, slurm-client and munge when they are missing (as root;
# no service starts by itself), writes a slurm.conf and a munge key into a temporary folder,
# starts munged, slurmctld and slurmd from there, waits until the node is idle, runs COMMAND
# with SLURM_CONF set, and on exit stops exactly the daemons it started (by pid) and removes
# the folder. The exit status is COMMAND's. Nothing under /etc is used or changed, apart from
# the packages themselves.
set -euo pipefail

if [ $# -eq 0 ]; then
    echo "usage: $0 COMMAND [ARGS...]" >&2
    exit 2
fi

need=()
for b in slurmctld slurmd sbatch munged; do
    command -v "$b" >/dev/null || need+=("$b")
done
if [ ${#need[@]} -gt 0 ]; then
    if [ "$(id -u)" -ne 0 ]; then
        echo "slurm-local: ${need[*]} missing and not root: cannot install Slurm" >&2
        exit 3
    fi
    # Debian's maintainer scripts would start the daemons with /etc's configuration: a
    # policy-rc.d that answers 101 forbids it for the length of the install.
    policy=/usr/sbin/policy-rc.d
    saved=""
    if [ -e "$policy" ]; then
        saved=$(mktemp)
        cp -p "$policy" "$saved"
    fi
    printf '#!/bin/sh\nexit 101\n' >"$policy"
    chmod 755 "$policy"
    restore_policy() {
        if [ -n "$saved" ]; then mv -f "$saved" "$policy"; else rm -f "$policy"; fi
    }
    trap restore_policy EXIT
    echo "slurm-local: installing slurmctld slurmd slurm-client munge" >&2
    export DEBIAN_FRONTEND=noninteractive
    timeout 600 apt-get install -y -q --no-install-recommends \
        slurmctld slurmd slurm-client munge >/dev/null ||
        { timeout 300 apt-get update -q >/dev/null &&
          timeout 600 apt-get install -y -q --no-install-recommends \
              slurmctld slurmd slurm-client munge >/dev/null; }
    restore_policy
    trap - EXIT
fi

dir=$(mktemp -d "${TMPDIR:-/tmp}/slurm-local.XXXXXX")
pids=()
stop() {
    # Reverse order of starting; only the pids this script recorded.
    for ((k = ${#pids[@]} - 1; k >= 0; k--)); do
        kill "${pids[k]}" 2>/dev/null || true
    done
    for p in "${pids[@]}"; do
        for _ in $(seq 50); do
            kill -0 "$p" 2>/dev/null || break
            sleep 0.1
        done
        kill -9 "$p" 2>/dev/null || true
    done
    rm -rf "$dir"
}
trap stop EXIT

# Waits up to $1 seconds for a pid file to name a live process, and records it.
started() {
    local file=$2
    for _ in $(seq $(($1 * 10))); do
        if [ -s "$file" ] && kill -0 "$(cat "$file")" 2>/dev/null; then
            pids+=("$(cat "$file")")
            return 0
        fi
        sleep 0.1
    done
    echo "slurm-local: $3 did not start; its log:" >&2
    tail -n 20 "$dir/$3.log" >&2 || true
    return 1
}

mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
chmod 700 "$dir/munge"
head -c 1024 /dev/urandom >"$dir/munge/munge.key"
chmod 400 "$dir/munge/munge.key"
socket="$dir/munge/munge.socket"
# --force: munged refuses a key folder under a world-writable /tmp otherwise.
munged --force --key-file "$dir/munge/munge.key" --socket "$socket" \
    --pid-file "$dir/munged.pid" --log-file "$dir/munged.log" \
    --seed-file "$dir/munge/munge.seed"
started 10 "$dir/munged.pid" munged

host=$(hostname -s)
cpus=$(nproc)
mem=$(awk '/MemTotal/ { print int($2 / 1024 * 0.9) }' /proc/meminfo)
user=$(id -un)
cat >"$dir/slurm.conf" <<EOF
ClusterName=local
SlurmctldHost=$host
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
SlurmctldPort=$((17000 + RANDOM % 20000))
SlurmdPort=$((37000 + RANDOM % 20000))
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerParameters=sched_interval=1
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$dir/slurm.conf"

slurmctld -f "$SLURM_CONF" -i
started 20 "$dir/slurmctld.pid" slurmctld
slurmd -f "$SLURM_CONF"
started 20 "$dir/slurmd.pid" slurmd

ready=""
for _ in $(seq 300); do
    state=$(timeout 5 sinfo -h -N -o '%T' 2>/dev/null | head -n 1 || true)
    if [ "$state" = idle ]; then
        ready=1
        break
    fi
    sleep 0.2
done
if [ -z "$ready" ]; then
    echo "slurm-local: the node did not become idle (state '${state:-none}')" >&2
    tail -n 20 "$dir/slurmctld.log" "$dir/slurmd.log" >&2 || true
    exit 1
fi
echo "slurm-local: one-node cluster '$host' ($cpus CPUs) up, SLURM_CONF=$SLURM_CONF" >&2

set +e
"$@"
status=$?
set -e
exit "$status"
