#!/usr/bin/env bash
# FarmShardCliGLTest — `render --shard` and `farm-verify` (SPEC §7), offline, no engine:
#   * 4 shards (I/4 and auto/4 from SLURM_ARRAY_TASK_ID and JOB_COMPLETION_INDEX) render 24
#     frames byte-identical to one process, interleaved (shard 1 wrote frames 1, 5, 9, …), each
#     with a manifest whose SHA-256s are the files';
#   * farm-verify: exit 0 when complete (folder or pattern), 1 naming a missing and a corrupt frame;
#   * a shard run again renders only what is missing ("… already complete");
#   * bad shards are refused naming --shard (exit 1), auto/N without a task index names both
#     variables.
# Usage: shard_cli.test.sh DERMIS_SERVER SOURCE_DIR
set -euo pipefail
exe=$1 src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
gl=${DERMIS_TEST_GL:-auto}
scene="$src/models/default.scene.json"
range=0:2.3:0.1
render() { "$exe" render --scene "$scene" --size 96x96 --frames "$range" --gl "$gl" "$@"; }

render --out "$tmp/one/frame_%04d.png" >/dev/null
[ "$(ls "$tmp/one" | wc -l)" = 24 ] || fail "one process: expected 24 frames"

render --shard 0/4 --out "$tmp/farm/frame_%04d.png" >/dev/null
SLURM_ARRAY_TASK_ID=1 render --shard auto/4 --out "$tmp/farm/frame_%04d.png" >"$tmp/s1.log"
JOB_COMPLETION_INDEX=2 render --shard auto/4 --out "$tmp/farm/frame_%04d.png" >/dev/null
render --shard 3/4 --out "$tmp/farm/frame_%04d.png" >/dev/null
grep -q "shard 1/4" "$tmp/s1.log" || fail "shard 1 log: $(cat "$tmp/s1.log")"
for f in "$tmp"/one/*.png; do
  cmp -s "$f" "$tmp/farm/$(basename "$f")" || fail "$(basename "$f") differs from the one-process render"
done
python3 - "$tmp/farm" <<'PY' || fail "manifests"
import hashlib, json, sys, os
d = sys.argv[1]
seen = {}
for i in range(4):
    m = json.load(open(os.path.join(d, f"manifest.shard-{i}-of-4.json")))
    assert m["format"] == "dermis.farm-manifest/1" and m["shard"] == f"{i}/4" and m["frames"] == "0:2.3:0.1", m
    frames = [e["frame"] for e in m["entries"]]
    assert frames == list(range(i, 24, 4)), (i, frames)        # interleaved
    for e in m["entries"]:
        data = open(os.path.join(d, e["file"]), "rb").read()
        assert hashlib.sha256(data).hexdigest() == e["sha256"] and len(data) == e["bytes"], e
        seen[e["frame"]] = e["file"]
assert sorted(seen) == list(range(24)), sorted(seen)
PY

"$exe" farm-verify "$tmp/farm" --frames "$range" >"$tmp/v.log" || fail "verify of a complete folder: $(cat "$tmp/v.log")"
grep -q "complete: 24 of 24" "$tmp/v.log" || fail "verify output: $(cat "$tmp/v.log")"
"$exe" farm-verify "$tmp/farm/frame_%04d.png" --frames "$range" >/dev/null || fail "verify by pattern"

rm "$tmp/farm/frame_0005.png"
printf 'not a frame' >"$tmp/farm/frame_0010.png"
set +e
"$exe" farm-verify "$tmp/farm" --frames "$range" --json >"$tmp/v.json"
rc=$?
set -e
[ $rc = 1 ] || fail "verify of a damaged folder exited $rc"
python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); assert r["missing"]==[5] and r["corrupt"]==[10] and not r["complete"], r' "$tmp/v.json" ||
  fail "report: $(cat "$tmp/v.json")"

# Shard 1 again: only frame 5 is missing there; frame 10 (shard 2) exists and is left alone.
SLURM_ARRAY_TASK_ID=1 render --shard auto/4 --out "$tmp/farm/frame_%04d.png" >"$tmp/s1b.log"
grep -q "rendered 1 frame (5 already complete) of shard 1/4" "$tmp/s1b.log" || fail "rerun: $(cat "$tmp/s1b.log")"
cmp -s "$tmp/one/frame_0005.png" "$tmp/farm/frame_0005.png" || fail "re-rendered frame 5 differs"
rm "$tmp/farm/frame_0010.png"
render --shard 2/4 --out "$tmp/farm/frame_%04d.png" >/dev/null
"$exe" farm-verify "$tmp/farm" --frames "$range" >/dev/null || fail "verify after repair"

for bad in 4/4 -1/4 x/4 1/0 2; do
  set +e
  render --shard "$bad" --out "$tmp/bad/frame_%04d.png" >/dev/null 2>"$tmp/err"
  rc=$?
  set -e
  [ $rc = 1 ] && grep -q -- "--shard" "$tmp/err" || fail "--shard $bad: exit $rc, $(cat "$tmp/err")"
done
set +e
env -u SLURM_ARRAY_TASK_ID -u JOB_COMPLETION_INDEX "$exe" render --scene "$scene" --frames "$range" \
  --shard auto/4 --out "$tmp/bad/f_%04d.png" --gl "$gl" >/dev/null 2>"$tmp/err"
rc=$?
set -e
[ $rc = 1 ] && grep -q SLURM_ARRAY_TASK_ID "$tmp/err" && grep -q JOB_COMPLETION_INDEX "$tmp/err" ||
  fail "auto without an index: exit $rc, $(cat "$tmp/err")"
[ ! -e "$tmp/bad" ] || fail "a refused render wrote files"
echo "FarmShardCliGLTest: passed"
