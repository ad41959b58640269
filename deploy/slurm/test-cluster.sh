#!/usr/bin/env bash
# Runs the Slurm scripts of this folder for real, on a one-node Slurm cluster on this machine:
# installs Slurm and munge from Debian's packages if they are missing, starts munged,
# slurmctld and slurmd from a temporary folder, renders a small frame as 4 parts plus a merge
# and checks the merged EXR is byte-identical to a single-process render, then runs a sweep
# (cells plus assemble) and checks the grid is a PNG. Stops what it started and removes its
# temporary folder on exit, whatever happened.
#
#   deploy/slurm/test-cluster.sh          # after cargo build --release; as root (Debian 12)
#
# Environment: FOTON (default target/release/foton of this repository), FOTON_TEST_TIMEOUT
# (seconds to wait for each group of jobs, default 600), FOTON_SLURM_PORT (slurmctld's port,
# default 16817; slurmd gets the next one), FOTON_TEST_KEEP=1 keeps the temporary folder.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
foton=${FOTON:-$repo/target/release/foton}
timeout=${FOTON_TEST_TIMEOUT:-600}
ctld_port=${FOTON_SLURM_PORT:-16817}
scene=$repo/scenes/cornell-box.toml
# Small and quick: the test is about the plumbing, not the picture.
render_args=(--set film.width=64 --set film.height=64 --spp 4 --seed 11)
parts=4
# The daemons live in /usr/sbin, which a CI user's PATH may lack.
export PATH=$PATH:/usr/sbin:/sbin
# Every Slurm command below must talk to this test's cluster, never to one SLURM_CONF names
# already (the cleanup cancels jobs).
unset SLURM_CONF

start=$SECONDS
log() { echo "[test-cluster $((SECONDS - start))s] $*" >&2; }
fail() {
    echo "test-cluster: FAILED: $*" >&2
    show_logs
    exit 1
}

[[ $(id -u) -eq 0 ]] || { echo "test-cluster: must run as root (apt-get, SlurmUser=root)" >&2; exit 2; }
[[ -x $foton ]] || { echo "test-cluster: no $foton: run cargo build --release first" >&2; exit 2; }

# --- Install ---------------------------------------------------------------------------------

policy_rc=/usr/sbin/policy-rc.d
made_policy_rc=
install_packages() {
    # The packages' maintainer scripts would start the system's own munge and Slurm daemons
    # (with /etc configs) where there is an init system to start them: a policy-rc.d that
    # refuses keeps them off, so the only daemons are this test's. Only if the machine has no
    # policy of its own.
    if [[ ! -e $policy_rc ]]; then
        printf '#!/bin/sh\nexit 101\n' >"$policy_rc"
        chmod 755 "$policy_rc"
        made_policy_rc=1
    fi
    local packages=(slurm-wlm munge) apt=(apt-get -y -qq -o Dpkg::Use-Pty=0 install --no-install-recommends)
    # A fresh machine may have no package lists (or stale ones): update only when needed.
    DEBIAN_FRONTEND=noninteractive "${apt[@]}" "${packages[@]}" ||
        { apt-get -qq update && DEBIAN_FRONTEND=noninteractive "${apt[@]}" "${packages[@]}"; }
    remove_policy_rc
}
remove_policy_rc() {
    if [[ -n $made_policy_rc ]]; then
        rm -f "$policy_rc"
        made_policy_rc=
    fi
}

# --- Start and stop --------------------------------------------------------------------------

