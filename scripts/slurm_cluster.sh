# shellcheck shell=bash
# A throwaway one-node Slurm cluster on this machine, for testing the
# sweep scripts: munged, slurmctld and slurmd started by hand (no systemd),
# every file — configuration, munge key, state, spool, logs, sockets —
# under one directory, on ports nobody listens on. Source it, then:
#
#   cluster_start DIR   # writes DIR/slurm.conf, starts the daemons, exports
#                       # SLURM_CONF, waits until `sinfo` shows the node idle
#   cluster_stop        # stops the daemons cluster_start started
#
# Needs root and Debian's slurm-wlm and munge packages (Slurm 22.05 here).
# The node is this machine with its real CPUs and memory (`slurmd -C`);
# jobs run as the submitting user, processes tracked by /proc
# (proctrack/linuxproc), no cgroups, no accounting.

# The daemons' process ids, for cluster_stop.
cluster_pids=()

# A TCP port on localhost that nothing listens on now.
cluster_free_port() {
    python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

# Starts munged with a fresh key; its socket is DIR/munge/munge.socket.
cluster_start_munge() {
    local dir=$1
    mkdir -p "$dir/munge"
    chmod 0700 "$dir/munge"
    dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
    chmod 0400 "$dir/munge/munge.key"
    munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
        --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
        --seed-file="$dir/munge/munged.seed"
    cluster_pids+=("$(cat "$dir/munge/munged.pid")")
}

# Writes DIR/slurm.conf for a cluster of this one machine.
cluster_write_conf() {
    local dir=$1 host
    host=$(hostname -s)
    # `slurmd -C` prints this node's line: NodeName, CPUs, sockets, cores,
    # threads, RealMemory (and an UpTime line, dropped).
    local node
    node=$(slurmd -C | grep '^NodeName=')
    mkdir -p "$dir/state" "$dir/spool" "$dir/log"
    cat >"$dir/slurm.conf" <<EOF
ClusterName=cosserat-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$(cluster_free_port)
SlurmdPort=$(cluster_free_port)
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
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SchedulerParameters=sched_interval=1
MinJobAge=600
KillWait=30
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
    export SLURM_CONF=$dir/slurm.conf
}

# Starts the cluster in DIR (an empty directory) and waits for an idle node.
cluster_start() {
    local dir=$1
    cluster_start_munge "$dir"
    cluster_write_conf "$dir"
    slurmctld -f "$SLURM_CONF"
    cluster_wait_file "$dir/slurmctld.pid" "$dir/log/slurmctld.log"
    cluster_pids+=("$(cat "$dir/slurmctld.pid")")
    slurmd -f "$SLURM_CONF"
    cluster_wait_file "$dir/slurmd.pid" "$dir/log/slurmd.log"
    cluster_pids+=("$(cat "$dir/slurmd.pid")")
    for _ in $(seq 1 60); do
        if [ "$(sinfo --noheader --format=%t 2>/dev/null)" = idle ]; then
            return 0
        fi
        sleep 0.5
    done
    echo "the node did not become idle:" >&2
    sinfo >&2 || true
    tail -n 20 "$dir/log/slurmctld.log" "$dir/log/slurmd.log" >&2
    return 1
}

# Waits for a daemon's pid file; shows its log if it never comes.
cluster_wait_file() {
    local file=$1 log=$2
    for _ in $(seq 1 40); do
        if [ -s "$file" ]; then
            return 0
        fi
        sleep 0.25
    done
    echo "no $file; the end of $log:" >&2
    tail -n 20 "$log" >&2
    return 1
}

# Stops the daemons cluster_start started (slurmd, slurmctld, munged), by
# their process ids, all at once (each takes a second or two), and waits
# for them to exit.
cluster_stop() {
    local pid
    for pid in "${cluster_pids[@]}"; do
        kill "$pid" 2>/dev/null || true
    done
    for pid in "${cluster_pids[@]}"; do
        for _ in $(seq 1 100); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.1
        done
    done
    cluster_pids=()
}
