#!/bin/bash
# One shard of a cosserat sweep, as one task of a Slurm job array. Each task
# writes its own file PREFIX.shard-I-of-N.h5; nothing here merges: the
# shards are joined by scripts/slurm_merge.sh, submitted as a job that
# depends on the array (docs/cluster.md):
#
#   jid=$(sbatch --parsable --array=0-7 scripts/slurm_sweep.sh \
#         problems/longest_arm_fig6.toml fig6 8)
#   sbatch --dependency=afterok:$jid scripts/slurm_merge.sh fig6 8 --plot fig6.png
#
# Arguments: the problem file, an output prefix, the shard count N, then any
# further arguments for `cosserat sweep` (e.g. --set ...), the same for every
# task. The task id is the shard (0-based: --array=0-(N-1)). N is given, not
# taken from the array's size, so that one task resubmitted alone
# (--array=3) is still shard 3 of N. Shards are whole lines of the grid, so
# every shard computes the numbers an unsharded run computes.
#
# Every task runs with --resume: a fresh task starts from nothing, a task
# that was killed (time limit, scancel, preemption) and is requeued or
# resubmitted with the same arguments goes on from its shard's checkpoint
# (the output file, saved every second) and computes only the missing
# points; a task whose shard is complete does nothing. A task exits 0 only
# when its shard is complete (130 when interrupted), which is what the
# merge job's afterok dependency waits for.
#
# The log (%x-%A_%a.out, appended to across requeues) shows a progress line
# every 10 s (COSSERAT_PROGRESS_SECONDS to change it).
#
# COSSERAT: the cosserat binary (default: `cosserat` on the PATH).
#
#SBATCH --job-name=cosserat-sweep
#SBATCH --cpus-per-task=4
#SBATCH --time=01:00:00
#SBATCH --output=%x-%A_%a.out
#SBATCH --open-mode=append
#SBATCH --requeue

set -euo pipefail
usage="usage: sbatch --array=0-(N-1) scripts/slurm_sweep.sh PROBLEM.toml PREFIX N [sweep args]"
problem=${1:?$usage}
prefix=${2:?$usage}
count=${3:?$usage}
shift 3
cosserat=${COSSERAT:-cosserat}

task=${SLURM_ARRAY_TASK_ID:?run this as a job array: $usage}
if ! [[ $count =~ ^[1-9][0-9]*$ ]] || ((task >= count)); then
    echo "slurm_sweep.sh: array task $task is not a shard of N = $count ($usage)" >&2
    exit 2
fi
out="${prefix}.shard-${task}-of-${count}.h5"

# The threads are the task's CPUs. `exec`: cosserat replaces this shell as
# the batch step's main process. Slurm's SIGTERM (scancel, time limit,
# preemption) reaches every process of the step, and a shell killed by it
# ends the step, whose remaining processes Slurm then kills at once; the
# sweep would lose that race to write its finished points.
exec "$cosserat" sweep "$problem" -o "$out" --shard "${task}/${count}" \
    --threads "${SLURM_CPUS_PER_TASK:-1}" --resume "$@"
