#!/usr/bin/env bash
# replicas_bench.sh — throughput of stateless replicas behind nginx on this machine: 1, 2 and 3
# `dermis-server serve` replicas behind Debian's nginx running docker/nginx-replicas.conf (its
# upstream replaced by the loopback replicas), a 60-frame range of CesiumMan with a pattern file
# rendered by `dermis render --scene-file … --parallel N --batch 10` through nginx, at 512² and
# 1024², PNG. Each configuration runs once untimed first (content sent by address, GL warm), then
# timed: frames/s = frames / the client's wall time. Prints JSON on stdout:
#   {"frames", "backend", "cores", "runs": [{"size", "replicas", "seconds", "fps", "speedup",
#    "first_run_content_misses", "first_run_files_sent"}, …]} — the last two from the untimed first
#    run, which sends the content: replicas' content-cache misses (one 409 counts 4: both files
#    looked up for the request and for its resend) and the files the client sent along after 409s
#    (2 per 409: one 409 per replica a batch went to).
# Usage: bench/replicas_bench.sh [BUILD_DIR] [GL_BACKEND] [FRAMES]   (build, egl-surfaceless, 60)
set -euo pipefail
build="${1:-build}"
gl="${2:-egl-surfaceless}"
frames="${3:-60}"
server="$build/dermis-server" client="$build/client/dermis"
[ -x "$server" ] && [ -x "$client" ] || { echo "replicas_bench: build dermis-server and dermis first ($build)" >&2; exit 2; }
src="$(cd "$(dirname "$0")/.." && pwd)"
models="${DERMIS_TEST_MODELS:-$src/tests/models}"
nginx_bin=$(command -v nginx || echo /usr/sbin/nginx)
work="$(mktemp -d)"
pids=()
stop_all() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; pids=(); }
trap 'stop_all; rm -rf "$work"' EXIT
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
now() { date +%s.%N; }
range="0:$(python3 -c "print(round(($frames - 1) * 0.04, 6))"):0.04"

mkdir -p "$work/shot"
cp "$src/patterns/crease.png" "$work/shot/crease_copy.png"
python3 - "$src/examples/cesiumman.scene.json" "$work/shot/shot.scene.json" "$models/CesiumMan/CesiumMan.glb" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
doc["model"] = sys.argv[3]
doc["patterns"] = {"crease_copy": "crease_copy.png"}
doc["placements"][0]["pattern"] = "crease_copy"
json.dump(doc, open(sys.argv[2], "w"))
PY

rows=()
for size in 512 1024; do
  base=""
  for n in 1 2 3; do
    ports=()
    for ((r = 0; r < n; ++r)); do
      "$server" serve --port 0 --data "$work/data_${size}_${n}_$r" --gl "$gl" >"$work/replica$r.log" 2>&1 &
      pids+=($!)
    done
    for ((r = 0; r < n; ++r)); do
      for _ in $(seq 600); do grep -q "serving http://127.0.0.1:" "$work/replica$r.log" && break; sleep 0.05; done
      ports+=("$(sed -n 's|.*serving http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$work/replica$r.log" | head -1)")
    done
    port=$(free_port)
    upstreams=""
    for p in "${ports[@]}"; do upstreams+="server 127.0.0.1:$p max_fails=1 fail_timeout=10s; "; done
    mkdir -p "$work/nginx/logs"
    sed -e "s|server dermis:8080 max_fails=1 fail_timeout=10s;|$upstreams|" -e "s|listen 80;|listen 127.0.0.1:$port;|" \
      "$src/docker/nginx-replicas.conf" >"$work/nginx/nginx.conf"
    "$nginx_bin" -p "$work/nginx" -c "$work/nginx/nginx.conf" -g "daemon off; pid $work/nginx/nginx.pid; error_log $work/nginx.log;" &
    pids+=($!)
    for _ in $(seq 100); do curl -s -o /dev/null "http://127.0.0.1:$port/api/v1/health" && break; sleep 0.05; done
    run() {
      "$client" --server "http://127.0.0.1:$port" --json render --scene-file "$work/shot/shot.scene.json" --frames "$range" \
        --size "${size}x${size}" --batch 10 --parallel "$n" -o "$1/frame_%04d.png" >"$1.json"
    }
    run "$work/warm"
    # The first run sends the content: how often replicas asked for it (409 missing_content) and
    # how many files the client sent along.
    misses=0
    for p in "${ports[@]}"; do
      m=$(curl -s "http://127.0.0.1:$p/api/v1/info" | python3 -c 'import json,sys; print(json.load(sys.stdin)["content_cache"]["misses"])')
      misses=$((misses + m))
    done
    sent=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["content_sent"])' "$work/warm.json")
    t0=$(now)
    run "$work/timed"
    t1=$(now)
    [ "$(ls "$work/timed" | wc -l)" -eq "$frames" ] || { echo "replicas_bench: $size² with $n replicas is incomplete" >&2; exit 1; }
    stop_all
    rm -rf "$work/warm" "$work/timed" "$work/warm.json" "$work/timed.json" "$work"/data_*
    secs=$(python3 -c "print(round($t1 - $t0, 3))")
    fps=$(python3 -c "print(round($frames / ($t1 - $t0), 2))")
    [ -n "$base" ] || base=$fps
    rows+=("{\"size\": $size, \"replicas\": $n, \"seconds\": $secs, \"fps\": $fps, \"speedup\": $(python3 -c "print(round($fps / $base, 2))"), \"first_run_content_misses\": $misses, \"first_run_files_sent\": $sent}")
  done
done
printf '{"frames": %d, "backend": "%s", "cores": %d, "runs": [\n  %s\n]}\n' "$frames" "$gl" "$(nproc)" \
  "$(IFS=$'\n'; echo "${rows[*]}" | paste -sd, - | sed 's/},{/},\n  {/g')"
