"""Blender's evaluated (posed) vertices of a glTF file at given scene times, for the skinning
and morphing tests: imports FILE with Blender's own importer, sets the frame of each time,
and writes every mesh's evaluated world-space vertices in glTF's axes (Y up) as little-endian
f32 triples, one file per time: OUT_DIR/<name>-t<ms>.f32. Prints the importer's frame rate and
the frame it gives t = 0.

    benches/peers/cycles/run.sh posed.py FILE OUT_DIR NAME T [T ...]
"""
import struct
import sys

import bpy

path, out_dir, name = sys.argv[sys.argv.index("--") + 1:][:3] if "--" in sys.argv else sys.argv[1:4]
times = [float(t) for t in (sys.argv[sys.argv.index("--") + 4:] if "--" in sys.argv else sys.argv[4:])]

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=path)
scene = bpy.context.scene
fps = scene.render.fps / scene.render.fps_base
# The importer keys glTF time t at frame t·fps (+ the start it reports below).
starts = [a.frame_range[0] for a in bpy.data.actions] or [0.0]
print(f"fps {fps}; actions start at frames {sorted(set(starts))}")
for t in times:
    frame = t * fps
    scene.frame_set(int(frame), subframe=frame - int(frame))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    data = bytearray()
    count = 0
    # The importer adds a mesh for drawing bones (a custom shape); it is no part of the scene.
    shapes = {pb.custom_shape for o in scene.objects if o.type == "ARMATURE" for pb in o.pose.bones}
    for obj in scene.objects:
        if obj.type != "MESH" or obj in shapes:
            continue
        ev = obj.evaluated_get(depsgraph)
        mesh = ev.to_mesh()
        m = ev.matrix_world
        for v in mesh.vertices:
            w = m @ v.co
            # Blender's Z-up to glTF's Y-up: (x, y, z) -> (x, z, -y).
            data += struct.pack("<3f", w.x, w.z, -w.y)
            count += 1
        ev.to_mesh_clear()
    out = f"{out_dir}/{name}-t{round(t * 1000)}.f32"
    with open(out, "wb") as f:
        f.write(data)
    print(f"{out}: {count} vertices at t = {t} s (frame {frame})")
