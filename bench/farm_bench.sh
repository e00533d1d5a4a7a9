#!/usr/bin/env bash
# farm_bench.sh — render-farm throughput on this machine: a range of the default scene split over
# 1, 2 and 3 shard processes running at once (`dermis-server render --frames … --shard I/N`, what
# each Slurm task or Indexed Job pod runs), at 512² and 1024², PNG. Frames/s = frames / wall time
# from the first start to the last exit (each process's start included, as on a farm). Checks with
# farm-verify that every run is complete. Prints JSON on stdout:
#   {"frames", "backend", "cores", "runs": [{"size", "shards", "seconds", "fps", "speedup"}, …]}
# Usage: bench/farm_bench.sh [BUILD_DIR] [GL_BACKEND] [FRAMES]   (build, egl-surfaceless, 60)
set -euo pipefail
build="${1:-build}"
gl="${2:-egl-surfaceless}"
frames="${3:-60}"
server="$build/dermis-server"
[ -x "$server" ] || { echo "farm_bench: build dermis-server first ($build)" >&2; exit 2; }
src="$(cd "$(dirname "$0")/.." && pwd)"
scene="$src/models/default.scene.json"
range="0:$(python3 -c "print(round(($frames - 1) * 0.02, 6))"):0.02"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
rows=()
for size in 512 1024; do
  base=""
  for n in 1 2 3; do
    out="$work/${size}_$n"
    t0=$(now)
    pids=()
    for ((i = 0; i < n; ++i)); do
      "$server" render --scene "$scene" --frames "$range" --shard "$i/$n" --size "${size}x${size}" \
        --gl "$gl" --out "$out/frame_%04d.png" >/dev/null &
      pids+=($!)
    done
    for p in "${pids[@]}"; do wait "$p"; done
    t1=$(now)
    "$server" farm-verify "$out" --frames "$range" >/dev/null ||
      { echo "farm_bench: $size² with $n shards is incomplete" >&2; exit 1; }
    secs=$(python3 -c "print(round($t1 - $t0, 3))")
    fps=$(python3 -c "print(round($frames / ($t1 - $t0), 2))")
    [ -n "$base" ] || base=$fps
    rows+=("{\"size\": $size, \"shards\": $n, \"seconds\": $secs, \"fps\": $fps, \"speedup\": $(python3 -c "print(round($fps / $base, 2))")}")
    rm -rf "$out"
  done
done
printf '{"frames": %d, "backend": "%s", "cores": %d, "runs": [\n  %s\n]}\n' "$frames" "$gl" "$(nproc)" \
  "$(IFS=$'\n'; echo "${rows[*]}" | paste -sd, - | sed 's/},{/},\n  {/g')"
