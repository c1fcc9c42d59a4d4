#!/bin/bash
# Tests yat-render.sbatch on a real Slurm: munged, slurmctld and two slurmd (this host as it is,
# and a second node on the same host) started under a temporary folder, nothing read from or
# written to /etc. See README.md ("Testing") for the configuration and why.
#
#   1. a render submitted with sbatch equals an in-process render of the same settings, byte for
#      byte;
#   2. so does the same render on two nodes (two workers), and a bidirectional one;
#   3. a job whose workers cannot start fails at once, saying so;
#   4. a longer render cancelled (scancel) once its checkpoint exists, then submitted again,
#      resumes from the checkpoint and still equals the in-process render byte for byte; the
#      job's token is in its processes' environment, on no command line;
#   5. the same render given the time-limit warning (USR1 to the batch shell) saves, requeues
#      itself, resumes in the requeued run and equals the in-process render byte for byte;
#   6. a job array of four frames, two a task, writes each frame's image under its Film
#      filename, each equal to the frame rendered alone in-process byte for byte.
#
# Needs root (it installs Debian's slurm-wlm and munge when missing, and runs the daemons):
# without root it says so and exits 77, the usual "skipped" code. Exits 0 when every check
# passed, 1 when one failed (the job logs and the daemons' logs are printed).
#
# Environment: YAT_BIN (the yat binary; default: cargo build -p yat, debug), YAT_SEED_SCENES
# (the seed project's scenes; default ../shared/seed-project/scenes beside the repository,
# else the repository's own scenes/cornell), YAT_SLURM_TEST_KEEP=1 keeps the temporary folder.
set -euo pipefail

readonly SKIPPED=77
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
batch_script=$here/yat-render.sbatch
# shellcheck source=../stop-processes.sh
source "$here/../stop-processes.sh"

now_ms() { date +%s%3N; }
test_start=$(now_ms)
# Progress goes to stderr, so that functions can return values on stdout.
say() { printf '[%6.1fs] %s\n' "$(($(now_ms) - test_start))e-3" "$*" >&2; }

# Timing of the steps: `step NAME` starts one, `step_done` prints how long it took.
step() {
    step_name=$1
    step_start=$(now_ms)
    say "$step_name ..."
}
step_done() { say "$step_name: done in $(seconds_since "$step_start") s${1:+ ($1)}"; }
seconds_since() { printf '%.1f' "$(($(now_ms) - $1))e-3"; }

if ((EUID != 0)); then
    echo "skipped: needs root (installs slurm-wlm and munge, runs munged, slurmctld and slurmd)"
    exit "$SKIPPED"
fi

passed=0
tmp=
jobs_submitted=()
daemons=()

