#!/usr/bin/env bash
# Runs a script of this folder with the Cycles venv's Python (`setup.sh` makes it), with
# Blender's user resources, temporary files and caches in a scratch folder, never in $HOME.
#   benches/peers/cycles/run.sh render.py SCENE.gltf OUT.exr --size 128,96 --spp 256 ...
#   benches/peers/cycles/run.sh scenes.py
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
VENV="${VENV:-$ROOT/target/peers/cycles/venv}"
SCRATCH="${SCRATCH:-$ROOT/target/peers/cycles/scratch}"
mkdir -p "$SCRATCH/resources" "$SCRATCH/tmp" "$SCRATCH/cache"
export BLENDER_USER_RESOURCES="$SCRATCH/resources" TMPDIR="$SCRATCH/tmp" XDG_CACHE_HOME="$SCRATCH/cache"
script="$1"
shift
exec "$VENV/bin/python" "$HERE/$script" "$@"
