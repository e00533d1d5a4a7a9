#!/usr/bin/env bash
# ImageTest — docker/Dockerfile built and run for real (issue #25), without a Docker daemon or a
# registry: Debian's buildah (vfs storage, chroot isolation) builds the image on a debian:12 base
# made here by debootstrap from the mirror apt uses (once: it stays in the store), then runs the
# server from it on the host's network and checks it from outside and with the image's own tools:
#   * the image: at most DERMIS_IMAGE_MAX_MB (400) MB, non-root user, health check, entry point,
#     port; no compiler, Node or browser in it; every library the executables need is there (ldd);
#   * the server: starts from the image with its content folder (default scene), answers
#     /api/v1/health (host curl, and curl and `dermis health` inside the image), renders the
#     default scene to a PNG of the size asked, by the API and by the image's `dermis frame`;
#     an EXR height map is refused as unavailable (no OpenImageIO) while the server stays up;
#     stops on SIGTERM with exit status 0;
#   * with DERMIS_IMAGE_OIIO=1, also the image built with --build-arg DERMIS_OIIO=1 (tag
#     dermis:oiio): its image module loads (ldd) and the EXR height map comes back (size printed,
#     not bounded).
# Repeat runs are fast: the base image and the build layers stay in the store (--layers), and the
# host's ccache (ccache's cache_dir, or $DERMIS_IMAGE_CCACHE) is the builder's /ccache.
# Environment: DERMIS_IMAGE_TAG (dermis), DERMIS_IMAGE_MAX_MB (400),
#   DERMIS_IMAGE_TIMEOUT (whole script, seconds: 5400), DERMIS_IMAGE_CONTEXT (the build context:
#   this clone), DERMIS_IMAGE_CCACHE, DERMIS_IMAGE_OIIO (0), DERMIS_IMAGE_KEEP_BASE (1: leave the
#   debootstrap tree in /var/tmp/dermis-debootstrap).
# Needs root (apt-get, buildah's chroot isolation). Prints one PASS/FAIL line per check, the time
# of every step and "N passed, M failed"; exit status 0 only when nothing failed.
# Usage: tests/docker/image_test.sh          (make test-image)
set -euo pipefail

here=$(cd "$(dirname "$0")/../.." && pwd)
limit=${DERMIS_IMAGE_TIMEOUT:-5400}
# Bounded: the whole run under timeout(1), in a process group of its own that it signals whole
# when the time is up; SIGINT/SIGTERM to this script are passed on to it the same way.
if [ -z "${DERMIS_IMAGE_TEST_INNER:-}" ]; then
  DERMIS_IMAGE_TEST_INNER=1 timeout -k 60 "$limit" bash "$0" "$@" &
  tpid=$!
  trap 'kill -TERM "$tpid" 2>/dev/null' INT TERM
  rc=0
  wait "$tpid" || rc=$?
  while kill -0 "$tpid" 2>/dev/null; do rc=0; wait "$tpid" || rc=$?; done # after a signal
  [ "$rc" -eq 124 ] && echo "FAIL: image test: over DERMIS_IMAGE_TIMEOUT=${limit}s"
  exit "$rc"
fi

tag=${DERMIS_IMAGE_TAG:-dermis}
max_mb=${DERMIS_IMAGE_MAX_MB:-400}
context=${DERMIS_IMAGE_CONTEXT:-$here}
oiio=${DERMIS_IMAGE_OIIO:-0}
B=(buildah --storage-driver vfs)
tmp=$(mktemp -d /tmp/dermis-image-test.XXXXXX)
passed=0 failed=0
steps=()
ctrs=()
server_pid=""

