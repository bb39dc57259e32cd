#!/usr/bin/env bash
# A one-node Slurm cluster on this machine for tests/farm/ (`mcctrace farm slurm --submit` for
# real), and the Open Job Description CLI those tests run templates with. Called from .ci/run;
# safe to run again (a cluster that already answers with an idle node is left alone).
#
# No systemd here: munged, slurmctld and slurmd are started in the background with a config in
# $MCCTRACE_SLURM_DIR (default /tmp/mcctrace-slurm). The tests find it there, or through
# MCCTRACE_SLURM_CONF (tests/farm/cluster.rs).
set -euo pipefail
cd "$(dirname "$0")/.."

dir="${MCCTRACE_SLURM_DIR:-/tmp/mcctrace-slurm}"
conf="$dir/slurm.conf"
export SLURM_CONF="$conf"
# Open Job Description's command line, pinned; into the checkout's venv (.ci/run makes it).
OPENJD_CLI_VERSION=0.8.0

if ! command -v slurmctld >/dev/null 2>&1 || ! command -v munged >/dev/null 2>&1; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi

[ -d .venv ] || python3 -m venv .venv
if ! .venv/bin/openjd --version 2>/dev/null | grep -q "$OPENJD_CLI_VERSION"; then
  .venv/bin/pip install --quiet "openjd-cli==$OPENJD_CLI_VERSION"
fi

node_idle() {
  sinfo --noheader --Node --format=%t 2>/dev/null | grep -qx 'idle'
}

if node_idle; then
  echo "slurm: the cluster of $conf is up, its node idle"
  exit 0
fi

# munge: its key, then the daemon (its own pid file, so only this one is stopped and restarted).
if [ ! -s /etc/munge/munge.key ]; then
  if command -v mungekey >/dev/null 2>&1; then mungekey --create --force; else create-munge-key -f; fi
fi
chown -R munge:munge /etc/munge /var/lib/munge /var/log/munge 2>/dev/null || true
mkdir -p /run/munge && chown munge:munge /run/munge
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  su -s /bin/sh munge -c munged || munged --force
  for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
fi
munge -n | unmunge >/dev/null

# Stop only the daemons an earlier run of this script started (by their pid files).
for pidfile in "$dir/slurmctld.pid" "$dir/slurmd.pid"; do
  if [ -s "$pidfile" ]; then
    kill "$(cat "$pidfile")" 2>/dev/null || true
  fi
done
sleep 1
rm -rf "$dir"
mkdir -p "$dir/state" "$dir/spool" "$dir/log"

host="$(hostname -s)"
# The node as slurmd sees this machine (CPUs, sockets, memory), so it never drains for claiming
# more than it has.
node="$(slurmd -C | head -n1 | sed "s/^NodeName=[^ ]*/NodeName=$host NodeAddr=127.0.0.1/")"
cat >"$conf" <<CONF
ClusterName=mcctrace
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
SlurmctldPort=6817
SlurmdPort=6818
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
MinJobAge=600
$node State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF

# In the background, detached from this shell, so they outlive the script.
setsid slurmctld -D -i -f "$conf" >"$dir/log/slurmctld.out" 2>&1 < /dev/null &
setsid slurmd -D -f "$conf" >"$dir/log/slurmd.out" 2>&1 < /dev/null &

for _ in $(seq 120); do
  if node_idle; then
    echo "slurm: cluster up ($conf), node $host idle"
    sinfo
    exit 0
  fi
  sleep 0.5
done
echo "slurm: the node did not become idle within 60 s; logs:" >&2
sinfo >&2 || true
tail -n 30 "$dir"/log/* >&2 || true
exit 1
