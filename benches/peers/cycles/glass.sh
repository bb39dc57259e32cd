#!/usr/bin/env bash
# Glass against Cycles (issue 39's glass figures; docs/performance.md §1.5): the rough_glass
# parity scene and the Khronos sample TransmissionTest (under a uniform sky of radiance 1 on both
# sides, `--sky 1`), each rendered by mcctrace and by Cycles with seeds 1 and 2, interleaved,
# same size, spp, 8 vertices, 2 threads; seconds are whole processes on both sides (Cycles'
# includes starting Python, bpy and the glTF import). `error.py` then gives each renderer's time ×
# relMSE (the variance part from its two seeds) and their ratio. Needs a release build and
# `setup.sh`.
#   benches/peers/cycles/glass.sh [OUT_DIR]
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
OUT="${1:-$ROOT/target/peers/cycles/glass}"
MCC="${MCCTRACE:-$ROOT/target/release/mcctrace}"
SAMPLES="${SAMPLES:-$ROOT/../shared/gltf-samples}"
# name|file|camera|WxH|spp|sky (empty: the file's own light)
CASES="${CASES:-rough_glass|$ROOT/tests/data/cycles/rough_glass/rough_glass.gltf|camera|96x72|256|
transmission|$SAMPLES/TransmissionTest/glTF/TransmissionTest.gltf|render_camera_n3d|128x96|128|1}"
mkdir -p "$OUT"
now() { date +%s.%N; }
while IFS='|' read -r name file camera res spp sky; do
  [ -n "$name" ] || continue
  mcc_sky=() cycles_sky=()
  if [ -n "$sky" ]; then mcc_sky=(--sky "$sky"); cycles_sky=(--sky "$sky"); fi
  for seed in 1 2; do
    start=$(now)
    "$MCC" render "$file" --camera "$camera" --res "$res" --spp "$spp" --seed "$seed" --threads 2 \
      --max-depth 8 "${mcc_sky[@]}" --out "$OUT/mcc-$name-$seed.exr" >/dev/null 2>&1
    echo "mcctrace,$name,$seed,$spp,$(echo "$(now) - $start" | bc)" >>"$OUT/times.csv"
    start=$(now)
    "$HERE/run.sh" render.py "$file" "$OUT/cycles-$name-$seed.exr" --size "${res/x/,}" --spp "$spp" \
      --camera "$camera" --seed "$seed" --threads 2 --depth 8 "${cycles_sky[@]}" >/dev/null 2>&1
    echo "cycles,$name,$seed,$spp,$(echo "$(now) - $start" | bc)" >>"$OUT/times.csv"
  done
done <<<"$CASES"
"$HERE/run.sh" error.py "$OUT"