tmp=
pids=()
cluster_started=
show_logs() {
    [[ -n $tmp && -d $tmp ]] || return 0
    local f
    # The jobs' own output first: a failed part says why there.
    for f in "$tmp"/out/*/logs/* "$tmp"/daemon-*.out; do
        [[ -s $f ]] || continue
        echo "----- ${f#"$tmp"/} (last 25 lines)" >&2
        tail -n 25 "$f" >&2
    done
    if [[ -n $cluster_started ]]; then
        echo "----- jobs (scontrol show job)" >&2
        scontrol show job -o 2>&1 | awk '{
            line = ""
            for (i = 1; i <= NF; i++)
                if ($i ~ /^(JobId|ArrayTaskId|JobName|JobState|Reason|ExitCode)=/) line = line " " $i
            print line
        }' | head -40 >&2 || true
    fi
}
cleanup() {
    local rc=$? i pid
    set +e
    # Jobs first, while slurmd is there to end their steps: stopping the daemons under running
    # jobs would leave slurmstepd processes behind. Bounded: a controller that no longer
    # answers must not hang the exit.
    if [[ -n $cluster_started ]]; then
        timeout 10 scancel --user=root >/dev/null 2>&1
        for ((i = 0; i < 20; i++)); do
            [[ -z $(timeout 5 squeue -h 2>/dev/null) ]] && break
            sleep 0.5
        done
    fi
    for pid in "${pids[@]}"; do
        kill "$pid" 2>/dev/null
    done
    for pid in "${pids[@]}"; do
        # A daemon that ignores SIGTERM for 10 s is killed.
        for ((i = 0; i < 20; i++)); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.5
        done
        kill -KILL "$pid" 2>/dev/null
        wait "$pid" 2>/dev/null
    done
    remove_policy_rc
    if [[ -n $tmp ]]; then
        if [[ -n ${FOTON_TEST_KEEP:-} ]]; then
            echo "test-cluster: kept $tmp" >&2
        else
            rm -rf "$tmp"
        fi
    fi
    exit "$rc"
}
trap cleanup EXIT
# Ctrl-C and kill go through the same cleanup (the EXIT trap runs on exit).
trap 'exit 130' INT
trap 'exit 143' TERM

# Waits until COMMAND (a function or command) succeeds, up to SECONDS; fails with WHAT.
wait_for() {
    local seconds=$1 what=$2
    shift 2
    local deadline=$((SECONDS + seconds))
    until "$@"; do
        ((SECONDS < deadline)) || fail "$what: not done after $seconds s"
        sleep 0.5
    done
}

needed=(munged mungekey slurmctld slurmd sbatch squeue sinfo scontrol scancel)
missing=()
for c in "${needed[@]}"; do
    command -v "$c" >/dev/null || missing+=("$c")
done
tmp=$(mktemp -d /tmp/foton-slurm.XXXXXX)
# munged wants its socket's folders searchable by everyone (its clients may be any user) and
# writable by nobody else; mktemp's 0700 is refused.
chmod 0755 "$tmp"
mkdir -p "$tmp"/{munge,slurm/state,slurm/spool,etc,out}

if [[ ${#missing[@]} -gt 0 ]]; then
    log "installing slurm-wlm and munge (missing: ${missing[*]})"
    install_packages >"$tmp/apt.log" 2>&1 || { cat "$tmp/apt.log" >&2; fail "cannot install slurm-wlm and munge"; }
fi
log "$(slurmctld -V), $(munged --version 2>&1 | awk '{print $1; exit}')"

# --- munge: its own key, socket and files, so that a munged of the machine (if any) is left
# alone and this one needs nothing in /etc, /run or /var.
munge_socket=$tmp/munge/munge.socket
mungekey --create --keyfile="$tmp/munge/munge.key" --force
chmod 0400 "$tmp/munge/munge.key"
munged --foreground --socket="$munge_socket" --key-file="$tmp/munge/munge.key" \
    --log-file="$tmp/munge/munged.log" --pid-file="$tmp/munge/munged.pid" \
    --seed-file="$tmp/munge/munged.seed" >"$tmp/daemon-munged.out" 2>&1 &
pids+=($!)
wait_for 20 "munged to create its socket" test -S "$munge_socket"

# --- slurm.conf -------------------------------------------------------------------------------
# The node is this machine under its short hostname (what slurmd calls itself), reached at
# 127.0.0.1 so that the hostname need not resolve. Its CPUs and memory are what slurmd
# detects (slurmd -C): a node configured with more than it has is drained as invalid.
node=$(hostname -s)
# slurmd -C: "NodeName=vm CPUs=2 Boards=1 SocketsPerBoard=1 CoresPerSocket=2 ThreadsPerCore=1
# RealMemory=24105"; the topology too, or slurmd logs that it had to reconfigure it.
hw=$(slurmd -C | head -n 1)
hw=${hw#NodeName=* }
cpus=$(sed -n 's/.*CPUs=\([0-9]*\).*/\1/p' <<<"$hw")
memory=$(sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' <<<"$hw")
[[ -n $cpus && -n $memory ]] || fail "cannot read CPUs and RealMemory from slurmd -C: $hw"
export SLURM_CONF=$tmp/etc/slurm.conf
cat >"$SLURM_CONF" <<CONF
# One-node cluster of deploy/slurm/test-cluster.sh (written on $(date -u +%FT%TZ)).
ClusterName=foton-test
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$((ctld_port + 1))
# Everything as root: the test runs as root and needs no slurm user.
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$munge_socket
StateSaveLocation=$tmp/slurm/state
SlurmdSpoolDir=$tmp/slurm/spool
SlurmctldPidFile=$tmp/slurm/slurmctld.pid
SlurmdPidFile=$tmp/slurm/slurmd.pid
SlurmctldDebug=info
SlurmdDebug=info
# No cgroups: Slurm's default proctrack/cgroup needs a cgroup tree slurmd may manage, which a
# container or a CI machine does not give (the first job then fails with "Plugin
# initialization failed" and drains the node). No accounting database either.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
# A node that comes back registers as usable instead of staying down.
ReturnToService=2
MailProg=/bin/true
# Jobs end in seconds: look again soon rather than every minute.
SchedulerParameters=sched_min_interval=100000
NodeName=$node NodeAddr=127.0.0.1 $hw State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF

# A daemon left over from a run that was killed outright (no EXIT trap) holds the ports: say
# so now rather than after the wait for the node.
for port in "$ctld_port" "$((ctld_port + 1))"; do
    if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
        fail "port $port is in use (a slurmctld or slurmd of an earlier run?); set FOTON_SLURM_PORT to another"
    fi
done
log "starting slurmctld and slurmd on $node ($cpus CPUs, $memory MB, port $ctld_port)"
# In the foreground (-D) of a background job: their pids are ours to stop, and without a
# LogFile they log to these files.
slurmctld -D -i >"$tmp/daemon-slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -N "$node" >"$tmp/daemon-slurmd.out" 2>&1 &
pids+=($!)
cluster_started=1
node_idle() {
    [[ $(sinfo -h -N -n "$node" -o %T 2>/dev/null) == idle ]]
}
wait_for 60 "the node to be idle in sinfo" node_idle
log "node $node idle"

# --- Jobs ------------------------------------------------------------------------------------

# The state of job ID (the last task's, for an array), from scontrol: there is no accounting
# database for sacct. Completed jobs stay visible for MinJobAge (300 s).
job_state() {
    scontrol show job -o "$1" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | tail -n 1
}
# Waits until job ID has ended; fails unless it COMPLETED (a failed part cancels the merge:
# --kill-on-invalid-dep).
wait_job() {
    local id=$1 what=$2 state node_state deadline=$((SECONDS + timeout))
    while :; do
        state=$(job_state "$id")
        case $state in
        COMPLETED) return 0 ;;
        PENDING | CONFIGURING | RUNNING | COMPLETING | SUSPENDED | "") ;;
        *) fail "$what (job $id) ended $state: $(scontrol show job -o "$id" 2>&1 | grep -o 'Reason=[^ ]*' | sort -u | tr '\n' ' ')" ;;
        esac
        ((SECONDS < deadline)) || fail "$what (job $id) not done after $timeout s (state ${state:-unknown})"
        # A job that cannot start on this node (a plugin that fails, for one) drains it: the
        # jobs would then wait for the timeout.
        node_state=$(sinfo -h -N -n "$node" -o %T 2>/dev/null)
        case $node_state in
        drain* | down* | fail* | inval*)
            fail "node $node is $node_state: $(sinfo -h -N -n "$node" -o %E 2>/dev/null)" ;;
        esac
        sleep 0.5
    done
}
# Every task of array job ID completed, with exit code 0.
check_array() {
    local id=$1 what=$2 bad
    bad=$(scontrol show job -o "$1" | grep -v 'JobState=COMPLETED .*ExitCode=0:0' || true)
    [[ -z $bad ]] || fail "$what: tasks of job $id did not all complete: $bad"
}

