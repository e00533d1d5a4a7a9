#!/usr/bin/env bash
# The GPU check, run on the device machine from the clone's root after bundle.sh: renders of every
# test character on egl-device (renders.tgz, to compare with .dev/ref by pngdiff.py), the
# 60-frame 1024² range, dermis-bench (--no-cpu --scaling), dermis-loadbench, dermis-coldbench.
# Writes into $OUT (default /tmp/dermis-device). NVIDIA's EGL is found through glvnd.
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
OUT=${OUT:-/tmp/dermis-device}
mkdir -p "$OUT"
exec > >(tee "$OUT/log.txt") 2>&1
nvidia-smi -L
export LD_LIBRARY_PATH=$root/.dev/lib:/usr/local/nvidia/lib64:/usr/local/nvidia/lib
for f in /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json /usr/share/glvnd/egl_vendor.d/10_nvidia.json; do
  [ -f "$f" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$f && break
done
export DERMIS_CONTENT_DIR=$root DERMIS_SOURCE_DIR=$root DERMIS_SERVER_EXE=$root/.dev/bin/dermis-server
export DERMIS_TEST_MODELS=$root/tests/models
echo "=== renders"
timeout 120 scripts/device/render_all.sh egl-device /tmp/dermis-renders
tar czf "$OUT/renders.tgz" -C /tmp dermis-renders
echo "=== 60-frame range, 1024²"
for aa in "" "--aa msaa --msaa 4"; do
  rm -rf /tmp/dermis-range && mkdir -p /tmp/dermis-range
  s=$(date +%s.%N)
  # shellcheck disable=SC2086
  timeout 120 .dev/bin/dermis-server render --scene models/default.scene.json --frames 0:1.9667:0.033333 \
    --size 1024x1024 $aa --gl egl-device --out /tmp/dermis-range/f_%04d.png
  e=$(date +%s.%N)
  echo "range [${aa:-default AA}]: $(python3 -c "print(round(($e-$s)*1000/60,1))") ms/frame"
done
echo "=== benchmarks"
timeout 200 .dev/bin/dermis-bench --gl egl-device --no-cpu --scaling --repeat 15 > "$OUT/bench.json"; echo "bench rc=$?"
timeout 150 .dev/bin/dermis-loadbench --gl egl-device > "$OUT/load.json"; echo "loadbench rc=$?"
timeout 150 .dev/bin/dermis-coldbench --gl egl-device --repeat 3 > "$OUT/cold.json"; echo "coldbench rc=$?"
