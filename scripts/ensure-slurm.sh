#!/usr/bin/env bash
# A Slurm cluster on this machine for the Slurm pool's tests and for trying it out: a controller,
# the accounting daemon with MariaDB, and NODES nodes (default 5: a league-placement 2 v 2 match
# takes a simulator node and four robot nodes), each slurmd in its own network namespace with its
# own address on a private bridge. Idempotent: starts what is not running.
#   scripts/ensure-slurm.sh [up|down|status]
# Everything lives under $HLVS_SLURM_DIR (default /var/lib/hlvs/slurm); commands find the
# cluster with SLURM_CONF=$HLVS_SLURM_DIR/slurm.conf (printed by `status`). Needs root (Debian).
set -euo pipefail
DIR=${HLVS_SLURM_DIR:-/var/lib/hlvs/slurm}
NODES=${HLVS_SLURM_NODES:-5}
BRIDGE=hlvsslurm0
NET=10.77.0
CTL_IP=$NET.1
CLUSTER=hlvs
export SLURM_CONF=$DIR/slurm.conf
LOG=/var/log/hlvs
mkdir -p "$LOG"

# dpkg without an fsync per file (scripts/setup-system.sh says why)
UNSAFE_IO=-oDpkg::Options::=--force-unsafe-io

need_packages() {
  local need=()
  for pkg in slurm-wlm slurmdbd munge mariadb-server; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "ok installed" || need+=("$pkg")
  done
  if [ ${#need[@]} -gt 0 ]; then
    echo "==> installing ${need[*]} (log: $LOG/apt.log)"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $UNSAFE_IO "${need[@]}" \
      >>"$LOG/apt.log" 2>&1 || { apt-get update -qq >>"$LOG/apt.log" 2>&1;
      DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $UNSAFE_IO "${need[@]}" \
      >>"$LOG/apt.log" 2>&1; }
    systemctl disable --now slurmctld slurmd slurmdbd munge mariadb >/dev/null 2>&1 || true
  fi
}

running() { pgrep -f "$1" >/dev/null 2>&1; }

network() {
  # the host's own network namespace by name: jobs of the one-machine cluster enter it to reach
  # the Docker engine's networks (nodes of a real cluster have an engine of their own)
  if ! mountpoint -q /run/netns/hlvs-host 2>/dev/null; then
    mkdir -p /run/netns && touch /run/netns/hlvs-host
    mount --bind /proc/self/ns/net /run/netns/hlvs-host
  fi
  ip link show "$BRIDGE" >/dev/null 2>&1 || {
    ip link add "$BRIDGE" type bridge
    ip addr add "$CTL_IP/24" dev "$BRIDGE"
    ip link set "$BRIDGE" up
  }
  for n in $(seq 1 "$NODES"); do
    ip netns list | grep -qw "hlvs-n$n" || ip netns add "hlvs-n$n"
    if ! ip link show "hlvsn$n" >/dev/null 2>&1; then
      ip link add "hlvsn$n" type veth peer name eth0 netns "hlvs-n$n"
      ip link set "hlvsn$n" master "$BRIDGE" up
      ip -n "hlvs-n$n" addr add "$NET.1$n/24" dev eth0
      ip -n "hlvs-n$n" link set eth0 up
      ip -n "hlvs-n$n" link set lo up
      ip -n "hlvs-n$n" route add default via "$CTL_IP"
    fi
  done
  # node to node (a league match's robots talk to the simulator node): the bridge's frames pass
  # the host's FORWARD chain (br_netfilter), whose policy Docker sets to DROP
  iptables -C FORWARD -i "$BRIDGE" -o "$BRIDGE" -j ACCEPT 2>/dev/null || \
    iptables -I FORWARD -i "$BRIDGE" -o "$BRIDGE" -j ACCEPT
}

epilog() {
  # after every job, on each of its nodes (in the node's network namespace): remove what a match
  # of the job left there -- containers labelled with the job id, the league firewall chains and
  # the traffic shaping of the node's interface (normally removed by the match itself)
  { echo '#!/bin/sh'; echo "export SLURM_CONF=$SLURM_CONF"; cat <<'SH'; } >"$DIR/epilog.sh"
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
job=${SLURM_JOB_ID:-}
[ -n "$job" ] || exit 0
# the containers a league match placed on this node (the nodes share one Docker engine here);
# a component of a heterogeneous job has an id of its own, the containers carry the job's
het=$(scontrol show job "$job" -o 2>/dev/null | tr ' ' '\n' | sed -n 's/^HetJobId=//p')
for id in $job $het; do
  ids=$(docker ps -aq --filter "label=org.hlvs-runner.slurm-job=$id" \
    --filter "label=org.hlvs-runner.node=${SLURMD_NODENAME:-none}" 2>/dev/null)
  [ -z "$ids" ] || docker rm -f $ids >/dev/null 2>&1
done
for hook in OUTPUT:HLVS-ROBOTS INPUT:HLVS-ROBOTS-IN; do
  chain=${hook#*:}
  while iptables -w -D "${hook%%:*}" -j "$chain" 2>/dev/null; do :; done
  while iptables -w -D "${hook%%:*}" -m cgroup --path hlvs-robots -j "$chain" 2>/dev/null; do :; done
  iptables -w -F "$chain" 2>/dev/null && iptables -w -X "$chain" 2>/dev/null
done
tc qdisc show dev eth0 2>/dev/null | grep -q "qdisc htb 1:" && tc qdisc del dev eth0 root 2>/dev/null
if [ -n "${SLURMD_NODENAME:-}" ] && [ -e /run/netns/hlvs-host ]; then
  nsenter --net=/run/netns/hlvs-host tc qdisc show dev "hlvs$SLURMD_NODENAME" 2>/dev/null | \
    grep -q "qdisc htb 1:" && nsenter --net=/run/netns/hlvs-host tc qdisc del dev "hlvs$SLURMD_NODENAME" root 2>/dev/null
fi
exit 0
SH
  chmod 0755 "$DIR/epilog.sh"
}

munge_up() {
  mkdir -p /etc/munge /var/lib/munge /run/munge /var/log/munge
  [ -s /etc/munge/munge.key ] || { dd if=/dev/urandom of=/etc/munge/munge.key bs=1k count=1 2>/dev/null; }
  chown -R munge:munge /etc/munge /var/lib/munge /run/munge /var/log/munge
  chmod 0700 /etc/munge; chmod 0400 /etc/munge/munge.key
  running "/usr/sbin/munged" || su -s /bin/sh munge -c /usr/sbin/munged
}

mariadb_up() {
  mkdir -p /run/mysqld && chown mysql:mysql /run/mysqld
  if ! running mariadbd; then
    (mysqld_safe --bind-address=127.0.0.1 >>"$LOG/mariadb.log" 2>&1 &)
    for _ in $(seq 60); do mariadb -e "select 1" >/dev/null 2>&1 && break; sleep 0.5; done
  fi
  mariadb -e "CREATE DATABASE IF NOT EXISTS slurm_acct_db;
    CREATE USER IF NOT EXISTS 'slurm'@'localhost' IDENTIFIED BY 'slurm';
    GRANT ALL ON slurm_acct_db.* TO 'slurm'@'localhost'; FLUSH PRIVILEGES;"
}

configs() {
  mkdir -p "$DIR"/{state,spool,log}

  cat >"$DIR/slurmdbd.conf" <<CONF
AuthType=auth/munge
DbdHost=localhost
DbdAddr=127.0.0.1
DbdPort=6819
SlurmUser=root
StorageType=accounting_storage/mysql
StorageHost=127.0.0.1
StorageUser=slurm
StoragePass=slurm
StorageLoc=slurm_acct_db
LogFile=$DIR/log/slurmdbd.log
PidFile=$DIR/slurmdbd.pid
CONF
  chown root:root "$DIR/slurmdbd.conf"; chmod 600 "$DIR/slurmdbd.conf"
  local nodes=""
  for n in $(seq 1 "$NODES"); do
    nodes+="NodeName=n$n NodeAddr=$NET.1$n CPUs=2 RealMemory=4000 Features=dense,sim,robot State=UNKNOWN"$'\n'
  done
  before=$(cat "$DIR/slurm.conf" 2>/dev/null || true)
  cat >"$DIR/slurm.conf" <<CONF
ClusterName=$CLUSTER
SlurmctldHost=$(hostname)($CTL_IP)
SlurmctldAddr=$CTL_IP
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=cred_expire=30
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool/%n
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd-%n.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd-%n.log
SlurmctldPort=6817
SlurmdPort=6818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
SchedulerParameters=bf_interval=5
ReturnToService=2
SlurmdTimeout=10
KillWait=150
Epilog=$DIR/epilog.sh
InactiveLimit=0
MinJobAge=600
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=127.0.0.1
AccountingStoragePort=6819
AccountingStorageEnforce=associations,limits,qos
PriorityType=priority/multifactor
PriorityWeightQOS=10000
MpiDefault=none
$nodes
PartitionName=matches Nodes=ALL Default=YES MaxTime=INFINITE State=UP OverSubscribe=EXCLUSIVE
CONF
  # cred_expire: a job requeued after a node failure may start again that many seconds later
  # (Slurm's default, 120 s, is long for a match)
  [ "$before" = "$(cat "$DIR/slurm.conf")" ] || CONF_CHANGED=1
}

up() {
  need_packages
  network
  munge_up
  mariadb_up
  configs
  epilog
  pgrep -x slurmdbd >/dev/null || slurmdbd  # reads slurmdbd.conf beside $SLURM_CONF
  for _ in $(seq 60); do sacctmgr -n show cluster >/dev/null 2>&1 && break; sleep 0.5; done
  sacctmgr -i add cluster "$CLUSTER" >/dev/null 2>&1 || true
  if [ "${CONF_CHANGED:-0}" = 1 ] && running "slurmctld -f $DIR"; then
    # a changed slurm.conf (AuthInfo among others) needs a controller restart; jobs survive it
    scontrol shutdown slurmctld >/dev/null 2>&1 || true
    for _ in $(seq 60); do running "slurmctld -f $DIR" || break; sleep 0.5; done
    RECONFIGURE=1
  fi
  running "slurmctld -f $DIR" || slurmctld -f "$SLURM_CONF"
  for n in $(seq 1 "$NODES"); do
    running "slurmd -f $SLURM_CONF -N n$n" || \
      nsenter --net="/run/netns/hlvs-n$n" slurmd -f "$SLURM_CONF" -N "n$n"
  done
  for _ in $(seq 120); do
    idle=$(sinfo -h -N -t idle -o %N 2>/dev/null | wc -l)
    [ "$idle" -ge "$NODES" ] && break
    scontrol update nodename="n[1-$NODES]" state=resume >/dev/null 2>&1 || true
    sleep 0.5
  done
  if [ "${RECONFIGURE:-0}" = 1 ]; then scontrol reconfigure >/dev/null 2>&1 || true; fi
  echo "==> Slurm cluster '$CLUSTER' up: $(sinfo -h -o '%D nodes %t' | tr '\n' ' ')(SLURM_CONF=$SLURM_CONF)"
}

down() {
  pkill -f "slurmd -f $SLURM_CONF" || true
  pkill -f "slurmctld -f $SLURM_CONF" || true
  pkill -f "/usr/sbin/slurmdbd" || pkill -x slurmdbd || true
  for ns in $(ip netns list | awk '{print $1}' | grep -E '^hlvs-n[0-9]+$'); do
    ip netns del "$ns" 2>/dev/null || true
  done
  iptables -D FORWARD -i "$BRIDGE" -o "$BRIDGE" -j ACCEPT 2>/dev/null || true
  ip link del "$BRIDGE" 2>/dev/null || true
  umount /run/netns/hlvs-host 2>/dev/null && rm -f /run/netns/hlvs-host || true
}

case "${1:-up}" in
  up) up ;;
  down) down ;;
  status) sinfo -N -l; echo "SLURM_CONF=$SLURM_CONF" ;;
  *) echo "usage: $0 [up|down|status]" >&2; exit 2 ;;
esac
