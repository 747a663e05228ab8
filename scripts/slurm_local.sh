#!/usr/bin/env bash
# A single-node Slurm cluster on this machine, for `ademono batch --engine slurm`'s test and for
# demos: munge, slurmctld and slurmd from Debian's packages (slurm-wlm, munge; scripts/setup.sh
# installs them), configured for this host only (127.0.0.1), one partition `local` with every CPU.
#
#   scripts/slurm_local.sh start    start what is not running (idempotent); returns when the node
#                                   takes jobs
#   scripts/slurm_local.sh stop     cancel every job, stop the daemons it started, wait until
#                                   none is left (idempotent)
#   scripts/slurm_local.sh status   what runs; exit 0 when the cluster takes jobs, 3 otherwise
#
# Runs as root (the daemons need it). It writes /etc/slurm/slurm.conf (where sbatch, squeue and
# scancel look) and refuses to touch one it did not write; its state, logs and pid files live in
# $ADEMONO_SLURM_STATE (default /var/lib/ademono-slurm). A real cluster needs none of this:
# docs/batch.md.
set -euo pipefail

state="${ADEMONO_SLURM_STATE:-/var/lib/ademono-slurm}"
conf=/etc/slurm/slurm.conf
marker="# Written by ademono scripts/slurm_local.sh: a one-node cluster for tests and demos."
munge_socket=/run/munge/munge.socket.2

die() { echo "slurm_local.sh: $*" >&2; exit 2; }

pid_alive() {  # pid file -> 0 when the process in it runs (readable without root)
  [ -f "$1" ] && [ -d "/proc/$(cat "$1")" ]
}

check_tools() {
  [ "$(id -u)" = 0 ] || die "must run as root (the Slurm and munge daemons need it)"
  local p
  for p in munged slurmctld slurmd sbatch squeue scancel sinfo scontrol; do
    command -v "$p" >/dev/null || [ -x "/usr/sbin/$p" ] ||
      die "$p not found: install Debian's slurm-wlm and munge (scripts/setup.sh does)"
  done
}

check_conf_is_ours() {
  if [ -f "$conf" ] && ! head -1 "$conf" | grep -qF "$marker"; then
    die "$conf was not written by this script: a Slurm is configured here already, use it"
  fi
}

write_conf() {
  local host node_line
  host="$(hostname -s)"
  # The node as slurmd measures it (CPUs, sockets, cores, memory), under our node name.
  node_line="$(/usr/sbin/slurmd -C | head -1 | sed -E "s/^NodeName=[^ ]+/NodeName=$host NodeAddr=127.0.0.1/")"
  mkdir -p /etc/slurm "$state/ctld" "$state/d" "$state/log" "$state/run"
  cat >"$conf.tmp.$$" <<EOF
$marker
ClusterName=ademono-local
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
# Short runs: schedule every second rather than every 30-60 s (the defaults suit big clusters).
SchedulerParameters=bf_interval=1,sched_interval=1
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
KillWait=10
MinJobAge=60
SlurmctldPort=6817
SlurmdPort=6818
StateSaveLocation=$state/ctld
SlurmdSpoolDir=$state/d
SlurmctldPidFile=$state/run/slurmctld.pid
SlurmdPidFile=$state/run/slurmd.pid
SlurmctldLogFile=$state/log/slurmctld.log
SlurmdLogFile=$state/log/slurmd.log
$node_line State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  mv "$conf.tmp.$$" "$conf"
}

munge_works() { munge -n --socket="$munge_socket" 2>/dev/null | unmunge --socket="$munge_socket" >/dev/null 2>&1; }

start_munge() {
  if munge_works; then return; fi
  [ -f /etc/munge/munge.key ] || { mungekey --create >/dev/null 2>&1 || die "cannot create /etc/munge/munge.key"; }
  chown munge:munge /etc/munge/munge.key
  chmod 0400 /etc/munge/munge.key
  install -d -o munge -g munge -m 0755 /run/munge
  install -d -o munge -g munge -m 0700 /var/lib/munge /var/log/munge
  runuser -u munge -- /usr/sbin/munged --socket="$munge_socket" --pid-file=/run/munge/munged.pid
  # Ours to stop: stop leaves a munged it did not start alone.
  cp /run/munge/munged.pid "$state/run/munged.pid"
  local i
  for i in $(seq 50); do munge_works && return; sleep 0.1; done
  die "munged did not start (see /var/log/munge/munged.log)"
}

