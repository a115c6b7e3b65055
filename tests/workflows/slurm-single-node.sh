#!/usr/bin/env bash
# A single-node Slurm cluster on this machine for the workflow tests, in folder DIR:
#   slurm-single-node.sh start DIR   writes DIR/slurm.conf, starts munged (if none runs), slurmctld
#                                    and slurmd, waits until the node is idle; prints the
#                                    SLURM_CONF line to export
#   slurm-single-node.sh stop DIR    stops the daemons it started
# Needs root (the daemons run as root here) and Debian's slurm-wlm and munge. Ports 16817/16818,
# apart from a system Slurm's defaults.
set -euo pipefail
action=${1:?start|stop}
dir=$(realpath -m "${2:?folder}")
node=$(hostname -s)
conf="$dir/slurm.conf"

write_conf() {
  mkdir -p "$dir/state" "$dir/spool"
  cat >"$conf" <<CONF
ClusterName=imscal-test
SlurmctldHost=$node
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$node CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
}

start_munge() {
  if munge -n >/dev/null 2>&1; then return; fi  # a munged answers already
  [ -f /etc/munge/munge.key ] || mungekey --create --keyfile /etc/munge/munge.key
  chown munge:munge /etc/munge/munge.key 2>/dev/null || true
  mkdir -p /run/munge && chown munge:munge /run/munge 2>/dev/null || true
  if id munge >/dev/null 2>&1; then
    runuser -u munge -- munged
  else
    munged --force
  fi
  touch "$dir/started-munged"
}

wait_for_idle_node() {
  for _ in $(seq 1 60); do
    state=$(SLURM_CONF="$conf" timeout 5 sinfo -h -o %t 2>/dev/null | head -1 || true)
    case "$state" in idle | mix) return 0 ;; esac
    sleep 1
  done
  echo "slurm-single-node: the node did not become idle (state '$state'); logs in $dir" >&2
  tail -n 20 "$dir/slurmctld.log" "$dir/slurmd.log" >&2 || true
  return 1
}

case "$action" in
  start)
    mkdir -p "$dir"
    write_conf
    start_munge
    SLURM_CONF="$conf" slurmctld -f "$conf" -i
    SLURM_CONF="$conf" slurmd -f "$conf"
    wait_for_idle_node
    echo "export SLURM_CONF=$conf"
    ;;
  stop)
    for pid_file in "$dir/slurmd.pid" "$dir/slurmctld.pid"; do
      [ -f "$pid_file" ] && kill "$(cat "$pid_file")" 2>/dev/null || true
    done
    if [ -f "$dir/started-munged" ]; then pkill -x munged || true; fi
    ;;
  *) echo "usage: $0 start|stop DIR" >&2; exit 2 ;;
esac
