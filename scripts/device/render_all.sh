#!/usr/bin/env bash
# Renders the default scene and .dev/scenes/* with GL backend $1 into folder $2: shaded and normal
# views at 1024², with --timings beside each image. Uses the packed .dev/bin (bundle.sh).
set -uo pipefail
gl=$1 out=$2
root=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out"
export LD_LIBRARY_PATH=$root/.dev/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH} DERMIS_CONTENT_DIR=$root
for s in "$root"/models/default.scene.json "$root"/.dev/scenes/*.scene.json; do
  n=$(basename "$s" .scene.json)
  for v in shaded normal; do
    "$root"/.dev/bin/dermis-server render --scene "$s" --out "$out/$n.$v.png" --size 1024x1024 \
      --view $v --gl "$gl" --timings 2> "$out/$n.$v.timings.json" || echo "FAILED $n $v"
  done
done
