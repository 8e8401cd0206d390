#!/bin/bash
# Submits a sharded render: a job array of N shard tasks and a merge job that starts when
# every task has succeeded (afterok on the array's job id).
#
#   deploy/slurm/submit.sh N SCENE OUT [render flags...]
#   deploy/slurm/submit.sh 8 scenes/marble.toml out/marble --method sone --spp 256
#
# Writes OUT-shard-I.{exr,png,json} for I in 0..N-1, then OUT.{exr,png,json}. Run it from a
# directory every node sees; set HET_BSSRDF to the binary if it is not on the nodes' PATH.
set -euo pipefail
if [ $# -lt 3 ]; then
    echo "usage: $0 N SCENE OUT [render flags...]" >&2
    exit 2
fi
n=$1 scene=$2 out=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$(dirname "${out}")"
array=$(SCENE="${scene}" OUT="${out}" SHARDS="${n}" RENDER_ARGS="$*" \
    sbatch --parsable --array="0-$((n - 1))" --export=ALL "${here}/render-shard.sbatch")
array=${array%%;*}
merge=$(OUT="${out}" SHARDS="${n}" \
    sbatch --parsable --dependency="afterok:${array}" --kill-on-invalid-dep=yes --export=ALL \
    "${here}/merge.sbatch")
echo "shards: job array ${array} (${n} tasks); merge: job ${merge%%;*} -> ${out}.exr"
