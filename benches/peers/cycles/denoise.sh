#!/usr/bin/env bash
# Denoised against denoised (issue 44; docs/performance.md §1.7): the café's `wide` at 240×135,
# mcctrace `render --denoise` and Cycles with its OIDN denoiser (`render.py --denoise`), at 16,
# 64 and 256 spp, seeds 1 and 2, one after the other (mcctrace, then Cycles, for each spp and
# seed), 2 threads, 8 vertices, box filter, Blender's spot falloff (as cafe.sh). Each renderer's
# time is its whole process (start-up, scene import, render, denoise, writing), wall and
# user+system CPU seconds; its error is relMSE against a 1024-spp render of its own (seed 99,
# not denoised), so that neither carries the other's small differences in light transport.
# `DENOISE_BENCH_PARTS=cycles cargo bench -p mcctrace-suite --bench denoise` then prints the
# time × relMSE table. Needs a release build (`cargo build --release`), `setup.sh` and OIDN.
#   benches/peers/cycles/denoise.sh [OUT_DIR]     (default target/peers/cycles/denoise)
# SPPS="16 64 256" and SEEDS="1 2" by default; a reference already in OUT_DIR is kept.
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
OUT="${1:-$ROOT/target/peers/cycles/denoise}"
MCC="${MCCTRACE:-$ROOT/target/release/mcctrace}"
SCENE="$ROOT/scenes/cafe/cafe.gltf"
SPPS="${SPPS:-16 64 256}"
SEEDS="${SEEDS:-1 2}"
mkdir -p "$OUT"
COMMON=(--camera wide --res 240x135 --threads 2 --max-depth 8 --spot-falloff blender --quiet)
CYCLES=(--size 240,135 --camera wide --threads 2 --depth 8)

# Runs a command, appending `who,spp,seed,wall,cpu` to times.csv.
timed() {
  local who="$1" spp="$2" seed="$3"
  shift 3
  /usr/bin/time -f "%e,%U,%S" -o "$OUT/time.tmp" "$@" >"$OUT/$who-$spp-$seed.log" 2>&1
  IFS=, read -r wall user sys <"$OUT/time.tmp"
  echo "$who,$spp,$seed,$wall,$(echo "$user + $sys" | bc)" | tee -a "$OUT/times.csv"
}

if [ ! -f "$OUT/mcc-ref.exr" ]; then
  "$MCC" render "$SCENE" "${COMMON[@]}" --spp 1024 --seed 99 --out "$OUT/mcc-ref.exr"
fi
if [ ! -f "$OUT/cycles-ref.exr" ]; then
  "$HERE/run.sh" render.py "$SCENE" "$OUT/cycles-ref.exr" "${CYCLES[@]}" --spp 1024 --seed 99 >/dev/null 2>&1
fi
echo "load average before: $(cat /proc/loadavg)" | tee -a "$OUT/load.txt"
rm -f "$OUT/times.csv"
for spp in $SPPS; do
  for seed in $SEEDS; do
    timed mcc "$spp" "$seed" "$MCC" render "$SCENE" "${COMMON[@]}" --spp "$spp" --seed "$seed" \
      --denoise --out "$OUT/mcc-$spp-$seed.exr"
    timed cycles "$spp" "$seed" "$HERE/run.sh" render.py "$SCENE" "$OUT/cycles-$spp-$seed.exr" \
      "${CYCLES[@]}" --spp "$spp" --seed "$seed" --denoise
  done
done
echo "load average after: $(cat /proc/loadavg)" | tee -a "$OUT/load.txt"
