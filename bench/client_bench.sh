#!/usr/bin/env bash
# client_bench.sh — `dermis render` (the command-line client through a running dermis-server's
# batch route, writing files) against `dermis-server render --frames` (the offline command) on the
# same range of the default scene: 120 frames at 512², PNG and JPEG. Prints JSON on stdout:
#   {"frames", "size", "backend", "png": {"offline_fps", "client_fps", "client_vs_offline"}, "jpeg": {…}}
# Both are end to end: the offline command's time includes its start (GL context, content); the
# client's includes its start, the request, the streamed answer and the atomic file writes, on a
# server already started (one warm-up batch first, as a farm's server would be warm).
# Usage: bench/client_bench.sh [BUILD_DIR] [GL_BACKEND]   (defaults: build, egl-surfaceless)
set -euo pipefail
build="${1:-build}"
gl="${2:-egl-surfaceless}"
server="$build/dermis-server"
client="$build/client/dermis"
[ -x "$server" ] && [ -x "$client" ] || { echo "client_bench: build dermis-server and dermis first ($build)" >&2; exit 2; }
frames=120
range="0:2.38:0.02" # 120 frames
work="$(mktemp -d)"
pid=""
cleanup() { [ -n "$pid" ] && kill "$pid" 2>/dev/null; wait 2>/dev/null || true; rm -rf "$work"; }
trap cleanup EXIT

"$server" serve --port 0 --data "$work/data" --gl "$gl" >"$work/server.log" 2>&1 &
pid=$!
port=""
for _ in $(seq 1 600); do
  port="$(grep -o 'serving http://127.0.0.1:[0-9]*' "$work/server.log" 2>/dev/null | grep -o '[0-9]*$' || true)"
  [ -n "$port" ] && break
  sleep 0.05
done
[ -n "$port" ] || { echo "client_bench: the server did not start" >&2; cat "$work/server.log" >&2; exit 1; }
export DERMIS_SERVER="http://127.0.0.1:$port"

# The default scene (default character with its patterns) as a document, rendered at 512².
sid="$("$client" scene create --default-patterns)"
"$client" scene export "$sid" -o "$work/scene.json"
python3 - "$work/scene.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); d["render"]["size"] = [512, 512]
json.dump(d, open(sys.argv[1], "w"))
PY
backend="$("$client" --json info | python3 -c 'import json,sys; print(json.load(sys.stdin)["backend"])')"
"$client" render --scene-file "$work/scene.json" --frames 0:0.1:0.02 --out "$work/warm/f_%04d.png" >/dev/null

now() { date +%s.%N; }
fps() { python3 -c "print(round($frames / ($2 - $1), 2))"; }
result=""
for ext in png jpg; do
  t0="$(now)"
  "$server" render --scene "$work/scene.json" --gl "$gl" --frames "$range" --out "$work/offline_$ext/frame_%04d.$ext" >/dev/null
  t1="$(now)"
  "$client" render --scene-file "$work/scene.json" --frames "$range" --out "$work/client_$ext/frame_%04d.$ext" >/dev/null
  t2="$(now)"
  n_off="$(ls "$work/offline_$ext" | wc -l)"; n_cli="$(ls "$work/client_$ext" | wc -l)"
  [ "$n_off" = "$frames" ] && [ "$n_cli" = "$frames" ] || { echo "client_bench: $n_off / $n_cli frames written" >&2; exit 1; }
  off="$(fps "$t0" "$t1")"; cli="$(fps "$t1" "$t2")"
  name="$([ "$ext" = jpg ] && echo jpeg || echo png)"
  ratio="$(python3 -c "print(round($cli / $off, 3))")"
  result="$result\"$name\": {\"offline_fps\": $off, \"client_fps\": $cli, \"client_vs_offline\": $ratio}, "
done
echo "{\"frames\": $frames, \"size\": [512, 512], \"backend\": \"$backend\", ${result%, }}"
