#!/usr/bin/env python3
"""Checks the Kubernetes manifests of deploy/kubernetes without a cluster (run by .ci/run).

No schema validator (kubeconform, kubeval) installs from a package registry reachable by CI,
so this checks the fields that matter against the Kubernetes API's own rules, as a validator
would, plus the rules of this project's sharded render:

- every key is one the API knows at its place (a typo such as `completion:` is an error, not
  a silently ignored field), and every value has the API's type;
- names are DNS-1123 labels; quantities (`2`, `500m`, `4Gi`) parse;
- every container has an explicit image tag other than `latest`, an explicit pull policy,
  and CPU and memory requests and limits (a request at most its limit);
- the render Job is Indexed with completions = parallelism = its SHARDS = the merge Job's
  SHARDS, and fails at once on a usage error instead of retrying until its backoffLimit;
- both Jobs mount the volume claim that volume.yaml defines, ReadWriteMany;
- run.sh's manifests (DRY_RUN=1) for another N set every `# N` field to that N.

Usage: check_manifests.py [DIR] (default: this script's directory). Exits 1 with one line per
problem.
"""

import os
import re
import subprocess
import sys

import yaml

DNS_LABEL = re.compile(r"^[a-z0-9]([-a-z0-9]*[a-z0-9])?$")
QUANTITY = re.compile(r"^[0-9]+(\.[0-9]+)?(m|k|Ki|Mi|Gi|Ti|M|G|T)?$")
SUFFIX = {
    None: 1,
    "m": 1e-3,
    "k": 1e3,
    "M": 1e6,
    "G": 1e9,
    "T": 1e12,
    "Ki": 2**10,
    "Mi": 2**20,
    "Gi": 2**30,
    "Ti": 2**40,
}

# The keys the API knows (batch/v1 Job, core/v1 PodSpec, Container, PersistentVolumeClaim),
# restricted to the parts these manifests use: {key: type or nested schema}.
STR, INT, LIST, BOOL = str, int, list, bool
CONTAINER = {
    "name": STR,
    "image": STR,
    "imagePullPolicy": STR,
    "command": [STR],
    "args": [STR],
    "env": [{"name": STR, "value": STR}],
    "resources": {
        "requests": {"cpu": STR, "memory": STR},
        "limits": {"cpu": STR, "memory": STR},
    },
    "volumeMounts": [{"name": STR, "mountPath": STR, "readOnly": BOOL}],
    "workingDir": STR,
}
POD_SPEC = {
    "restartPolicy": STR,
    "containers": [CONTAINER],
    "volumes": [{"name": STR, "persistentVolumeClaim": {"claimName": STR, "readOnly": BOOL}}],
    "nodeSelector": {},
}
METADATA = {"name": STR, "labels": {}, "annotations": {}, "namespace": STR}
JOB = {
    "apiVersion": STR,
    "kind": STR,
    "metadata": METADATA,
    "spec": {
        "completionMode": STR,
        "completions": INT,
        "parallelism": INT,
        "backoffLimit": INT,
        "backoffLimitPerIndex": INT,
        "activeDeadlineSeconds": INT,
        "ttlSecondsAfterFinished": INT,
        "podFailurePolicy": {
            "rules": [
                {
                    "action": STR,
                    "onExitCodes": {"containerName": STR, "operator": STR, "values": [INT]},
                }
            ]
        },
        "template": {"metadata": METADATA, "spec": POD_SPEC},
    },
}
PVC = {
    "apiVersion": STR,
    "kind": STR,
    "metadata": METADATA,
    "spec": {
        "accessModes": [STR],
        "storageClassName": STR,
        "resources": {"requests": {"storage": STR}},
    },
}


def check_schema(value, schema, where, problems):
    """Every key of `value` known at its place in `schema`, every value of its type."""
    if isinstance(schema, dict):
        if not isinstance(value, dict):
            problems.append(f"{where}: expected a mapping, got {type(value).__name__}")
            return
        if not schema:  # free-form map of strings (labels, annotations, nodeSelector)
            for k, v in value.items():
                if not isinstance(v, str):
                    problems.append(f"{where}.{k}: expected a string")
            return
        for k, v in value.items():
            if k not in schema:
                problems.append(f"{where}: unknown field `{k}`")
            else:
                check_schema(v, schema[k], f"{where}.{k}", problems)
    elif isinstance(schema, list):
        if not isinstance(value, list):
            problems.append(f"{where}: expected a list, got {type(value).__name__}")
            return
        for i, item in enumerate(value):
            check_schema(item, schema[0], f"{where}[{i}]", problems)
    elif schema is INT:
        if not isinstance(value, int) or isinstance(value, bool):
            problems.append(f"{where}: expected an integer, got {value!r}")
    elif not isinstance(value, schema):
        problems.append(f"{where}: expected {schema.__name__}, got {value!r}")


