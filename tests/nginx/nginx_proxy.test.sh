#!/usr/bin/env bash
# NginxProxyHttpTest — docker/nginx.conf in front of dermis-server (docs/reliability.md): nginx
# in the foreground with a temporary prefix, the config's ports and body size replaced; a frame
# and an event stream's first event pass through, a body over client_max_body_size is answered
# 413 by nginx in the API's error shape. Usage: nginx_proxy.test.sh DERMIS_SERVER NGINX_CONF
set -euo pipefail
server_exe=$1 conf=$2
tmp=$(mktemp -d)
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; rm -rf "$tmp"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; echo "--- server log"; cat "$tmp/server.log" || true; echo "--- nginx log"; cat "$tmp/nginx.log" || true; exit 1; }
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }

"$server_exe" serve --port 0 --data "$tmp/data" --gl "${DERMIS_TEST_GL:-auto}" --max-upload-mb 2 >"$tmp/server.log" 2>&1 &
pids+=($!)
for _ in $(seq 600); do grep -q "serving http://127.0.0.1:" "$tmp/server.log" && break; sleep 0.05; done
upstream=$(sed -n 's|.*serving http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$tmp/server.log" | head -1)
scene=$(sed -n 's|.*: scene \([^:]*\): .*|\1|p' "$tmp/server.log" | head -1)
[ -n "$upstream" ] && [ -n "$scene" ] || fail "dermis-server did not start"

port=$(free_port)
mkdir -p "$tmp/nginx/logs"
sed -e "s|server 127.0.0.1:8080;|server 127.0.0.1:$upstream;|" -e "s|listen 80;|listen 127.0.0.1:$port;|" \
    -e "s|client_max_body_size 64m;|client_max_body_size 2m;|" "$conf" >"$tmp/nginx/nginx.conf"
grep -q "listen 127.0.0.1:$port;" "$tmp/nginx/nginx.conf" || fail "config: listen line not found"
nginx -p "$tmp/nginx" -c "$tmp/nginx/nginx.conf" -g "daemon off; pid $tmp/nginx/nginx.pid; error_log $tmp/nginx.log;" &
pids+=($!)
base="http://127.0.0.1:$port/api/v1"
for _ in $(seq 100); do curl -s -o /dev/null "$base/health" && break; sleep 0.05; done

# A frame through the proxy.
code=$(curl -s -m 60 -o "$tmp/frame.png" -w '%{http_code} %{content_type}' "$base/scenes/$scene/frame")
[ "$code" = "200 image/png" ] || fail "frame: $code"
# The event stream's first event arrives through the proxy at once (not buffered).
curl -s -N -m 3 "$base/scenes/$scene/events" >"$tmp/events.txt" || true
grep -q "event: hello" "$tmp/events.txt" || fail "events: no hello within 3 s: $(head -c 300 "$tmp/events.txt")"
# A body over client_max_body_size: 413 from nginx, before the body is read, in the API's shape.
answer=$(python3 - "$port" <<'PY'
import socket, sys
s = socket.create_connection(("127.0.0.1", int(sys.argv[1])), timeout=5)
s.sendall(b"POST /api/v1/patterns HTTP/1.1\r\nHost: t\r\nContent-Type: image/png\r\nContent-Length: 100000000\r\n\r\n")
data = b""
while True:
    d = s.recv(65536)
    if not d: break
    data += d
    if b"}}" in data: break
print(data.decode(errors="replace"))
PY
)
# (Here-strings, not `echo | head | grep -q`: under pipefail the early exit of head or grep -q
# can kill echo with SIGPIPE and fail the check on a right answer — it did once in CI.)
[[ "$answer" == "HTTP/1.1 413"* ]] || fail "large body: $answer"
grep -q '"code":"too_large"' <<<"$answer" || fail "large body shape: $answer"
echo "NginxProxyHttpTest: frame, event stream and 413 through nginx $(nginx -v 2>&1 | sed 's|.*/||') passed"