show_logs() {
    [[ -n $tmp && -d $tmp ]] || return 0
    local file
    for file in "$tmp"/jobs/*.log "$tmp"/log/*; do
        [[ -s $file ]] || continue
        echo "----- last lines of $file"
        tail -n 40 "$file"
    done
}

fail() {
    say "FAIL: $*"
    show_logs
    echo "slurm: $passed passed, 1 failed"
    exit 1
}

pass() {
    passed=$((passed + 1))
    say "PASS: $*"
}

cleanup() {
    local status=$?
    trap - EXIT
    if ((${#jobs_submitted[@]})) && [[ -n ${SLURM_CONF:-} ]]; then
        scancel "${jobs_submitted[@]}" 2>/dev/null || true
        for job in "${jobs_submitted[@]}"; do
            wait_job_end "$job" 30 >/dev/null 2>&1 || true
        done
    fi
    # Only the daemons this script started, by their process ids.
    stop_processes 15 "${daemons[@]}"
    if [[ -n $tmp ]]; then
        if [[ ${YAT_SLURM_TEST_KEEP:-} == 1 ]]; then
            say "kept $tmp"
        else
            rm -rf "$tmp"
        fi
    fi
    exit "$status"
}
trap cleanup EXIT
trap 'fail "interrupted"' INT TERM

# ---------------------------------------------------------------------------------- tools
step "Slurm and munge"
missing=()
for tool in munged munge slurmctld slurmd sbatch srun scontrol scancel sinfo; do
    command -v "$tool" >/dev/null || missing+=("$tool")
done
if ((${#missing[@]})); then
    say "missing ${missing[*]}: installing slurm-wlm and munge"
    export DEBIAN_FRONTEND=noninteractive
    apt_log=$(mktemp /tmp/yat-slurm-test-apt.XXXXXX)
    if ! { timeout 600 apt-get update -q &&
        timeout 900 apt-get install -y -q --no-install-recommends slurm-wlm munge; } >"$apt_log" 2>&1; then
        tail -n 30 "$apt_log"
        rm -f "$apt_log"
        fail "apt-get could not install slurm-wlm and munge"
    fi
    rm -f "$apt_log"
fi
step_done "$(slurmd -V), $(munged -V 2>&1 | head -n 1)"

step "the yat binary"
if [[ -n ${YAT_BIN:-} ]]; then
    yat=$YAT_BIN
else
    (cd "$repo" && cargo build -q -p yat --locked) || fail "cargo build -p yat failed"
    yat=${CARGO_TARGET_DIR:-$repo/target}/debug/yat
fi
yat=$(realpath "$yat")
[[ -x $yat ]] || fail "no yat binary at $yat"
step_done "$yat"

seed_scenes=${YAT_SEED_SCENES:-$repo/../shared/seed-project/scenes}
scene=$seed_scenes/CornellBox/cornell-box.lxs
if [[ ! -r $scene ]]; then
    say "no seed scenes at $seed_scenes: using the repository's own Cornell box"
    scene=$repo/scenes/cornell/cornell-box.lxs
fi
scene=$(realpath "$scene")

# ---------------------------------------------------------------------------------- cluster
step "a Slurm cluster: this host, and a second slurmd on it for two-node jobs"
tmp=$(mktemp -d /tmp/yat-slurm-test.XXXXXX)
# munged wants every folder above its socket searchable by all, and its key private.
chmod 755 "$tmp"
mkdir -p "$tmp"/{munge,run,log,state,spool,jobs,work}
chmod 700 "$tmp/munge"
chmod 755 "$tmp/run"
head -c 1024 /dev/urandom >"$tmp/munge/munge.key"
chmod 600 "$tmp/munge/munge.key"

# A port nothing on this machine listens on (no connection is accepted there), below the
# kernel's ephemeral range: a port inside it can be taken as the source port of an outgoing
# connection between the probe and the bind ("address already in use", seen once).
free_port() {
    local port ephemeral_low
    ephemeral_low=$(cut -f1 /proc/sys/net/ipv4/ip_local_port_range 2>/dev/null || echo 32768)
    [ "$ephemeral_low" -gt 11000 ] 2>/dev/null || ephemeral_low=32768
    for _ in $(seq 100); do
        port=$((10000 + RANDOM % (ephemeral_low - 10000)))
        if ! (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
            echo "$port"
            return 0
        fi
    done
    fail "no free TCP port found"
}
ctld_port=$(free_port)
slurmd_port=$(free_port)
second_slurmd_port=$(free_port)
worker_port=$(free_port)

host=$(hostname -s)
# This node as slurmd sees it: its real CPUs, sockets, cores and memory.
node_line=$(slurmd -C | head -n 1)
[[ $node_line == NodeName=$host\ * ]] || fail "slurmd -C says '$node_line', not NodeName=$host"
# Node `$host` is this machine as it is; node `yatsecond`, a second slurmd on the same host
# (its own port, reached at 127.0.0.1), makes the two-node partition `two`.
# cred_expire=10: a requeued job waits cred_expire + 1 seconds before it may start again
# (default 120), and sched_interval=1 starts it within a second of that (default: the next
# full scheduling pass, up to 60 s later). proctrack/linuxproc and task/none: no cgroups.
cat >"$tmp/slurm.conf" <<EOF
ClusterName=yattest
SlurmctldHost=$host
SlurmctldPort=$ctld_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/run/munge.sock,cred_expire=10
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool/%n
SlurmctldPidFile=$tmp/run/slurmctld.pid
SlurmdPidFile=$tmp/run/slurmd-%n.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd-%n.log
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
KillWait=10
SchedulerParameters=sched_interval=1
$node_line Port=$slurmd_port State=UNKNOWN
NodeName=yatsecond NodeHostname=$host NodeAddr=127.0.0.1 Port=$second_slurmd_port CPUs=1 RealMemory=1024 State=UNKNOWN
PartitionName=one Nodes=$host Default=YES MaxTime=INFINITE State=UP
PartitionName=two Nodes=$host,yatsecond MaxTime=INFINITE State=UP
EOF

# The clients (sbatch, squeue, scontrol, and srun inside the jobs) find the cluster here; no
# variable of an enclosing Slurm job may leak in.
unset "${!SLURM_@}"
export SLURM_CONF=$tmp/slurm.conf

munged -F --key-file="$tmp/munge/munge.key" --socket="$tmp/run/munge.sock" \
    --pid-file="$tmp/run/munged.pid" --seed-file="$tmp/munge/munged.seed" \
    --log-file="$tmp/log/munged.log" >"$tmp/log/munged.out" 2>&1 &
daemons+=($!)
timeout 20 bash -c "until munge -n -S '$tmp/run/munge.sock' >/dev/null 2>&1; do sleep 0.1; done" ||
    fail "munged did not start"
slurmctld -D -f "$tmp/slurm.conf" >"$tmp/log/slurmctld.out" 2>&1 &
daemons+=($!)
for node in "$host" yatsecond; do
    slurmd -D -f "$tmp/slurm.conf" -N "$node" >"$tmp/log/slurmd-$node.out" 2>&1 &
    daemons+=($!)
done
timeout 60 bash -c "until [[ \$(sinfo -h -N -t idle -o %N | sort -u | wc -l) == 2 ]]; do sleep 0.2; done" ||
    fail "the nodes did not become idle: $(sinfo -N 2>&1)"
step_done "$node_line"

# ---------------------------------------------------------------------------------- helpers
# Submits the batch script for a render of the scene to OUTPUT ($1) with sbatch's options
# `sbatch_options`; sets `job` to its id.
sbatch_options=(--nodes=1 --exclusive)
submit() {
    job=$(cd "$tmp/work" && sbatch --parsable "${sbatch_options[@]}" \
        --output="$tmp/jobs/job-%j.log" "$batch_script" "$scene" "$@") || fail "sbatch failed"
    job=${job%%;*}
    jobs_submitted+=("$job")
}

job_field() { scontrol show job -o "$1" 2>/dev/null | grep -o "\b$2=[^ ]*" | cut -d= -f2; }

# Waits (at most $2 seconds) until job $1 has ended; prints its final state.
wait_job_end() {
    local deadline=$((SECONDS + $2)) state
    while ((SECONDS < deadline)); do
        state=$(job_field "$1" JobState)
        case $state in
        COMPLETED | FAILED | CANCELLED | TIMEOUT | NODE_FAIL | PREEMPTED | OUT_OF_MEMORY | BOOT_FAIL | DEADLINE)
            echo "$state"
            return 0
            ;;
        esac
        sleep 0.2
    done
    return 1
}

# Waits (at most $2 seconds) until file $1 exists.
wait_file() {
    timeout "$2" bash -c "until [[ -e '$1' ]]; do sleep 0.1; done"
}

# In-process reference render to $1; sets `render_time` to how long it took.
reference() {
    local out=$1 start
    shift
    start=$(now_ms)
    "$yat" render "$scene" -o "$out" --quiet --checkpoint-every 0 --preview-every 0 "$@" ||
        fail "in-process render failed"
    render_time=$(seconds_since "$start")
}

expect_same_image() {
    cmp "$1" "$2" || fail "$1 differs from the in-process render $2"
}

# ---------------------------------------------------------------------------------- 1. render
export YAT_BIN=$yat YAT_PORT=$worker_port YAT_TIMEOUT=60
# Backtraces of the errors the jobs are expected to end with would drown their logs.
unset RUST_BACKTRACE
small=(--resolution 384x216 --spp 32 --seed 0)

step "in-process render, ${small[*]}"
reference "$tmp/small-ref.png" "${small[@]}"
small_time=$render_time
step_done "render $small_time s"

step "sbatch render, ${small[*]}"
submitted=$(now_ms)
submit "$tmp/small.png" "${small[@]}"
state=$(wait_job_end "$job" 300) || fail "job $job did not end within 300 s"
sbatch_time=$(seconds_since "$submitted")
[[ $state == COMPLETED ]] || fail "job $job ended $state"
expect_same_image "$tmp/small.png" "$tmp/small-ref.png"
job_render_time=$(grep -o 'render [0-9.]* s$' "$tmp/jobs/job-$job.log" | cut -d' ' -f2)
step_done "submit to end $sbatch_time s, of which the coordinator's render $job_render_time s; in-process $small_time s"
pass "the sbatch render equals the in-process render byte for byte"

step "sbatch render on two nodes, ${small[*]}"
sbatch_options=(--partition=two --nodes=2)
submit "$tmp/small-two.png" "${small[@]}"
state=$(wait_job_end "$job" 300) || fail "job $job did not end within 300 s"
[[ $state == COMPLETED ]] || fail "job $job ended $state"
workers_used=$(grep -c '^worker .* ready' "$tmp/jobs/job-$job.log") || true
((workers_used == 2)) || fail "job $job rendered on $workers_used workers, not 2"
expect_same_image "$tmp/small-two.png" "$tmp/small-ref.png"
step_done
pass "a two-node sbatch render (two workers) equals the in-process render byte for byte"

# Bidirectional path tracing: the units' light splats land anywhere on the film and travel
# with their results.
bidirectional=(--resolution 192x108 --spp 16 --seed 0 --integrator bidirectional)
step "in-process and two-node sbatch render, ${bidirectional[*]}"
reference "$tmp/bidirectional-ref.png" "${bidirectional[@]}"
submit "$tmp/bidirectional-two.png" "${bidirectional[@]}"
state=$(wait_job_end "$job" 300) || fail "job $job did not end within 300 s"
[[ $state == COMPLETED ]] || fail "job $job ended $state"
expect_same_image "$tmp/bidirectional-two.png" "$tmp/bidirectional-ref.png"
sbatch_options=(--nodes=1 --exclusive)
step_done
pass "a two-node bidirectional sbatch render equals the in-process render byte for byte"

step "sbatch render whose workers cannot start"
# A cache folder inside a file: every worker exits at start. The job must fail soon after,
# not wait for workers for YAT_TIMEOUT (600 s here).
YAT_TIMEOUT=600 YAT_WORKER_FLAGS="--cache-dir $tmp/slurm.conf/cache" \
    submit "$tmp/no-workers.png" "${small[@]}"
state=$(wait_job_end "$job" 120) || fail "job $job without workers still runs after 120 s"
[[ $state == FAILED ]] || fail "job $job without workers ended $state"
grep -q "the workers' step ended before the render" "$tmp/jobs/job-$job.log" ||
    fail "job $job does not say its workers ended"
step_done
pass "a job whose workers cannot start fails at once"

# ---------------------------------------------------------------------------------- 2. resume
long=(--resolution 384x216 --spp 128 --seed 0)
export YAT_CHECKPOINT_EVERY=1

step "in-process render, ${long[*]}"
reference "$tmp/long-ref.png" "${long[@]}"
long_time=$render_time
step_done "render $long_time s"

# Waits until job $1 runs and its checkpoint $2 exists, then waits $3 seconds more.
wait_checkpoint() {
    wait_file "$2" 120 || fail "job $1 wrote no checkpoint $2 within 120 s ($(job_field "$1" JobState))"
    sleep "$3"
    [[ $(job_field "$1" JobState) == RUNNING ]] ||
        fail "job $1 is $(job_field "$1" JobState) before it could be stopped: make the render longer"
}

# The token of the running job's processes: the worker's and the coordinator's environments
# hold the same fresh YAT_TOKEN, and neither command line shows it.
expect_token_hidden() {
    local worker coordinator tokens
    worker=$(pgrep -f "^$yat worker --listen [^ ]*:$worker_port ") || fail "no worker process"
    coordinator=$(pgrep -f "^$yat render $scene -o $1 ") || fail "no coordinator process"
    tokens=$(for pid in $worker $coordinator; do
        tr '\0' '\n' <"/proc/$pid/environ" | grep '^YAT_TOKEN='
    done | sort -u)
    [[ $tokens =~ ^YAT_TOKEN=[0-9a-f]{64}$ ]] ||
        fail "the worker and the coordinator do not share one 256-bit YAT_TOKEN: '$tokens'"
    ! grep -qa -e --token -e "${tokens#YAT_TOKEN=}" "/proc/$worker/cmdline" \
        "/proc/$coordinator/cmdline" || fail "a command line shows the token"
}

# Sets `resumed` to the "N of M units" of job log $1's resume message, checked to be a true
# part of the render.
expect_resumed() {
    local line done_units all_units
    line=$(grep -o 'resuming from .*: [0-9]* of [0-9]* units' "$1") ||
        fail "$1 does not say it resumed"
    [[ $line =~ ([0-9]+)\ of\ ([0-9]+)\ units$ ]]
    done_units=${BASH_REMATCH[1]}
    all_units=${BASH_REMATCH[2]}
    ((done_units > 0 && done_units < all_units)) ||
        fail "resumed with $done_units of $all_units units done: not a partial render"
    resumed="$done_units of $all_units units"
}

step "sbatch render cancelled half way, then submitted again"
submit "$tmp/long.png" "${long[@]}"
wait_checkpoint "$job" "$tmp/long.resume" 0.5
expect_token_hidden "$tmp/long.png"
scancel "$job"
state=$(wait_job_end "$job" 60) || fail "cancelled job $job did not end within 60 s"
[[ $state == CANCELLED ]] || fail "cancelled job $job ended $state"
[[ -e $tmp/long.resume && ! -e $tmp/long.png ]] ||
    fail "the cancelled job left no checkpoint, or an image"
grep -q "interrupted by SIGTERM; .* kept in" "$tmp/jobs/job-$job.log" ||
    fail "job $job's coordinator did not save on SIGTERM"
submit "$tmp/long.png" "${long[@]}"
state=$(wait_job_end "$job" 300) || fail "resubmitted job $job did not end within 300 s"
[[ $state == COMPLETED ]] || fail "resubmitted job $job ended $state"
expect_resumed "$tmp/jobs/job-$job.log"
expect_same_image "$tmp/long.png" "$tmp/long-ref.png"
[[ ! -e $tmp/long.resume ]] || fail "the checkpoint outlived the finished render"
step_done "resumed with $resumed"
pass "a cancelled and resubmitted render resumes and equals the in-process render byte for byte"

# ---------------------------------------------------------------------------------- 3. requeue
step "sbatch render given the time-limit warning, requeued by itself"
submit "$tmp/requeued.png" "${long[@]}"
wait_checkpoint "$job" "$tmp/requeued.resume" 0.5
# What --signal=B:USR1@120 sends before the time limit: USR1 to the batch shell alone.
scancel --batch --signal=USR1 "$job"
timeout 60 bash -c "until [[ \$(scontrol show job -o $job | grep -o 'Restarts=[0-9]*') == Restarts=1 ]]; do sleep 0.2; done" ||
    fail "job $job was not requeued within 60 s"
state=$(wait_job_end "$job" 600) || fail "requeued job $job did not end within 600 s"
[[ $state == COMPLETED ]] || fail "requeued job $job ended $state"
expect_resumed "$tmp/jobs/job-$job.log"
expect_same_image "$tmp/requeued.png" "$tmp/long-ref.png"
step_done "resumed with $resumed"
pass "a render requeued at the time-limit warning resumes and equals the in-process render"

# ---------------------------------------------------------------------------------- 4. frames
step "a job array of four frames (the repository's Cornell box, its width changed), two a task"
frames_dir=$tmp/frames
mkdir -p "$frames_dir"
cp "$repo"/scenes/cornell/cornell-*.lxo "$frames_dir/"
for n in 1 2 3 4; do
    sed -e "s/\"string filename\" \[\"cornell-box\"\]/\"string filename\" [\"frame.000$n\"]/" \
        -e "s/\"integer xresolution\" \[512\] \"integer yresolution\" \[512\]/\"integer xresolution\" [$((40 + 8 * n))] \"integer yresolution\" [48]/" \
        "$repo/scenes/cornell/cornell-box.lxs" >"$frames_dir/frame$n.lxs"
    grep -q "frame.000$n" "$frames_dir/frame$n.lxs" && grep -q "\[$((40 + 8 * n))\]" "$frames_dir/frame$n.lxs" ||
        fail "frame $n: the Cornell box's Film is not as this test expects"
    "$yat" render "$frames_dir/frame$n.lxs" -o "$frames_dir/alone$n.png" --spp 16 --quiet \
        --checkpoint-every 0 --preview-every 0 || fail "in-process render of frame $n failed"
done
printf '%s\n' "$frames_dir"/frame{1,2,3,4}.lxs >"$frames_dir/frames.txt"
job=$(cd "$tmp/work" && YAT_FRAMES_PER_TASK=2 sbatch --parsable --nodes=1 --exclusive --array=0-1 \
    --output="$tmp/jobs/job-%A_%a.log" "$batch_script" "$frames_dir/frames.txt" "$frames_dir/out" \
    --spp 16) || fail "sbatch --array failed"
job=${job%%;*}
jobs_submitted+=("$job")
for task in 0 1; do
    state=$(wait_job_end "${job}_$task" 300) || fail "array task ${job}_$task did not end within 300 s"
    [[ $state == COMPLETED ]] || fail "array task ${job}_$task ended $state"
done
for n in 1 2 3 4; do
    expect_same_image "$frames_dir/out/frame.000$n.png" "$frames_dir/alone$n.png"
done
grep -q "rendering frames 1 to 2 of" "$tmp/jobs/job-${job}_0.log" &&
    grep -q "rendering frames 3 to 4 of" "$tmp/jobs/job-${job}_1.log" ||
    fail "the array tasks did not take frames 1-2 and 3-4"
step_done
pass "a job array renders each task's frames, each equal to the frame rendered alone byte for byte"

say "all done in $(seconds_since "$test_start") s"
echo "slurm: $passed passed, 0 failed"