log() { echo "image-test: $*"; }
pass() { passed=$((passed + 1)); echo "PASS: $*"; }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }
check() { # check "what" command...
  local what=$1; shift
  if "$@" >"$tmp/check.out" 2>&1; then pass "$what"; else fail "$what"; sed 's/^/  | /' "$tmp/check.out" | tail -20; fi
}
step_start() { step_name=$1; step_t0=$(date +%s.%N); log "$1 ..."; }
step_end() {
  local s; s=$(awk -v a="$step_t0" -v b="$(date +%s.%N)" 'BEGIN{printf "%.1f", b - a}')
  steps+=("$(printf '%-44s %7s s' "$step_name" "$s")")
  log "$step_name: $s s"
}
summary() {
  echo "--- step times (this machine: $(nproc) cores)"
  for s in "${steps[@]}"; do echo "  $s"; done
  echo "$passed passed, $failed failed"
}
# server_of PID: the dermis-server process that `buildah run` (PID) started, else PID. buildah's
# chroot isolation starts no PID namespace: the server is a descendant on this machine.
server_of() {
  local pids=("$1") found="" i=0 pid ppid comm
  while [ $i -lt ${#pids[@]} ]; do
    while read -r pid ppid comm; do
      [ "$ppid" = "${pids[$i]}" ] || continue
      pids+=("$pid")
      [ "$comm" = dermis-server ] && [ -z "$found" ] && found=$pid
    done < <(ps -e -o pid=,ppid=,comm=)
    i=$((i + 1))
  done
  echo "${found:-$1}"
}
stop_server() {
  [ -n "$server_pid" ] || return 0
  # buildah run (chroot isolation) runs the server as its child, in no PID namespace: signal the
  # server by its id, then wait for buildah run to return its exit status.
  kill -TERM "$(server_of "$server_pid")" 2>/dev/null || true
  for _ in $(seq 100); do kill -0 "$server_pid" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$server_pid" 2>/dev/null || true
  server_pid=""
}
ctrs_before="" # the store's containers before this run: an interrupted build leaves its own behind
cleanup() {
  stop_server
  if [ -n "$ctrs_before" ]; then
    while read -r c; do ctrs+=("$c"); done < <("${B[@]}" containers -q 2>/dev/null | sort |
                                                comm -13 <(echo "$ctrs_before") -)
  fi
  for c in "${ctrs[@]}"; do "${B[@]}" rm "$c" >/dev/null 2>&1 || true; done
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 143' TERM INT
die() { fail "$*"; summary; exit 1; }

[ "$(id -u)" -eq 0 ] || die "run as root (apt-get, buildah's chroot isolation)"

# --- 1. tools --------------------------------------------------------------------------------
step_start "tools (buildah podman debootstrap)"
missing=()
for p in buildah podman debootstrap; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  log "installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  timeout 600 apt-get update -qq || die "apt-get update"
  timeout 900 apt-get install -y -qq --no-install-recommends "${missing[@]}" >"$tmp/apt.log" 2>&1 ||
    { tail -20 "$tmp/apt.log"; die "apt-get install ${missing[*]}"; }
fi
step_end

# --- 2. the debian:12 base, made once ----------------------------------------------------------
# The mirror apt uses for a suite (deb lines or deb822 .sources), else deb.debian.org.
mirror_of() {
  local suite=$1 fallback=$2 m
  m=$( { sed -E 's/\[[^]]*\]//' /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null |
           awk -v s="$suite" '$1 == "deb" && $3 == s {print $2}'
         awk -v s="$suite" 'BEGIN{RS=""} /(^|\n)Types:[^\n]*deb([ \n]|$)/ {
             u=""; ok=0; n=split($0, l, "\n")
             for (i = 1; i <= n; i++) {
               if (l[i] ~ /^URIs:/) { split(l[i], f, " "); u=f[2] }
               if (l[i] ~ /^Suites:/) { k=split(l[i], f, " "); for (j = 2; j <= k; j++) if (f[j] == s) ok=1 }
             }
             if (ok && u != "") print u }' /etc/apt/sources.list.d/*.sources 2>/dev/null; } | head -1)
  echo "${m:-$fallback}"
}
step_start "base image debian:12"
if [ -n "$("${B[@]}" images -q debian:12 2>/dev/null)" ]; then
  log "debian:12 is in the store: $("${B[@]}" images --noheading debian:12 | head -1)"
else
  main=$(mirror_of bookworm http://deb.debian.org/debian)
  security=$(mirror_of bookworm-security http://deb.debian.org/debian-security)
  root=/var/tmp/dermis-debootstrap/rootfs
  rm -rf "$root" && mkdir -p "$root"
  log "debootstrap --variant=minbase bookworm from $main"
  timeout 1200 debootstrap --variant=minbase bookworm "$root" "$main" >"$tmp/debootstrap.log" 2>&1 ||
    { tail -20 "$tmp/debootstrap.log"; die "debootstrap"; }
  # As the official image: bookworm, -updates and -security; no package lists or archives.
  rm -f "$root/etc/apt/sources.list"
  cat >"$root/etc/apt/sources.list.d/debian.sources" <<EOF
Types: deb
URIs: $main
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: $security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  rm -rf "$root"/var/lib/apt/lists/* "$root"/var/cache/apt/*.bin "$root"/var/cache/apt/archives/*.deb
  tar -C "$root" -c . | podman --storage-driver vfs import \
    --change 'ENV=PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
    --change 'CMD=["bash"]' - debian:12 >/dev/null || die "podman import debian:12"
  [ "${DERMIS_IMAGE_KEEP_BASE:-0}" = 1 ] || { rm -rf "$root"; rmdir "${root%/*}" 2>/dev/null || true; }
fi
step_end

# --- 3. the image ------------------------------------------------------------------------------
ctrs_before=$( { echo none; "${B[@]}" containers -q 2>/dev/null; } | sort)
ccache_dir=${DERMIS_IMAGE_CCACHE:-$(ccache -k cache_dir 2>/dev/null || echo "$HOME/.cache/ccache")}
mkdir -p "$ccache_dir"
# build TAG LOG [--build-arg …]: the image TAG, its builder stage tagged TAG-builder (so that it
# stays in the store as the cache of the next build), then the layers of earlier builds no tag
# leads to are removed (with vfs storage every layer is a whole copy of its tree: ~1.5 GB a
# builder step).
build() {
  local t=$1 out=$2; shift 2
  timeout "$limit" "${B[@]}" bud --isolation chroot --format docker --layers --pull-never \
    --volume "$ccache_dir:/ccache" "$@" \
    -t "$t" -f "$context/docker/Dockerfile" "$context" >"$out" 2>&1 || return 1
  local builder
  builder=$(awk '/^--> [0-9a-f]+$/ {id = $2} /^\[2\/2\] STEP 1\// {print id; exit}' "$out")
  local btag="$t-builder"
  [[ "$t" == *:* ]] && btag="${t%%:*}-builder:${t#*:}"
  [ -z "$builder" ] || "${B[@]}" tag "$builder" "$btag"
  for _ in $(seq 30); do
    [ -n "$("${B[@]}" rmi --prune 2>/dev/null)" ] || break
  done
}
step_start "build $tag (ccache $ccache_dir)"
if build "$tag" "$tmp/build.log"; then
  pass "buildah bud -f docker/Dockerfile -t $tag"
  grep -E '^builder: compiled|^ *(Hits|Misses)' "$tmp/build.log" | sed 's/^/  /' || log "compile layer from the cache"
else
  tail -40 "$tmp/build.log"
  die "buildah bud -f docker/Dockerfile -t $tag"
fi
step_end

# --- 4. what is in the image -------------------------------------------------------------------
step_start "image checks"
bytes=$(podman --storage-driver vfs image inspect --format '{{.Size}}' "$tag")
mb=$((bytes / 1000000))
"${B[@]}" images "$tag"
log "runtime image $tag: $mb MB ($bytes bytes)"
check "image size $mb MB <= $max_mb MB" test "$mb" -le "$max_mb"
"${B[@]}" inspect --type image "$tag" >"$tmp/inspect.json"
check "image config: non-root user, entry point, CMD serve, port 8080, health check, content dir" python3 - "$tmp/inspect.json" <<'EOF'
import json, sys
c = json.load(open(sys.argv[1]))["Docker"]["config"]  # the docker format keeps HEALTHCHECK
problems = []
if c.get("User") in (None, "", "root", "0"): problems.append(f"user {c.get('User')!r}")
if not (c.get("Entrypoint") or [""])[0].endswith("/dermis-server"): problems.append(f"entrypoint {c.get('Entrypoint')}")
if (c.get("Cmd") or [""])[0] != "serve": problems.append(f"cmd {c.get('Cmd')}")
if "8080/tcp" not in (c.get("ExposedPorts") or {}): problems.append(f"ports {c.get('ExposedPorts')}")
hc = (c.get("Healthcheck") or {}).get("Test") or []
if not any("/api/v1/health" in t for t in hc): problems.append(f"healthcheck {hc}")
if not any(e.startswith("DERMIS_CONTENT_DIR=") for e in c.get("Env") or []): problems.append("no DERMIS_CONTENT_DIR")
print("\n".join(problems) or json.dumps(c, indent=1))
sys.exit(1 if problems else 0)
EOF
ctr=$("${B[@]}" from --pull-never "$tag") || die "buildah from $tag"
ctrs+=("$ctr")
in_image() { "${B[@]}" run --isolation chroot --network host "$ctr" -- "$@"; }
check "no build or test tools in the image (g++, cmake, node, chromium, nginx, clang)" \
  in_image sh -c 'for t in g++ cc cmake ninja node npm chromium nginx clang; do
                    if command -v $t; then echo "found $t"; exit 1; fi; done'
check "every library of dermis-server, dermis and what is beside them resolves (ldd)" \
  in_image sh -c 'set -e; ls -la /opt/dermis/bin; for f in /opt/dermis/bin/*; do
                    ldd "$f" > /tmp/ldd.txt; if grep "not found" /tmp/ldd.txt; then echo "in $f"; exit 1; fi; done'
check "the image's processes run as dermis (uid 10001), \$HOME /data writable" \
  in_image sh -c 'id; [ "$(id -u)" = 10001 ] && touch /data/.w && rm /data/.w'
check "content folder: patterns/manifest.json, models/default.glb, web/index.html" \
  in_image sh -c 'cd "$DERMIS_CONTENT_DIR" && ls -l patterns/manifest.json models/default.glb models/default.scene.json web/index.html'
check "dermis-server info (GL backend) from the image" in_image dermis-server info
in_image dermis-server info 2>/dev/null | head -c 600 && echo
step_end

# --- 5. the server from the image --------------------------------------------------------------
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
# run_server CTR LOG: the server of CTR on a free port in the background ($server_pid, $port).
run_server() {
  port=$(free_port)
  "${B[@]}" run --isolation chroot --network host "$1" -- \
    /opt/dermis/bin/dermis-server serve --bind 127.0.0.1 --port "$port" --data /data >"$2" 2>&1 &
  server_pid=$!
  local t0=$SECONDS
  while [ $((SECONDS - t0)) -lt 120 ]; do
    curl -fsS "http://127.0.0.1:$port/api/v1/health" >/dev/null 2>&1 && return 0
    kill -0 "$server_pid" 2>/dev/null || break
    sleep 0.2
  done
  cat "$2"
  return 1
}
# png_size FILE: "W H" of a PNG (signature and IHDR checked).
png_size() {
  python3 - "$1" <<'EOF'
import struct, sys
b = open(sys.argv[1], "rb").read()
assert b[:8] == b"\x89PNG\r\n\x1a\n" and b[12:16] == b"IHDR", f"not a PNG: {b[:16]!r}"
print(*struct.unpack(">II", b[16:24]))
EOF
}

step_start "server start (to /api/v1/health)"
run_server "$ctr" "$tmp/server.log" && pass "dermis-server serve from the image answers /api/v1/health" ||
  die "dermis-server serve from the image did not answer /api/v1/health"
step_end
head -3 "$tmp/server.log" | sed 's/^/  /'
api="http://127.0.0.1:$port/api/v1"
step_start "render through the API and the client"
check "the image's curl (HEALTHCHECK) and \`dermis health\`" \
  in_image sh -c "curl -fsS $api/health && echo && dermis --server http://127.0.0.1:$port health"
scene=$(curl -fsS "$api/scenes" | python3 -c 'import json,sys; print(json.load(sys.stdin)["scenes"][0]["id"])') ||
  die "no default scene in GET /scenes"
log "default scene $scene"
w=320 h=240
api_frame() {
  curl -fsS -o "$tmp/api.png" "$api/scenes/$scene/frame?format=png&width=$w&height=$h" &&
    size=$(png_size "$tmp/api.png") && echo "$size" && [ "$size" = "$w $h" ]
}
check "GET /scenes/$scene/frame?format=png&width=$w&height=$h is a ${w}x${h} PNG" api_frame
if in_image dermis --server "http://127.0.0.1:$port" frame "$scene" -o /tmp/client.png --width 256 --height 192 \
     >"$tmp/client.log" 2>&1 && in_image cat /tmp/client.png >"$tmp/client.png" &&
   [ "$(png_size "$tmp/client.png")" = "256 192" ]; then
  pass "the image's \`dermis frame $scene -o client.png --width 256 --height 192\` wrote a 256x192 PNG"
else
  fail "the image's \`dermis frame\`"; cat "$tmp/client.log"
fi
code=$(curl -sS -o "$tmp/exr.out" -w '%{http_code}' "$api/scenes/$scene/heightmaps/bump?format=exr" || echo 000)
check "EXR height map without OpenImageIO: refused ($code), the server still up" \
  sh -c "[ '$code' != 200 ] && [ '$code' != 000 ] && grep -qi 'unavailable\|libdermis_oiio' '$tmp/exr.out' &&
         curl -fsS '$api/health' >/dev/null"
step_end

step_start "server stop (SIGTERM)"
stop_pid=$server_pid
kill -TERM "$(server_of "$stop_pid")"
rc=0; wait "$stop_pid" || rc=$?
server_pid=""
check "SIGTERM stops the server with status 0 (\"stopped\")" sh -c "[ $rc -eq 0 ] && grep -q 'dermis-server: stopped' '$tmp/server.log'"
step_end

# --- 6. the variant with OpenImageIO (DERMIS_IMAGE_OIIO=1) ------------------------------------------
if [ "$oiio" = 1 ]; then
  step_start "build $tag:oiio (--build-arg DERMIS_OIIO=1)"
  if build "$tag:oiio" "$tmp/build-oiio.log" --build-arg DERMIS_OIIO=1; then
    pass "buildah bud --build-arg DERMIS_OIIO=1 -t $tag:oiio"
  else
    tail -40 "$tmp/build-oiio.log"; die "buildah bud --build-arg DERMIS_OIIO=1"
  fi
  step_end
  step_start "$tag:oiio checks"
  obytes=$(podman --storage-driver vfs image inspect --format '{{.Size}}' "$tag:oiio")
  log "image $tag:oiio: $((obytes / 1000000)) MB"
  octr=$("${B[@]}" from --pull-never "$tag:oiio") || die "buildah from $tag:oiio"
  ctrs+=("$octr")
  check "$tag:oiio: libdermis_oiio.so beside dermis-server and all its libraries resolve" \
    "${B[@]}" run --isolation chroot "$octr" -- sh -c 'ldd /opt/dermis/bin/libdermis_oiio.so > /tmp/l && ! grep "not found" /tmp/l'
  if run_server "$octr" "$tmp/server-oiio.log"; then
    oscene=$(curl -fsS "http://127.0.0.1:$port/api/v1/scenes" | python3 -c 'import json,sys; print(json.load(sys.stdin)["scenes"][0]["id"])')
    check "$tag:oiio: GET /scenes/$oscene/heightmaps/bump?format=exr is an OpenEXR file" \
      sh -c "curl -fsS -o '$tmp/bump.exr' 'http://127.0.0.1:$port/api/v1/scenes/$oscene/heightmaps/bump?format=exr' &&
             [ \"\$(head -c 4 '$tmp/bump.exr' | od -An -tx1 | tr -d ' ')\" = 762f3101 ]"
  else
    fail "$tag:oiio: the server did not start"
  fi
  stop_server
  step_end
fi

summary
[ "$failed" -eq 0 ]