def quantity(text):
    """The value of a Kubernetes quantity, or None when it does not parse."""
    m = QUANTITY.match(str(text))
    if not m:
        return None
    number = float(str(text)[: len(str(text)) - len(m.group(2) or "")])
    return number * SUFFIX[m.group(2)]


def check_container(c, where, problems):
    image = c.get("image", "")
    name, _, tag = image.rpartition(":") if ":" in image.split("/")[-1] else (image, "", "")
    if not tag or tag == "latest":
        problems.append(f"{where}.image: `{image}` needs an explicit version tag, not latest")
    if c.get("imagePullPolicy") not in ("IfNotPresent", "Always", "Never"):
        problems.append(f"{where}.imagePullPolicy: set it (IfNotPresent, Always or Never)")
    resources = c.get("resources", {})
    for kind in ("cpu", "memory"):
        req = resources.get("requests", {}).get(kind)
        lim = resources.get("limits", {}).get(kind)
        if req is None or lim is None:
            problems.append(f"{where}.resources: needs a {kind} request and limit")
            continue
        r, l_ = quantity(req), quantity(lim)
        if r is None or l_ is None:
            problems.append(f"{where}.resources: bad {kind} quantity `{req}` or `{lim}`")
        elif r > l_:
            problems.append(f"{where}.resources: {kind} request {req} above its limit {lim}")
    if not DNS_LABEL.match(c.get("name", "")):
        problems.append(f"{where}.name: `{c.get('name')}` is not a DNS-1123 label")


def env_of(c):
    return {e["name"]: e.get("value") for e in c.get("env", [])}


def shards(job):
    containers = job["spec"]["template"]["spec"]["containers"]
    values = {env_of(c).get("SHARDS") for c in containers} - {None}
    if len(values) != 1:
        return None
    (value,) = values
    return int(value) if str(value).isdigit() else None


def check(docs, problems):
    by_kind = {}
    for name, doc in docs:
        kind = doc.get("kind")
        schema = {"Job": JOB, "PersistentVolumeClaim": PVC}.get(kind)
        if schema is None:
            problems.append(f"{name}: unexpected kind {kind!r}")
            continue
        api = {"Job": "batch/v1", "PersistentVolumeClaim": "v1"}[kind]
        if doc.get("apiVersion") != api:
            problems.append(f"{name}: {kind} needs apiVersion {api}")
        check_schema(doc, schema, name, problems)
        if not DNS_LABEL.match(doc.get("metadata", {}).get("name", "")):
            problems.append(f"{name}: metadata.name is not a DNS-1123 label")
        by_kind.setdefault(kind, []).append((name, doc))
    claims = {d["metadata"]["name"]: (n, d) for n, d in by_kind.get("PersistentVolumeClaim", [])}
    for name, pvc in claims.values():
        if pvc["spec"].get("accessModes") != ["ReadWriteMany"]:
            problems.append(f"{name}: shards on several nodes need accessModes [ReadWriteMany]")
        if quantity(pvc["spec"].get("resources", {}).get("requests", {}).get("storage")) is None:
            problems.append(f"{name}: needs a storage request")
    jobs = {d["metadata"]["name"]: (n, d) for n, d in by_kind.get("Job", [])}
    for name, job in jobs.values():
        pod = job["spec"]["template"]["spec"]
        if pod.get("restartPolicy") not in ("Never", "OnFailure"):
            problems.append(f"{name}: a Job's restartPolicy must be Never or OnFailure")
        volumes = {v["name"]: v for v in pod.get("volumes", [])}
        for i, c in enumerate(pod.get("containers", [])):
            where = f"{name}.spec.template.spec.containers[{i}]"
            check_container(c, where, problems)
            for m in c.get("volumeMounts", []):
                if m["name"] not in volumes:
                    problems.append(f"{where}: mounts undefined volume `{m['name']}`")
        for v in volumes.values():
            claim = v.get("persistentVolumeClaim", {}).get("claimName")
            if claim not in claims:
                problems.append(f"{name}: volume `{v['name']}` names unknown claim `{claim}`")
    render, merge = jobs.get("het-bssrdf-render"), jobs.get("het-bssrdf-merge")
    if render is None or merge is None:
        problems.append("the render and merge Jobs must both be defined")
        return
    (rname, r), (mname, m) = render, merge
    spec = r["spec"]
    if spec.get("completionMode") != "Indexed":
        problems.append(f"{rname}: the render Job must be Indexed (JOB_COMPLETION_INDEX)")
    n = shards(r)
    counts = {
        "completions": spec.get("completions"),
        "parallelism": spec.get("parallelism"),
        "its SHARDS": n,
        f"{mname}'s SHARDS": shards(m),
    }
    if n is None or any(v != n for v in counts.values()):
        problems.append(f"{rname}: shard counts differ: {counts}")
    rules = spec.get("podFailurePolicy", {}).get("rules", [])
    if not any(
        rule.get("action") == "FailJob"
        and rule.get("onExitCodes", {}).get("operator") == "In"
        and 2 in rule.get("onExitCodes", {}).get("values", [])
        for rule in rules
    ):
        problems.append(f"{rname}: a usage error (exit code 2) must fail the Job at once")


