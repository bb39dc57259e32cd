#!/usr/bin/env bash
# Makes the Cycles peer's venv: Blender 5.0.1 as a Python module (`bpy`, about 1 GB, needs
# Python 3.11). VENV defaults to target/peers/cycles/venv (under the ignored target folder).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../../.." && pwd)"
VENV="${VENV:-$ROOT/target/peers/cycles/venv}"
PYTHON="${PYTHON:-python3.11}"
if [ ! -x "$VENV/bin/python" ]; then
  "$PYTHON" -m venv "$VENV"
fi
"$VENV/bin/pip" install --quiet bpy==5.0.1 numpy==1.26.4
"$VENV/bin/python" -c "import bpy; print('bpy', bpy.app.version_string)"
