#!/bin/bash
# Runs a sharded render on Kubernetes: the shared volume, the Indexed Job of shards, a wait
# for its completion, then the merge Job. Copy the scene to the volume's scene.toml first
# (e.g. with a helper pod and `kubectl cp`).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
kubectl apply -f "${here}/volume.yaml"
kubectl apply -f "${here}/render-job.yaml"
kubectl wait --for=condition=complete --timeout=24h job/het-bssrdf-render
kubectl apply -f "${here}/merge-job.yaml"
kubectl wait --for=condition=complete --timeout=1h job/het-bssrdf-merge
kubectl logs job/het-bssrdf-merge
