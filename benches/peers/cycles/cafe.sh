#!/usr/bin/env bash
# The café against Cycles (issue 25's target; docs/performance.md §1.5): each view rendered by
# mcctrace and by Cycles with seeds 1 and 2, interleaved, same size, spp, 8 vertices, 2 threads,
# box filter; then `error.py` gives each renderer's time × relMSE (the variance part from its
# two seeds) and their ratio. Needs a release build (`cargo build --release`) and `setup.sh`.
# The café is not from Blender, so mcctrace would fade its spot by glTF's ramp, which Cycles
# cannot render: mcctrace gets `--spot-falloff blender` (docs/design/tracer.md §3.10).
#   benches/peers/cycles/cafe.sh [OUT_DIR] [EXTRA mcctrace FLAGS...]
# Views: VIEWS="wide:240x135:256 left:480x270:64 right:480x270:64" (name:WxH:spp) by default.
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
OUT="${1:-$ROOT/target/peers/cycles/cafe}"
shift || true
MCC="${MCCTRACE:-$ROOT/target/release/mcctrace}"
SCENE="$ROOT/scenes/cafe/cafe.gltf"
VIEWS="${VIEWS:-wide:240x135:256 left:480x270:64 right:480x270:64}"
mkdir -p "$OUT"
for view in $VIEWS; do
  IFS=: read -r name res spp <<<"$view"
  for seed in 1 2; do
    start=$(date +%s.%N)
    "$MCC" render "$SCENE" --camera "$name" --res "$res" --spp "$spp" --seed "$seed" \
      --threads 2 --max-depth 8 --spot-falloff blender --out "$OUT/mcc-$name-$seed.exr" "$@" \
      >/dev/null 2>&1
    end=$(date +%s.%N)
    echo "mcctrace,$name,$seed,$spp,$(echo "$end - $start" | bc)" >>"$OUT/times.csv"
    seconds=$("$HERE/run.sh" render.py "$SCENE" "$OUT/cycles-$name-$seed.exr" \
      --size "${res/x/,}" --spp "$spp" --camera "$name" --seed "$seed" --threads 2 --depth 8 \
      2>/dev/null | tail -1 | cut -d, -f2)
    echo "cycles,$name,$seed,$spp,$seconds" >>"$OUT/times.csv"
  done
done
"$HERE/run.sh" error.py "$OUT"
