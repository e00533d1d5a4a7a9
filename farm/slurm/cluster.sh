#!/usr/bin/env bash
# A throw-away single-node Slurm cluster for tests and trying the farm on one machine, from
# Debian's slurm-wlm + munge (slurmctld, slurmd, slurm-client, munge), as root, without systemd
# or cgroups. Everything lives under one folder: config, state, spool, logs, a private munged.
#
#   farm/slurm/cluster.sh start DIR   writes DIR/slurm.conf for this host, starts munged, slurmctld
#                                     and slurmd in the background, waits (≤ 30 s) for the node to
#                                     be idle, prints `export SLURM_CONF=DIR/slurm.conf`
#   farm/slurm/cluster.sh stop DIR    stops the three daemons by PID (and waits for them to exit)
#
# Not for production: no accounting, no cgroups (proctrack/linuxproc), root runs the jobs.
# Fails (exit 1, with the daemons' log tails) when a daemon dies or the node never becomes idle.
set -euo pipefail

cmd=${1:-}
dir=${2:-}
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)

# PID 1 in a container may not reap orphans: a zombie still answers kill -0, so "alive" is read
# from /proc/PID/stat (state Z = gone).
alive() { [ -r "/proc/$1/stat" ] && [ "$(awk '{print $3}' "/proc/$1/stat" 2>/dev/null)" != "Z" ]; }

stop() {
  for name in slurmd slurmctld munged; do
    f="$dir/$name.pid"
    [ -f "$f" ] || continue
    pid=$(cat "$f")
    if alive "$pid"; then kill "$pid" 2>/dev/null || true; fi
    for _ in $(seq 50); do alive "$pid" || break; sleep 0.1; done
    if alive "$pid"; then kill -9 "$pid" 2>/dev/null || true; fi
    rm -f "$f"
  done
}

logs() { for f in "$dir"/log/*.log; do echo "== $f" >&2; tail -n 15 "$f" >&2 || true; done; }

case "$cmd" in
  stop) stop; exit 0 ;;
  start) ;;
  *) echo "usage: $0 start|stop DIR" >&2; exit 2 ;;
esac

for exe in munged slurmctld slurmd sinfo; do
  command -v "$exe" >/dev/null || [ -x "/usr/sbin/$exe" ] ||
    { echo "$0: $exe is missing (apt-get install slurmctld slurmd slurm-client munge)" >&2; exit 1; }
done
export PATH="$PATH:/usr/sbin"
stop # a previous run's daemons in the same folder
host=$(hostname -s)
# munge's socket path must stay short (sun_path); the key must be mode 400 in a 700-free folder.
sock="$dir/munge.sock"
if [ ${#sock} -ge 100 ]; then echo "$0: $sock is too long for a socket; use a shorter DIR" >&2; exit 1; fi
mkdir -p "$dir/state" "$dir/spool" "$dir/log" "$dir/munge"
chmod 755 "$dir" "$dir/munge"
if [ ! -f "$dir/munge/munge.key" ]; then
  head -c 1024 /dev/urandom > "$dir/munge/munge.key"
  chmod 400 "$dir/munge/munge.key"
fi
# Two free TCP ports for slurmctld and slurmd (a cluster per test folder may run side by side).
read -r ctld_port d_port < <(python3 -c '
import socket
ss=[socket.socket() for _ in range(2)]
for s in ss: s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in ss])')
cpus=$(nproc)
mem=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
cat > "$dir/slurm.conf" <<EOF
# Written by farm/slurm/cluster.sh for $host (single node, throw-away).
ClusterName=dermis
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$sock,cred_expire=10
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmdParameters=config_overrides
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SwitchType=switch/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
SchedulerParameters=sched_interval=2
ReturnToService=2
MailProg=/bin/true
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=dermis Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$dir/slurm.conf"

munged --foreground --key-file="$dir/munge/munge.key" --socket="$sock" \
       --pid-file="$dir/munge/munged.pid" --log-file="$dir/log/munged.log" \
       --seed-file="$dir/munge/seed" --force >/dev/null 2>&1 &
echo $! > "$dir/munged.pid"
for _ in $(seq 50); do [ -S "$sock" ] && break; sleep 0.1; done
slurmctld -D -f "$SLURM_CONF" >"$dir/log/slurmctld.out" 2>&1 &
echo $! > "$dir/slurmctld.pid"
slurmd -D -f "$SLURM_CONF" >"$dir/log/slurmd.out" 2>&1 &
echo $! > "$dir/slurmd.pid"

for _ in $(seq 300); do
  for name in munged slurmctld slurmd; do
    if ! alive "$(cat "$dir/$name.pid")"; then
      echo "$0: $name exited" >&2; logs; stop; exit 1
    fi
  done
  state=$(sinfo -h -N -o '%T' 2>/dev/null | head -n1 || true)
  if [ "$state" = "idle" ]; then
    echo "export SLURM_CONF=$SLURM_CONF"
    exit 0
  fi
  sleep 0.1
done
echo "$0: the node did not become idle in 30 s (state '${state:-none}')" >&2
logs
stop
exit 1
