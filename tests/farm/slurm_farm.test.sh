#!/usr/bin/env bash
# FarmSlurmGLTest — the render farm on a real (throw-away, single-node) Slurm cluster from
# Debian's slurm-wlm and munge (farm/slurm/cluster.sh): farm/slurm/render.sbatch submitted as a
# job array of 4 tasks for 24 frames; task 2 is cancelled mid-way (its render is frozen after its
# first frame) and requeued with `scontrol requeue`; the requeued task renders only the frames
# still missing. Then farm-verify finds all 24 frames, byte-identical to one process rendering the
# range. The daemons are stopped by PID at the end, whatever happens.
# Usage: slurm_farm.test.sh DERMIS_SERVER SOURCE_DIR
set -euo pipefail
exe=$(readlink -f "$1") src=$(readlink -f "$2")
export PATH="$PATH:/usr/sbin"
tmp=$(mktemp -d /tmp/dslurm.XXXXXX) # short: munge's socket path lives here
cleanup() { bash "$src/farm/slurm/cluster.sh" stop "$tmp/cluster" || true; rm -rf "$tmp"; }
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  squeue -a 2>/dev/null || true
  for f in "$tmp"/task-*.out "$tmp"/cluster/log/slurmctld.log; do [ -f "$f" ] && { echo "--- $f"; tail -n 20 "$f"; }; done
  exit 1
}
gl=${DERMIS_TEST_GL:-auto}
scene="$src/models/default.scene.json"
range=0:2.3:0.1
size=384x384

eval "$(bash "$src/farm/slurm/cluster.sh" start "$tmp/cluster")"
[ -n "${SLURM_CONF:-}" ] || fail "the cluster did not start"

"$exe" render --scene "$scene" --size $size --frames $range --gl "$gl" --out "$tmp/one/frame_%04d.png" >/dev/null

# Task 2's first run freezes its render (SIGSTOP) once its first frame exists: it is then cancelled
# mid-way for certain. mkdir is the atomic "first run?" test; the requeued run renders normally.
mkdir -p "$tmp/marks"
cat >"$tmp/server-wrapper.sh" <<WRAP
#!/bin/bash
if [ "\$SLURM_ARRAY_TASK_ID" = 2 ] && mkdir "$tmp/marks/first-run" 2>/dev/null; then
  "$exe" "\$@" & pid=\$!
  while [ ! -e "$tmp/out/frame_0002.png" ] && kill -0 \$pid 2>/dev/null; do sleep 0.01; done
  kill -STOP \$pid
  touch "$tmp/marks/frozen"
  wait \$pid
else
  exec "$exe" "\$@"
fi
WRAP
chmod +x "$tmp/server-wrapper.sh"

job=$(DERMIS_SERVER="$tmp/server-wrapper.sh" sbatch --parsable --array=0-3 --open-mode=append \
        --output="$tmp/task-%a.out" "$src/farm/slurm/render.sbatch" "$scene" $range \
        "$tmp/out/frame_%04d.png" --size $size --gl "$gl") || fail "sbatch"
for _ in $(seq 1200); do [ -e "$tmp/marks/frozen" ] && break; sleep 0.1; done
[ -e "$tmp/marks/frozen" ] || fail "task 2 never started rendering"
scancel "${job}_2"
for _ in $(seq 300); do
  state=$(scontrol show job "${job}_2" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | head -n1)
  [ "$state" = CANCELLED ] && break
  sleep 0.1
done
[ "$state" = CANCELLED ] || fail "task 2 is $state after scancel"
before=$(ls "$tmp/out" | grep -c '^frame_' || true)
scontrol requeue "${job}_2" || fail "requeue"
for _ in $(seq 1800); do
  [ -z "$(squeue -h -j "$job" 2>/dev/null)" ] && break
  sleep 0.1
done
[ -z "$(squeue -h -j "$job")" ] || fail "the job array did not finish in 180 s"
for i in 0 1 2 3; do
  info=$(scontrol show job "${job}_$i")
  grep -q "JobState=COMPLETED" <<<"$info" || fail "task $i: $(grep -o 'JobState=[A-Z]*' <<<"$info")"
done
grep -q "Restarts=1" <<<"$(scontrol show job "${job}_2")" || fail "task 2 was not requeued"
# The requeued task skipped what its first run had finished and rendered the rest.
line=$(grep "of shard 2/4" "$tmp/task-2.out" | tail -n1)
[[ "$line" =~ rendered\ ([0-9]+)\ frames?\ \(([0-9]+)\ already\ complete\) ]] || fail "task 2 log: $line"
rendered=${BASH_REMATCH[1]} skipped=${BASH_REMATCH[2]}
[ "$skipped" -ge 1 ] && [ "$rendered" -ge 1 ] && [ $((rendered + skipped)) = 6 ] ||
  fail "requeued task 2 rendered $rendered and skipped $skipped of 6"
"$exe" farm-verify "$tmp/out" --frames $range >"$tmp/verify.log" || fail "farm-verify: $(cat "$tmp/verify.log")"
for f in "$tmp"/one/*.png; do
  cmp -s "$f" "$tmp/out/$(basename "$f")" || fail "$(basename "$f") differs from the one-process render"
done
echo "FarmSlurmGLTest: 4 tasks, task 2 cancelled after $before frames and requeued (rendered $rendered, skipped $skipped); $(cat "$tmp/verify.log")"
