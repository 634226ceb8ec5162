#!/bin/bash
# The Slurm scripts under a real Slurm (issue 19, item 7): on a one-node
# cluster started here (scripts/slurm_cluster.sh), the shipped Fig. 6 sweep
# (problems/longest_arm_fig6.toml on a small grid, 4 lines of 10 points,
# with a cheap search) runs as a 4-task job array of scripts/slurm_sweep.sh,
# with the merge job of scripts/slurm_merge.sh depending on it. Midway
# through one task, once its log shows progress, the task is cancelled
# (`scancel`, SIGTERM); it is resubmitted alone with the same arguments,
# the merge job is pointed at the resubmitted task, and the test checks:
#
#   - the killed task's log has progress lines (a cluster log shows the run
#     is alive) and its shard file holds some, not all, of its points, and
#     the merge job waits; slurm_merge.sh refuses (exit 1) to merge it, or
#     a set without it;
#   - the resumed task reports those points as done and computes only the
#     others (`resume    K finished points`, `time ... for M points`,
#     K + M = the shard's points): no finished point is redone;
#   - the merge job completes, and its file equals a single-process run of
#     the same sweep (`cosserat sweep` without Slurm, 2 threads) dataset by
#     dataset, bit for bit, read by h5py (scripts/same_hdf5.py), except the
#     root attribute `shard` (`merged` against `0/1`).
#
# Run from the repository root, as root (it installs slurm-wlm, munge and
# python3-h5py with apt-get when they are missing, and runs the daemons):
#
#   scripts/slurm_test.sh            # builds target/release/cosserat
#   COSSERAT=path/to/cosserat scripts/slurm_test.sh
#
# Exit 0 only when everything holds. The working directory (logs, shard
# files, the cluster's files) is removed on success (kept with
# SLURM_TEST_KEEP=1), kept on failure. It takes about a minute (40 s of it
# the sweeps), plus about 30 s when it installs the packages.

set -euo pipefail
start=$SECONDS
repo=$(pwd)
if [ ! -f "$repo/scripts/slurm_sweep.sh" ]; then
    echo "slurm_test.sh: run it from the repository root" >&2
    exit 2
fi
if [ "$(id -u)" != 0 ]; then
    echo "slurm_test.sh: run it as root (it installs packages and starts munged, slurmctld, slurmd)" >&2
    exit 2
fi
python=/usr/bin/python3

say() { printf '== %s [%d s]\n' "$*" "$((SECONDS - start))"; }
fail() {
    echo "FAIL: $*" >&2
    exit 1
}

# --- what the test needs --------------------------------------------------

install_tools() {
    if command -v slurmctld >/dev/null && command -v munged >/dev/null &&
        "$python" -c 'import h5py' 2>/dev/null; then
        return
    fi
    say "installing slurm-wlm, munge, python3-h5py"
    local log
    log=$(mktemp)
    if ! (export DEBIAN_FRONTEND=noninteractive && apt-get update -qq &&
        apt-get install -y -qq --no-install-recommends slurm-wlm munge python3-h5py) >"$log" 2>&1; then
        tail -n 20 "$log" >&2
        fail "apt-get install slurm-wlm munge python3-h5py failed"
    fi
    rm -f "$log"
}

find_binary() {
    if [ -z "${COSSERAT:-}" ]; then
        say "cargo build --release -p cosserat-cli"
        cargo build --release -q -p cosserat-cli
        COSSERAT=$repo/target/release/cosserat
    fi
    COSSERAT=$(realpath "$COSSERAT")
    [ -x "$COSSERAT" ] || fail "no cosserat binary at $COSSERAT"
    export COSSERAT
}

# --- the cluster and its jobs ---------------------------------------------

# shellcheck source=scripts/slurm_cluster.sh
source "$repo/scripts/slurm_cluster.sh"

jobs_submitted=()
work=""

