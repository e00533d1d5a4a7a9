#!/usr/bin/env bash
# workbench_bench.sh — issue #28's yardstick on this machine: the default scene's 60-frame 1024²
# range (the squat clip at 50 frames/s, PNG) rendered by dermis-server with its default
# anti-aliasing and by Blender's Workbench (bench/workbench_scene.py: the same clip, framing, size
# and format), alternately, REPEAT times each. dermis-server's figure is the whole process
# (start-up, scene load and the first frame's shader compilation included, as dermis-coldbench
# times it); Blender's is its render only (its start and the glTF import not counted). Needs
# Debian's blender and xvfb (Blender takes its GL context from an X display; here Mesa's llvmpipe
# under Xvfb, the same rasterizer dermis-server's egl-surfaceless uses): install them with
#   apt-get install --no-install-recommends blender xvfb xauth
# Prints JSON on stdout:
#   {"frames", "size", "runs", "dermis_ms_per_frame": [...], "workbench_ms_per_frame": [...],
#    "dermis_median", "workbench_median", "speedup", "blender"}
# Usage: bench/workbench_bench.sh [BUILD_DIR] [REPEAT] [GL_BACKEND]   (build, 3, egl-surfaceless)
set -euo pipefail
build="${1:-build}"
repeat="${2:-3}"
gl="${3:-egl-surfaceless}"
frames=60
server="$build/dermis-server"
[ -x "$server" ] || { echo "workbench_bench: build dermis-server first ($build)" >&2; exit 2; }
for tool in blender xvfb-run; do
  command -v "$tool" >/dev/null ||
    { echo "workbench_bench: $tool is missing: apt-get install --no-install-recommends blender xvfb xauth" >&2; exit 2; }
done
src="$(cd "$(dirname "$0")/.." && pwd)"
scene="$src/models/default.scene.json"
range="0:$(python3 -c "print(round(($frames - 1) * 0.02, 6))"):0.02"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
dermis=()
workbench=()
blender_version=""
for ((r = 0; r < repeat; ++r)); do
  rm -rf "$work/d" "$work/b"
  t0=$(now)
  "$server" render --scene "$scene" --frames "$range" --size 1024x1024 --gl "$gl" \
    --out "$work/d/f_%04d.png" >/dev/null
  t1=$(now)
  [ "$(ls "$work/d" | wc -l)" -eq "$frames" ] || { echo "workbench_bench: dermis-server wrote too few frames" >&2; exit 1; }
  dermis+=("$(python3 -c "print(round(($t1 - $t0) * 1000 / $frames, 1))")")
  line=$(xvfb-run -a -s "-screen 0 1280x1024x24" blender -b --python "$src/bench/workbench_scene.py" -- \
           "$src/models/default.glb" "$work/b" squat "$frames" 1024 2>&1 | grep '^WB_JSON ' || true)
  [ -n "$line" ] || { echo "workbench_bench: Blender rendered nothing (run it by hand to see why)" >&2; exit 1; }
  [ "$(ls "$work/b" | wc -l)" -eq "$frames" ] || { echo "workbench_bench: Blender wrote too few frames" >&2; exit 1; }
  workbench+=("$(python3 -c "import json,sys; print(json.loads(sys.argv[1][8:])['ms_per_frame'])" "$line")")
  blender_version=$(python3 -c "import json,sys; print(json.loads(sys.argv[1][8:])['blender'])" "$line")
done
python3 - "$frames" "$blender_version" "${dermis[*]}" "${workbench[*]}" <<'PY'
import json, statistics, sys
frames, version = int(sys.argv[1]), sys.argv[2]
d = [float(x) for x in sys.argv[3].split()]
w = [float(x) for x in sys.argv[4].split()]
dm, wm = statistics.median(d), statistics.median(w)
print(json.dumps({"frames": frames, "size": 1024, "runs": len(d), "dermis_ms_per_frame": d,
                  "workbench_ms_per_frame": w, "dermis_median": dm, "workbench_median": wm,
                  "speedup": round(wm / dm, 1), "blender": version}))
PY
