#!/usr/bin/env python3
"""Writes the big-scene benchmark mesh (issue 43 item 5): a rippled terrain of N x N quads
(2 N^2 triangles; N = 1581 gives 5.0 M) as OBJ text and as a GLB, deterministic, under
target/big/ (never committed). Usage: PYTHON benches/big_mesh.py [N] [OUTDIR] (a Python with numpy, e.g.
target/peers/cycles/venv/bin/python)

The OBJ has `v` and `f a b c` lines alone (192 MB at N = 1581, as the issue measured); the
GLB holds f32 positions and u32 indices in one buffer, one node, one default material, and a
camera looking down at the terrain so `mcctrace render` needs no camera flags.
"""
import json
import os
import struct
import sys

import numpy as np

n = int(sys.argv[1]) if len(sys.argv) > 1 else 1581
out = sys.argv[2] if len(sys.argv) > 2 else "target/big"
os.makedirs(out, exist_ok=True)

# Vertices on a (n+1)^2 grid over [-1, 1]^2, height a sum of ripples (fixed, so deterministic).
s = np.linspace(-1.0, 1.0, n + 1, dtype=np.float64)
x, z = np.meshgrid(s, s)
y = 0.05 * np.sin(9.0 * x) * np.cos(7.0 * z) + 0.02 * np.sin(31.0 * (x + z))
pos = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype(np.float32)
i = np.arange(n, dtype=np.uint32)
a = (i[:, None] * (n + 1) + i[None, :]).reshape(-1)
b, c, d = a + 1, a + n + 1, a + n + 2
tris = np.stack([np.stack([a, c, b], -1), np.stack([b, c, d], -1)], 1).reshape(-1, 3)

with open(os.path.join(out, f"terrain{n}.obj"), "w") as f:
    f.write("# rippled terrain, %d triangles\n" % len(tris))
    np.savetxt(f, pos, fmt="v %.6f %.6f %.6f")
    np.savetxt(f, tris + 1, fmt="f %d %d %d")

binary = pos.tobytes() + tris.astype(np.uint32).tobytes()
lo, hi = pos.min(0).tolist(), pos.max(0).tolist()
doc = {
    "asset": {"version": "2.0", "generator": "benches/big_mesh.py"},
    "scene": 0,
    "scenes": [{"nodes": [0, 1]}],
    "nodes": [
        {"mesh": 0},
        {"camera": 0, "translation": [0.0, 2.5, 0.0], "rotation": [-0.7071068, 0.0, 0.0, 0.7071068]},
    ],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"byteLength": len(binary)}],
    "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": pos.nbytes},
        {"buffer": 0, "byteOffset": pos.nbytes, "byteLength": tris.size * 4},
    ],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3", "min": lo, "max": hi},
        {"bufferView": 1, "componentType": 5125, "count": int(tris.size), "type": "SCALAR"},
    ],
}
js = json.dumps(doc).encode()
js += b" " * (-len(js) % 4)
binary += b"\0" * (-len(binary) % 4)
with open(os.path.join(out, f"terrain{n}.glb"), "wb") as f:
    f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(binary)))
    f.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
    f.write(struct.pack("<II", len(binary), 0x004E4942) + binary)
print(f"{len(tris)} triangles, {len(pos)} vertices -> {out}/terrain{n}.obj, .glb")