cleanup() {
    local rc=$?
    if ((${#jobs_submitted[@]} > 0)); then
        scancel "${jobs_submitted[@]}" 2>/dev/null || true
        for _ in $(seq 1 120); do
            [ -z "$(squeue --noheader 2>/dev/null)" ] && break
            sleep 0.5
        done
    fi
    cluster_stop
    if [ -n "$work" ]; then
        if ((rc == 0)) && [ -z "${SLURM_TEST_KEEP:-}" ]; then
            rm -rf "$work"
        else
            echo "kept for inspection: $work" >&2
        fi
    fi
    exit "$rc"
}

# A job's (or array task's) state: PENDING, RUNNING, COMPLETED, CANCELLED...
job_state() {
    scontrol show job "$1" | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | head -n 1
}

# Waits until job $1 has ended (none of PENDING, RUNNING, COMPLETING...),
# at most $2 seconds; prints its final state.
wait_ended() {
    local job=$1 limit=$2 state
    for _ in $(seq 1 $((limit * 4))); do
        state=$(job_state "$job")
        case $state in
        PENDING | CONFIGURING | RUNNING | COMPLETING | SUSPENDED | REQUEUED | RESIZING) sleep 0.25 ;;
        *)
            echo "$state"
            return
            ;;
        esac
    done
    fail "job $job still $state after $limit s"
}

# points_of FILE: the number of points in a sweep file, then its stop_reason.
points_of() {
    "$python" - "$1" <<'EOF'
import sys, h5py
with h5py.File(sys.argv[1], "r") as f:
    reason = f.attrs["stop_reason"]
    reason = reason.decode() if isinstance(reason, bytes) else reason
    print(len(f["points/index"]), reason)
EOF
}

# --- the test -------------------------------------------------------------

install_tools
find_binary
trap cleanup EXIT
trap 'exit 130' INT TERM HUP
work=$(mktemp -d /tmp/cosserat-slurm.XXXXXX)
mkdir "$work/cluster" "$work/run"
say "starting munged, slurmctld, slurmd in $work/cluster"
cluster_start "$work/cluster"
sinfo

problem=$repo/problems/longest_arm_fig6.toml
shards=4
# 4 lines (B̄1) of 10 points (B̄3): one line per shard. A cheap search (one
# family, 4 coefficients, 40 samples, one polish of 100 iterations) keeps a
# point near a quarter of a second of one core.
sweep_args=(
    --set 'sweep.axes=[{key="energy.stiffness[0]",linspace=[0.25,7,4]},{key="energy.stiffness[2]",linspace=[0.1666666666666667,4.666666666666667,10]}]'
    --set sweep.families=1 --set sweep.warm_iterations=100
    --set arm.coefficients=4 --set 'arm.bounds=[[-4,4],[-2,2],[-0.5,0.5]]'
    --set arm.samples=40 --set arm.starts=1 --set arm.iterations=100
)
per_shard=10
# A progress line every quarter second, so that several show the task midway.
export COSSERAT_PROGRESS_SECONDS=0.25
cd "$work/run"

say "sbatch --array=0-$((shards - 1)) scripts/slurm_sweep.sh (and the merge job after it)"
array=$(sbatch --parsable --array=0-$((shards - 1)) --cpus-per-task=1 \
    "$repo/scripts/slurm_sweep.sh" "$problem" fig6 "$shards" "${sweep_args[@]}")
jobs_submitted+=("$array")
merge=$(sbatch --parsable --dependency="afterok:$array" "$repo/scripts/slurm_merge.sh" fig6 "$shards")
jobs_submitted+=("$merge")

# The first task whose log shows at least 2 of its points done, 3 or more
# still to do, is cancelled.
victim=""
for _ in $(seq 1 1200); do
    for ((k = 0; k < shards; k++)); do
        log="cosserat-sweep-${array}_${k}.out"
        [ -f "$log" ] || continue
        done_points=$(sed -n 's/^progress  *\([0-9]*\)\/[0-9]* points.*/\1/p' "$log" | tail -n 1)
        if [ -n "$done_points" ] && ((done_points >= 2 && done_points <= per_shard - 3)); then
            victim=$k
            break 2
        fi
    done
    sleep 0.1
done
[ -n "$victim" ] || fail "no task showed progress within 120 s"
task="${array}_${victim}"
say "scancel $task (its log: $done_points of $per_shard points done)"
scancel "$task"
state=$(wait_ended "$task" 60)
[ "$state" = CANCELLED ] || fail "task $task ended $state, not CANCELLED"
killed_log="cosserat-sweep-${task}.out"
shard_file="fig6.shard-${victim}-of-${shards}.h5"
progress_lines=$(grep -c '^progress  ' "$killed_log" || true)
((progress_lines >= 1)) || fail "$killed_log has no progress line"
read -r kept reason < <(points_of "$shard_file")
echo "killed task: $progress_lines progress lines in $killed_log; $shard_file holds $kept of $per_shard points ($reason)"
((kept >= 1 && kept < per_shard)) || fail "the killed shard holds $kept of $per_shard points: not killed midway"
[ "$reason" = interrupted ] || fail "$shard_file: stop_reason $reason, not interrupted (SIGTERM)"
tail -n 2 "$killed_log" | sed 's/^/  log: /'
merge_wait=$(scontrol show job "$merge" | grep -o 'JobState=[A-Z]* Reason=[A-Za-z]*')
echo "merge job after the cancel: $merge_wait (afterok on the array cannot be met now)"
[[ $merge_wait == JobState=PENDING* ]] || fail "the merge job did not wait: $merge_wait"
cp "$shard_file" killed.h5

say "sbatch --array=$victim (resume) and the merge job pointed at it"
resumed=$(sbatch --parsable --array="$victim" --cpus-per-task=1 \
    "$repo/scripts/slurm_sweep.sh" "$problem" fig6 "$shards" "${sweep_args[@]}")
jobs_submitted+=("$resumed")
scontrol update JobId="$merge" Dependency="afterany:$array,afterok:$resumed"

say "single-process run, 2 threads"
"$COSSERAT" sweep "$problem" -o single.h5 --threads 2 "${sweep_args[@]}" >single.out 2>&1 ||
    fail "the single-process sweep failed: $(tail -n 5 single.out)"

state=$(wait_ended "$resumed" 300)
[ "$state" = COMPLETED ] || fail "resumed task ended $state: $(tail -n 5 "cosserat-sweep-${resumed}_${victim}.out")"
state=$(wait_ended "$merge" 300)
[ "$state" = COMPLETED ] || fail "the merge job ended $state: $(tail -n 5 "cosserat-merge-${merge}.out")"
for ((k = 0; k < shards; k++)); do
    [ "$k" = "$victim" ] && continue
    state=$(job_state "${array}_${k}")
    [ "$state" = COMPLETED ] || fail "task ${array}_${k} ended $state"
done

resumed_log="cosserat-sweep-${resumed}_${victim}.out"
resume_line=$(grep '^resume ' "$resumed_log") || fail "$resumed_log has no resume line"
time_line=$(grep '^time ' "$resumed_log") || fail "$resumed_log has no time line"
reported=$(sed -n 's/^resume *\([0-9]*\) finished points.*/\1/p' <<<"$resume_line")
computed=$(sed -n 's/^time .* for \([0-9]*\) points.*/\1/p' <<<"$time_line")
echo "resumed task: '$resume_line'; '$time_line'"
((reported == kept)) || fail "the resumed task found $reported points, the killed file holds $kept"
((reported + computed == per_shard)) ||
    fail "the resumed task computed $computed points after $reported done: $per_shard in the shard"
echo "merge job: $(grep '^merged ' "cosserat-merge-${merge}.out")"

say "slurm_merge.sh by hand on the killed shard, then without it"
mkdir incomplete
for ((k = 0; k < shards; k++)); do
    cp "fig6.shard-${k}-of-${shards}.h5" incomplete/
done
cp killed.h5 "incomplete/$shard_file"
if (cd incomplete && "$repo/scripts/slurm_merge.sh" fig6 "$shards") >incomplete.out 2>&1; then
    fail "slurm_merge.sh accepted an interrupted shard"
fi
grep -q '^merged .*(partial)' incomplete.out || fail "slurm_merge.sh: $(tail -n 3 incomplete.out)"
echo "with the killed shard: $(grep '^merged ' incomplete.out); exit 1"
rm "incomplete/$shard_file"
if (cd incomplete && "$repo/scripts/slurm_merge.sh" fig6 "$shards") >missing.out 2>&1; then
    fail "slurm_merge.sh accepted a missing shard"
fi
grep -q "no file for shard(s) $victim of" missing.out || fail "slurm_merge.sh: $(tail -n 3 missing.out)"
echo "without it: $(cat missing.out); exit 1"

say "comparing the merged file with the single-process run"
"$python" "$repo/scripts/same_hdf5.py" fig6.h5 single.h5 --ignore /@shard ||
    fail "the merged sweep differs from the single-process run"

say "PASS: job array, scancel midway, resume ($reported kept + $computed computed), merge job, identical to one process"
