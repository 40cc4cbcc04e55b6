#!/usr/bin/env bash
# A one-node Slurm 22.05 cluster that lives entirely under one scratch folder (munge key, socket,
# config, state, spool, logs, pid files), for tests and local runs. Root, no systemd needed.
#
#   scripts/slurm-local-cluster.sh start DIR   # prints `export SLURM_CONF=DIR/slurm.conf`
#   scripts/slurm-local-cluster.sh stop DIR    # cancels every job, shuts the daemons down
#
# What a working cluster needed here (docs/ARCHITECTURE.md, "Sharding"): munged with
# its own key, socket (folder mode 755), pid, log and seed files; proctrack/linuxproc (the default
# cgroup tracking fails silently: jobs "succeed" without running and the node drains);
# select/cons_tres with CR_CPU (else array tasks run one at a time); MinJobAge=5 (else
# `sbatch --wait` polls at 2, 10, 42, 74 s); kill_invalid_depend (else a merge whose shard failed
# stays pending forever).
set -euo pipefail

cmd="${1:-}" dir="${2:-}"
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: $0 start|stop DIR" >&2; exit 1; }
dir="$(realpath -m "$dir")"
conf="$dir/slurm.conf"
export SLURM_CONF="$conf"

wait_for() {  # wait_for SECONDS COMMAND...: polls every 0.1 s
  local deadline=$((SECONDS + $1)); shift
  until "$@" >/dev/null 2>&1; do
    [ $SECONDS -lt $deadline ] || return 1
    sleep 0.1
  done
}

start() {
  for tool in munged mungekey slurmctld slurmd sbatch scontrol sinfo; do
    command -v "$tool" >/dev/null || { echo "slurm-local-cluster: $tool not installed (scripts/setup.sh)" >&2; exit 77; }
  done
  mkdir -p "$dir"/{munge,state,spool,log}
  chmod 755 "$dir" "$dir/munge"
  mungekey --create --keyfile="$dir/munge/munge.key" --force
  chmod 600 "$dir/munge/munge.key"
  munged --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/munge/munge.seed" --force
  local node cpus mem port
  node="$(hostname -s)"
  cpus="$(nproc)"
  mem="$(slurmd -C | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p')"
  port=$((20000 + (RANDOM % 20000) * 2))  # two ports; a clash with another cluster is unlikely
  cat > "$conf" <<EOF
ClusterName=gibake-local
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MinJobAge=5
DependencyParameters=kill_invalid_depend
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
  slurmctld -f "$conf"
  wait_for 20 scontrol ping || { echo "slurm-local-cluster: slurmctld did not answer" >&2; exit 4; }
  slurmd -f "$conf" -N "$node"
  wait_for 30 sh -c "sinfo -h -o %T | grep -qx idle" || { echo "slurm-local-cluster: the node is not idle" >&2; exit 4; }
  echo "export SLURM_CONF=$conf"
}

stop_pid() {  # stop_pid PIDFILE: TERM, then KILL after 5 s
  [ -f "$1" ] || return 0
  local pid
  pid="$(cat "$1")"
  kill "$pid" 2>/dev/null || return 0
  for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || return 0; sleep 0.1; done
  kill -9 "$pid" 2>/dev/null || true
}

stop() {
  if [ -f "$conf" ]; then
    scancel --full --quiet --user="$(id -un)" 2>/dev/null || true
    wait_for 15 sh -c '[ -z "$(squeue -h 2>/dev/null)" ]' || true
    timeout 10 scontrol shutdown >/dev/null 2>&1 || true
    sleep 0.5
    stop_pid "$dir/slurmd.pid"
    stop_pid "$dir/slurmctld.pid"
  fi
  stop_pid "$dir/munge/munged.pid"
}

case "$cmd" in
  start) start ;;
  stop) stop ;;
  *) echo "usage: $0 start|stop DIR" >&2; exit 1 ;;
esac
