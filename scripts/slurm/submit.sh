#!/usr/bin/env bash
# Submit a whirlmap sweep as a Slurm job array of N shards plus a dependent merge-and-render
# job; prints the two job ids.
#
#   scripts/slurm/submit.sh SPEC N [OUT] [--throttle K] [--cpus C]
#
# Shards go to OUT/shards/shard-I-of-N, the merged result and charts to OUT (default
# results/<spec file stem>). At most K shards run at once (default: no limit), each with C
# CPUs and threads (default 1). Extra sbatch options (partition, account, time) can be given
# in SBATCH_* environment variables, which sbatch reads itself. Set WHIRLMAP to the binary
# if it is not on PATH on the compute nodes.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [ $# -lt 2 ]; then
    echo "usage: $0 SPEC N [OUT] [--throttle K] [--cpus C]" >&2
    exit 2
fi
spec=$1
shards=$2
shift 2
out="results/$(basename "${spec%.json}")"
if [ $# -gt 0 ] && [ "${1#--}" = "$1" ]; then
    out=$1
    shift
fi
throttle=""
cpus=1
while [ $# -gt 0 ]; do
    case $1 in
    --throttle) throttle="%$2"; shift 2 ;;
    --cpus) cpus=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
    esac
done
case $shards in
'' | *[!0-9]* | 0) echo "N must be a positive integer, got '$shards'" >&2; exit 2 ;;
esac
mkdir -p "$out/shards"
array=$(sbatch --parsable --array="0-$((shards - 1))$throttle" --cpus-per-task="$cpus" \
    --output="$out/shards/slurm-%A_%a.out" \
    "$here/sweep-array.sbatch" "$spec" "$out/shards")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterany:$array" \
    --output="$out/shards/slurm-%j-merge.out" \
    "$here/merge.sbatch" "$out/shards" "$shards" "$out")
merge=${merge%%;*}
echo "$array $merge"
