#!/usr/bin/env bash
# Installs the Debian packages Dermis needs to build and test. Used by the Makefile,
# .ci/run and docker/Dockerfile. Quick on a ready machine: it only calls apt-get when a
# package is missing.
set -euo pipefail
PKGS=(
  cmake g++ make ninja-build pkg-config
  libglm-dev libtinygltf-dev nlohmann-json3-dev libcli11-dev
  libopenimageio-dev
  libgtest-dev libgmock-dev libbenchmark-dev
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