def load(directory, names):
    docs = []
    for f in names:
        with open(os.path.join(directory, f), encoding="utf-8") as fh:
            for i, doc in enumerate(yaml.safe_load_all(fh)):
                if doc is not None:
                    docs.append((f if i == 0 else f"{f}#{i}", doc))
    return docs


def self_test(docs):
    """The check finds a planted fault of each kind in a copy of the manifests (a check that
    cannot fail is worse than none)."""
    import copy

    def job(ds, name):
        return next(d for _, d in ds if d.get("metadata", {}).get("name") == name)

    def container(ds, name):
        return job(ds, name)["spec"]["template"]["spec"]["containers"][0]

    faults = {
        "a misspelt key": lambda ds: job(ds, "het-bssrdf-render")["spec"].update(completion=4),
        "completions other than SHARDS": lambda ds: job(ds, "het-bssrdf-render")[
            "spec"
        ].update(completions=5),
        "an image tagged latest": lambda ds: container(ds, "het-bssrdf-merge").update(
            image="het-bssrdf:latest"
        ),
        "no memory limit": lambda ds: container(ds, "het-bssrdf-render")["resources"][
            "limits"
        ].pop("memory"),
        "a request above its limit": lambda ds: container(ds, "het-bssrdf-merge")["resources"][
            "requests"
        ].update(memory="8Gi"),
        "an unknown claim": lambda ds: job(ds, "het-bssrdf-merge")["spec"]["template"]["spec"][
            "volumes"
        ][0]["persistentVolumeClaim"].update(claimName="other"),
    }
    missed = []
    for what, plant in faults.items():
        planted = copy.deepcopy(docs)
        plant(planted)
        found = []
        check(planted, found)
        if not found:
            missed.append(what)
    return [f"self-test: {what} was not found" for what in missed]


def main():
    directory = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    names = sorted(f for f in os.listdir(directory) if f.endswith(".yaml"))
    problems = []
    docs = load(directory, names)
    check(docs, problems)
    if not problems:
        problems.extend(self_test(docs))
    # The manifests run.sh applies for N = 7.
    out = subprocess.run(
        ["bash", os.path.join(directory, "run.sh"), "7"],
        env={**os.environ, "DRY_RUN": "1"},
        capture_output=True,
        text=True,
        check=False,
    )
    if out.returncode != 0:
        problems.append(f"run.sh DRY_RUN=1 failed: {out.stderr.strip()}")
    else:
        docs = [("run.sh 7", d) for d in yaml.safe_load_all(out.stdout) if d is not None]
        before = len(problems)
        check(docs, problems)
        render = [d for _, d in docs if d.get("metadata", {}).get("name") == "het-bssrdf-render"]
        if render and render[0]["spec"].get("completions") != 7:
            problems.append("run.sh 7: the render Job's completions are not 7")
        if len(problems) > before:
            problems.append("run.sh 7: the manifests it applies are not consistent")
    for p in problems:
        print(f"error: {p}", file=sys.stderr)
    print(f"kubernetes manifests: {len(names)} files checked, {len(problems)} problems")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
