#!/bin/bash
# A cosserat sweep spread over a Slurm job array: one array task per shard,
# each writing its own HDF5 file, then one dependent job that merges them.
#
#   sbatch --array=0-7 scripts/slurm_sweep.sh problems/longest_arm_fig6.toml fig6
#   # after the array: the merge job below runs by itself (see the end), or
#   cosserat merge fig6.shard-*.h5 -o fig6.h5 --plot fig6.png
#
# Arguments: the problem file, an output prefix, and any further arguments
# for `cosserat sweep` (e.g. --set ...). The shard count is the array size
# (SLURM_ARRAY_TASK_COUNT), the shard the task id (0-based: --array=0-(n-1)).
# Shards are whole lines of the grid, so every shard computes the numbers an
# unsharded run computes. A task that is killed (time limit, preemption) is
# resumed by resubmitting the same array: --resume continues from the
# shard's checkpoint and loses no finished point.
#
#SBATCH --job-name=cosserat-sweep
#SBATCH --cpus-per-task=4
#SBATCH --time=01:00:00
#SBATCH --output=%x-%A_%a.out
#SBATCH --requeue

set -euo pipefail
problem=${1:?usage: sbatch --array=0-N scripts/slurm_sweep.sh PROBLEM.toml PREFIX [sweep args]}
prefix=${2:?usage: sbatch --array=0-N scripts/slurm_sweep.sh PROBLEM.toml PREFIX [sweep args]}
shift 2
cosserat=${COSSERAT:-cosserat}

task=${SLURM_ARRAY_TASK_ID:?run this as a job array: sbatch --array=0-N ...}
count=${SLURM_ARRAY_TASK_COUNT:?run this as a job array}
out="${prefix}.shard-${task}-of-${count}.h5"

# --resume: a requeued or resubmitted task goes on from its checkpoint (a
# fresh task starts from nothing); the threads are the task's CPUs.
"$cosserat" sweep "$problem" -o "$out" --shard "${task}/${count}" \
    --threads "${SLURM_CPUS_PER_TASK:-1}" --resume "$@"

# The last task to finish submits nothing; merge once all are done, e.g.
#   sbatch --dependency=afterok:<array job id> --wrap \
#     "cosserat merge ${prefix}.shard-*-of-${count}.h5 -o ${prefix}.h5 --plot ${prefix}.png"