frame=$tmp/out/frame
jobs=$("$here/submit-frame.sh" --foton "$foton" "$scene" "$parts" "$frame" -- "${render_args[@]}") ||
    fail "submit-frame.sh failed"
read -r parts_job merge_job <<<"$jobs"
log "frame: $parts parts as job $parts_job, merge job $merge_job"
wait_job "$merge_job" "merge"
check_array "$parts_job" "frame parts"
log "frame merged: $(cat "$frame"/logs/merge-*.out)"

"$foton" render "$scene" "${render_args[@]}" -o "$tmp/single.exr" -q 2>/dev/null ||
    fail "the single-process render failed"
cmp "$frame/frame.exr" "$tmp/single.exr" ||
    fail "the merged frame differs from the single-process render"
log "merged frame == single-process render ($(stat -c %s "$tmp/single.exr") bytes, cmp)"

sweep=$tmp/out/sweep
jobs=$("$here/submit-sweep.sh" --foton "$foton" "$scene" "$sweep" -- \
    --set render.spp=1,4 --set film.exposure=0,1 --set film.width=48 --set film.height=48) ||
    fail "submit-sweep.sh failed"
read -r cells_job assemble_job <<<"$jobs"
log "sweep: cells job $cells_job, assemble job $assemble_job"
wait_job "$assemble_job" "assemble"
check_array "$cells_job" "sweep cells"
cells=$(find "$sweep/cells" -name 'cell-*.exr' | wc -l)
[[ $cells -eq 4 ]] || fail "expected 4 cell files, found $cells: $(ls "$sweep/cells")"
[[ -s $sweep/sweep.png ]] || fail "no grid $sweep/sweep.png"
# A PNG starts with its 8-byte signature \x89 P N G \r \n \x1a \n.
[[ $(head -c 8 "$sweep/sweep.png" | od -An -tx1 | tr -d ' \n') == 89504e470d0a1a0a ]] ||
    fail "$sweep/sweep.png is not a PNG"
log "sweep assembled: $cells cells -> sweep.png ($(stat -c %s "$sweep/sweep.png") bytes)"

log "PASSED in $((SECONDS - start)) s"
# The closing line CI reads as a test count: the frame and the sweep.
echo "test-cluster: 2 passed, 0 failed"
