#!/bin/bash
# Runs a sharded render on Kubernetes: the shared volume, the Indexed Job of N shards, a wait
# for its completion (or its failure), then the merge Job. Copy the scene to the volume's
# scene.toml first (e.g. with a helper pod and `kubectl cp`).
#
#   deploy/kubernetes/run.sh [N]      (default 4)
#
# N is set in both Jobs (every field marked `# N`), so the shard count and the Job's
# completions cannot differ. Jobs of an earlier run are deleted first: a Job's spec cannot be
# changed, and its old merge's log would be printed as this one's. DRY_RUN=1 prints the
# manifests instead of applying them.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
n=${1:-4}
if ! [[ "${n}" =~ ^[1-9][0-9]*$ ]]; then
    echo "usage: $0 [N]: N must be a positive whole number, got '${n}'" >&2
    exit 2
fi

# The manifest `$1` with every field marked `# N` set to n.
manifest() {
    sed -E \
        -e "s/^([[:space:]]*(completions|parallelism):[[:space:]]*)[0-9]+([[:space:]]+# N)$/\1${n}\3/" \
        -e "s/^([[:space:]]*value:[[:space:]]*)\"[0-9]+\"([[:space:]]+# N)$/\1\"${n}\"\2/" \
        "${here}/$1"
}

# Waits for Job `$1` to complete, at most `$2` seconds; fails as soon as the Job fails
# (`kubectl wait --for=condition=complete` would wait out its whole timeout).
wait_for_job() {
    local job=$1 limit=$2 start=${SECONDS} state
    while :; do
        state=$(kubectl get "job/${job}" \
            -o jsonpath='{range .status.conditions[?(@.status=="True")]}{.type} {end}')
        case " ${state}" in
            *" Complete "*) return 0 ;;
            *" Failed "*)
                echo "error: job ${job} failed" >&2
                kubectl describe "job/${job}" >&2 || true
                return 1
                ;;
        esac
        if ((SECONDS - start > limit)); then
            echo "error: job ${job} did not finish within ${limit} s" >&2
            return 1
        fi
        sleep 10
    done
}

if [ -n "${DRY_RUN:-}" ]; then
    for f in volume.yaml render-job.yaml merge-job.yaml; do
        echo "---"
        manifest "${f}"
    done
    exit 0
fi
kubectl delete job het-bssrdf-render het-bssrdf-merge --ignore-not-found --wait=true
kubectl apply -f "${here}/volume.yaml"
manifest render-job.yaml | kubectl apply -f -
wait_for_job het-bssrdf-render 86400
manifest merge-job.yaml | kubectl apply -f -
wait_for_job het-bssrdf-merge 3600
kubectl logs job/het-bssrdf-merge
