#!/bin/bash
# Joins the shard files written by the job array of scripts/slurm_sweep.sh
# into PREFIX.h5 (replacing it). Submit it depending on the array, so that
# it starts once every task has completed its shard (docs/cluster.md):
#
#   jid=$(sbatch --parsable --array=0-7 scripts/slurm_sweep.sh \
#         problems/longest_arm_fig6.toml fig6 8)
#   sbatch --dependency=afterok:$jid scripts/slurm_merge.sh fig6 8 --plot fig6.png
#
# Arguments: the output prefix and shard count N given to slurm_sweep.sh,
# then any further arguments for `cosserat merge` (e.g. --plot fig6.png).
# It can also be run by hand, without Slurm.
#
# It fails (exit 1) when a shard file is missing (nothing is written) or
# not complete, i.e. a task killed and not yet resumed (`cosserat merge`
# then writes PREFIX.h5 with the points there are, its stop_reason
# `partial`).
#
# COSSERAT: the cosserat binary (default: `cosserat` on the PATH).
#
#SBATCH --job-name=cosserat-merge
#SBATCH --cpus-per-task=1
#SBATCH --time=00:10:00
#SBATCH --output=%x-%j.out

set -euo pipefail
usage="usage: scripts/slurm_merge.sh PREFIX N [merge args]"
prefix=${1:?$usage}
count=${2:?$usage}
shift 2
cosserat=${COSSERAT:-cosserat}
if ! [[ $count =~ ^[1-9][0-9]*$ ]]; then
    echo "slurm_merge.sh: N = $count is not a shard count ($usage)" >&2
    exit 2
fi

shards=()
missing=()
for ((i = 0; i < count; i++)); do
    shard="${prefix}.shard-${i}-of-${count}.h5"
    if [ -f "$shard" ]; then
        shards+=("$shard")
    else
        missing+=("$i")
    fi
done
if ((${#missing[@]} > 0)); then
    echo "slurm_merge.sh: no file for shard(s) ${missing[*]} of $count (${prefix}.shard-I-of-${count}.h5); run those array tasks first" >&2
    exit 1
fi

report=$(mktemp)
trap 'rm -f "$report"' EXIT
"$cosserat" merge "${shards[@]}" -o "${prefix}.h5" --force "$@" | tee "$report"
# `merged    N files, P of Q points (completed) into ...`: anything but
# completed means some shard was interrupted or is still running.
if ! grep -q '^merged .*(completed) into' "$report"; then
    echo "slurm_merge.sh: the shards do not make the whole sweep (a task was killed?): resubmit it with the same arguments, e.g. sbatch --array=I scripts/slurm_sweep.sh ..., then merge again" >&2
    exit 1
fi
