#!/usr/bin/env bash
# FarmK8sJobGLTest — the Indexed Job of farm/k8s/job.yaml, run here exactly as its pods would run
# it: the container's command and args (read from the manifest by tests/k8s/validate.test.mjs
# --job-command), the image's executable and the volume mount paths mapped to this build and
# temporary folders, JOB_COMPLETION_INDEX set to each completion index in turn; then farm-verify
# must find every frame of the range, byte-identical to one process rendering the range.
# Usage: k8s_job.test.sh DERMIS_SERVER SOURCE_DIR NODE
set -euo pipefail
exe=$1 src=$2 node=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
job=$("$node" "$src/tests/k8s/validate.test.mjs" "$src" --job-command)
mkdir -p "$tmp/frames" "$tmp/scenes"
# The ConfigMap's scene.json, as the pod sees it under /scenes.
python3 - "$src/farm/k8s/scene-configmap.yaml" "$tmp/scenes/scene.json" <<'PY'
import sys, re, json
text = open(sys.argv[1]).read()
body = text.split("scene.json: |", 1)[1].strip()
json.loads(body)
open(sys.argv[2], "w").write(body)
PY
mapfile -t cmd < <(python3 - "$job" "$exe" "$tmp" <<'PY'
import json, sys
job, exe, tmp = json.loads(sys.argv[1]), sys.argv[2], sys.argv[3]
args = [exe] + job["command"][1:]
args = [a.replace("/frames/", tmp + "/frames/").replace("/scenes/", tmp + "/scenes/") for a in args]
for a in args: print(a)
PY
)
completions=$(python3 -c 'import json,sys; print(json.loads(sys.argv[1])["completions"])' "$job")
frames=$(python3 -c 'import json,sys; c=json.loads(sys.argv[1])["command"]; print(c[c.index("--frames")+1])' "$job")
[ "$completions" -ge 2 ] || fail "completions $completions"
# Smaller frames than the Job's 512² keep the test short; everything else is the Job's command.
for ((i = 0; i < completions; ++i)); do
  JOB_COMPLETION_INDEX=$i "${cmd[@]}" --size 64x64 --gl "${DERMIS_TEST_GL:-auto}" >"$tmp/pod$i.log" ||
    fail "index $i: $(cat "$tmp/pod$i.log")"
  grep -q "of shard $i/$completions" "$tmp/pod$i.log" || fail "index $i log: $(cat "$tmp/pod$i.log")"
done
"$exe" farm-verify "$tmp/frames" --frames "$frames" >"$tmp/verify.log" || fail "$(cat "$tmp/verify.log")"
"$exe" render --scene "$tmp/scenes/scene.json" --frames "$frames" --size 64x64 \
  --out "$tmp/one/frame_%04d.png" --gl "${DERMIS_TEST_GL:-auto}" >/dev/null
n=0
for f in "$tmp"/one/*.png; do
  cmp -s "$f" "$tmp/frames/$(basename "$f")" || fail "$(basename "$f") differs from the one-process render"
  n=$((n + 1))
done
[ $n -gt 10 ] || fail "only $n frames"
echo "FarmK8sJobGLTest: $completions indexes, $n frames identical; $(cat "$tmp/verify.log")"