node_ready() {
  local s
  s="$(sinfo -h -o %T 2>/dev/null | head -1)" || return 1
  case "$s" in idle|mixed|allocated|completing) return 0 ;; *) return 1 ;; esac
}

start() {
  check_tools
  check_conf_is_ours
  mkdir -p "$state/run"
  if pid_alive "$state/run/slurmctld.pid" && pid_alive "$state/run/slurmd.pid" && node_ready; then
    echo "slurm_local.sh: already running (partition local on $(hostname -s))"
    return
  fi
  write_conf
  start_munge
  pid_alive "$state/run/slurmctld.pid" || /usr/sbin/slurmctld
  pid_alive "$state/run/slurmd.pid" || /usr/sbin/slurmd
  local i
  for i in $(seq 150); do
    if node_ready; then
      echo "slurm_local.sh: running: partition local, $(sinfo -h -o '%c CPUs, %m MB' | head -1) on $(hostname -s)"
      return
    fi
    # A node left DOWN by an earlier unclean stop comes back once asked.
    [ "$i" = 20 ] && scontrol update nodename="$(hostname -s)" state=resume >/dev/null 2>&1 || true
    sleep 0.2
  done
  echo "slurm_local.sh: the node did not come up; logs:" >&2
  tail -n 5 "$state/log/slurmctld.log" "$state/log/slurmd.log" >&2 || true
  stop
  exit 1
}

stop_daemon() {  # name pidfile
  local pidfile="$2" pid i
  [ -f "$pidfile" ] || return 0
  pid="$(cat "$pidfile")"
  if kill -0 "$pid" 2>/dev/null; then
    kill -TERM "$pid" 2>/dev/null || true
    for i in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    if kill -0 "$pid" 2>/dev/null; then
      echo "slurm_local.sh: $1 ($pid) did not stop on SIGTERM; killing it" >&2
      kill -KILL "$pid" 2>/dev/null || true
    fi
  fi
  rm -f "$pidfile"
}

# The job step daemons of this cluster (they outlive slurmd): their pids, from the process table.
stepds() {
  local p
  for p in /proc/[0-9]*; do
    [ "$(cat "$p/comm" 2>/dev/null)" = slurmstepd ] && echo "${p#/proc/}"
  done
  return 0
}

stop() {
  if [ "$(id -u)" != 0 ]; then
    # Nothing of ours runs: nothing to do (CTest's clean-up step runs this for every user).
    if ! pid_alive "$state/run/slurmctld.pid" && ! pid_alive "$state/run/slurmd.pid" &&
      ! pid_alive "$state/run/munged.pid"; then
      echo "slurm_local.sh: not running"
      return
    fi
    die "must run as root"
  fi
  check_conf_is_ours
  local i jobs
  if pid_alive "$state/run/slurmctld.pid"; then
    jobs="$(squeue -h -o %A 2>/dev/null || true)"
    # shellcheck disable=SC2086
    [ -z "$jobs" ] || scancel $jobs 2>/dev/null || true
    for i in $(seq 150); do
      [ -z "$(squeue -h -o %A 2>/dev/null || true)" ] && break
      sleep 0.2
    done
  fi
  stop_daemon slurmd "$state/run/slurmd.pid"
  stop_daemon slurmctld "$state/run/slurmctld.pid"
  # Steps of jobs that did not end (their slurmd is gone): stop them too.
  for i in $(seq 50); do [ -z "$(stepds)" ] && break; sleep 0.2; done
  for i in $(stepds); do kill -KILL "$i" 2>/dev/null || true; done
  stop_daemon munged "$state/run/munged.pid"
  [ -f "$conf" ] && rm -f "$conf"
  echo "slurm_local.sh: stopped"
}

status() {
  local up=0 name
  for name in munged slurmctld slurmd; do
    if pid_alive "$state/run/$name.pid"; then
      echo "$name: running (pid $(cat "$state/run/$name.pid"))"
    elif [ "$name" = munged ] && munge_works; then
      echo "munged: running (not started by this script)"
    else
      echo "$name: not running"
      up=3
    fi
  done
  if [ "$up" = 0 ] && node_ready; then
    sinfo
  else
    up=3
  fi
  return "$up"
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  status) status ;;
  *) echo "usage: scripts/slurm_local.sh start|stop|status" >&2; exit 2 ;;
esac
