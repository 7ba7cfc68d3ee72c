# A real single-node Slurm for the cluster tests (sourced by .ci/slurm/test.sh): Debian's slurm-wlm
# and munge, installed when missing, and munged, slurmctld and slurmd started on this host with
# a generated slurm.conf. `cluster_up DIR` starts them (their state, logs and PIDs in DIR) and
# exports SLURM_CONF (CLUSTER_MAX_ARRAY_SIZE sets its MaxArraySize, default Slurm's 1001);
# `cluster_down` stops them by their PIDs.

cluster_install() {
    if command -v slurmctld >/dev/null && command -v slurmd >/dev/null &&
        command -v sbatch >/dev/null && command -v munged >/dev/null; then
        return 0
    fi
    local packages="slurm-wlm munge"
    { apt-get install -y -qq --no-install-recommends $packages ||
        { apt-get update -qq && apt-get install -y -qq --no-install-recommends $packages; }; } \
        >/dev/null || {
        echo "ci: could not install $packages with apt-get (root and Debian's archive are needed)" >&2
        return 1
    }
}

cluster_up() {
    local dir=$1
    mkdir -p "$dir"/{state,spool,log,munge}
    CLUSTER_DIR=$dir
    local host cpus mem
    host=$(hostname -s)
    cpus=$(nproc)
    # What slurmd may hand out: the machine's memory less 2 GiB for everything else.
    mem=$(($(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo) - 2048))
    # munged: its own socket, key and PID file under DIR (no system service needed).
    if [ ! -s /etc/munge/munge.key ]; then
        mkdir -p /etc/munge
        dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 2>/dev/null
    fi
    cp /etc/munge/munge.key "$dir/munge/munge.key"
    chmod 700 "$dir/munge"
    chmod 400 "$dir/munge/munge.key"
    munged --force --socket="$dir/munge/munge.socket" --key-file="$dir/munge/munge.key" \
        --pid-file="$dir/munge/munged.pid" --log-file="$dir/log/munged.log" \
        --seed-file="$dir/munge/munged.seed"
    cat >"$dir/slurm.conf" <<EOF
ClusterName=ci
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
JobRequeue=1
KillWait=30
MinJobAge=600
MaxArraySize=${CLUSTER_MAX_ARRAY_SIZE:-1001}
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=ci Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
    export SLURM_CONF=$dir/slurm.conf
    slurmctld -i -f "$SLURM_CONF"
    slurmd -f "$SLURM_CONF"
    local i
    for i in $(seq 1 60); do
        if sinfo -h -o '%t' 2>/dev/null | grep -qE '^(idle|mix|alloc)'; then
            return 0
        fi
        sleep 0.5
    done
    echo "ci: the Slurm node did not come up; its logs:" >&2
    tail -n 20 "$dir"/log/*.log >&2
    return 1
}

cluster_down() {
    local dir=${CLUSTER_DIR:-}
    [ -n "$dir" ] || return 0
    local pidfile
    for pidfile in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
        [ -s "$pidfile" ] && kill "$(cat "$pidfile")" 2>/dev/null || true
    done
    CLUSTER_DIR=
}
