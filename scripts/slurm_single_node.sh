#!/usr/bin/env bash
# Starts a single-node Slurm cluster on this machine (Debian slurm-wlm + munge), enough to run the
# sbatch --array recipe of docs/dataset.md for generate_dataset for real. Needs root. Writes its config to
# /etc/slurm/slurm.conf (this host as the controller and the only compute node, all its cores),
# starts munged, slurmctld and slurmd in the background, and waits until the node is idle.
#   scripts/slurm_single_node.sh          start;   scripts/slurm_single_node.sh stop
set -euo pipefail
if [[ ${1:-} == stop ]]; then
  pkill -x slurmd || true; pkill -x slurmctld || true; pkill -x munged || true
  exit 0
fi
[[ $(id -u) -eq 0 ]] || { echo "slurm_single_node.sh: needs root"; exit 1; }
command -v slurmctld > /dev/null || { echo "slurm_single_node.sh: install slurm-wlm and munge first"; exit 1; }
host=$(hostname -s)
cpus=$(nproc)
memory=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 1024 ))
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm /run/munge /var/lib/munge /var/log/munge
[[ -s /etc/munge/munge.key ]] || { mkdir -p /etc/munge; dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none; }
chown -R munge:munge /etc/munge /run/munge /var/lib/munge /var/log/munge 2> /dev/null || true
chmod 0700 /etc/munge; chmod 0400 /etc/munge/munge.key
cat > /etc/slurm/slurm.conf <<CONF
ClusterName=manisoft
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$host CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
pgrep -x munged > /dev/null || runuser -u munge -- munged 2> /dev/null || munged --force
pgrep -x slurmctld > /dev/null || slurmctld
pgrep -x slurmd > /dev/null || slurmd
for _ in $(seq 60); do
  if sinfo -h -o %T 2> /dev/null | grep -q idle; then
    sinfo
    exit 0
  fi
  sleep 1
done
echo "slurm_single_node.sh: the node did not become idle; see /var/log/slurm/"
sinfo || true
tail -5 /var/log/slurm/slurmctld.log /var/log/slurm/slurmd.log 2> /dev/null || true
exit 1
