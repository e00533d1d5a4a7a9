#!/usr/bin/env bash
# Packs what a GPU check needs into .dev/ (ignored by git; ~18 MB): the server, the client and the
# benchmarks from build/, stripped, with the shared libraries they link that a bare Ubuntu or
# Debian machine may lack (not libc, libm, libgcc_s, libstdc++), the device-check scenes of the
# three test characters and reference renders made here on Mesa (egl-surfaceless).
# The GL test executables are not packed: they link OpenImageIO (260 libraries, 365 MB).
# Usage: scripts/device/bundle.sh [BUILD_DIR]   then run scripts/device/check.sh there
# (docs/benchmarks.md "On a GPU").
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
cd "$root"
grep -qx '/.dev/' .git/info/exclude 2>/dev/null || echo '/.dev/' >> .git/info/exclude
rm -rf .dev && mkdir -p .dev/bin .dev/lib .dev/scenes
exes=(dermis-server client/dermis bench/dermis-bench bench/dermis-coldbench bench/dermis-loadbench)
for e in "${exes[@]}"; do
  cp "$build/$e" .dev/bin/ && strip ".dev/bin/$(basename "$e")"
done
for e in "${exes[@]}"; do ldd "$build/$e"; done | awk '/=>/ {print $3}' | sort -u |
  grep -vE '/(libc|libm|libgcc_s|libstdc\+\+)\.so' | xargs -I{} cp -L {} .dev/lib/
for m in CesiumMan/CesiumMan.glb KayKitBarbarian/Barbarian.glb RiggedFigure/RiggedFigure.glb; do
  printf '{"format":"dermis.scene/1","model":"../../tests/models/%s","pose":{"time":0.5}}\n' "$m" \
    > ".dev/scenes/$(basename "$m" .glb).scene.json"
done
sed 's|"../tests/models|"../../tests/models|' examples/cesiumman.scene.json > .dev/scenes/cesium_patterns.scene.json
scripts/device/render_all.sh egl-surfaceless .dev/ref > /dev/null
du -sh .dev
