"""Cycles as a peer: imports a glTF with Blender's own importer and renders it with Cycles on the
CPU under settings that match mcctrace's (docs/testing.md §5), then reports time and error.

Run it with the venv's Python (`setup.sh` makes the venv; `run.sh` sets the scratch folders and
calls this). Usage:
    render.py SCENE.gltf OUT.exr --size W,H --spp N [--depth D] [--camera NAME] [--seed S]
              [--threads T] [--reference REF.exr] [--noise-spp M]

- `--depth` is mcctrace's scattering vertices (default 8); Cycles' `max_bounces` is one less,
  and the diffuse, glossy and transmission limits equal it (their defaults are lower).
- `--reference` prints relMSE (mean over pixels and channels of (x − r)² / (r² + 0.01)) and the
  per-channel means of both images.
- `--noise-spp M` renders the scene again at M spp with another seed and prints the estimated
  relMSE of OUT itself: relMSE(OUT, second) · N / (N + M) · M / N … see `noise_of`.

Prints one CSV row `spp,seconds,rel_mse` (rel_mse empty without a reference) as its last line.
"""

import argparse
import json
import os
import sys
import time

import bpy
import numpy as np


def math_node(tree, operation, a=None, b=None):
    """A Math node of `tree` computing `operation`; each input is a number, a socket to link
    from, or None (left as it is)."""
    node = tree.nodes.new("ShaderNodeMath")
    node.operation = operation
    for socket, value in zip(node.inputs, (a, b)):
        if isinstance(value, (int, float)):
            socket.default_value = value
        elif value is not None:
            tree.links.new(value, socket)
    return node


def one_sided_emission(gltf_path):
    """Blender's importer drops `doubleSided: false`, so Cycles would emit from both faces of an
    emissive surface that glTF (and mcctrace, docs/design/tracer.md §3.9) lights from the front only.
    For each such material, multiply its Principled BSDF's emission strength by (1 − Backfacing)
    from a Geometry node: the back face then emits nothing, the front face as before. Returns
    the names of the materials changed."""
    with open(gltf_path, encoding="utf-8") as f:
        doc = json.load(f)
    changed = []
    for m in doc.get("materials", []):
        emissive = m.get("emissiveFactor", [0.0, 0.0, 0.0])
        if m.get("doubleSided", False) or max(emissive) <= 0.0:
            continue
        mat = bpy.data.materials.get(m.get("name", ""))
        if mat is None or mat.node_tree is None:
            raise SystemExit(f"{gltf_path}: emissive material {m.get('name')!r} not found after import")
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        bsdf = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
        if bsdf is None:
            raise SystemExit(f"{gltf_path}: material {mat.name!r} has no Principled BSDF")
        strength = bsdf.inputs["Emission Strength"]
        geometry = nodes.new("ShaderNodeNewGeometry")
        front = math_node(mat.node_tree, "SUBTRACT", 1.0, geometry.outputs["Backfacing"])
        scale = math_node(mat.node_tree, "MULTIPLY")
        if strength.is_linked:
            links.new(strength.links[0].from_socket, scale.inputs[0])
        else:
            scale.inputs[0].default_value = strength.default_value
        links.new(front.outputs[0], scale.inputs[1])
        links.new(scale.outputs[0], strength)
        changed.append(mat.name)
    return changed


def import_scene(gltf_path, camera):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=os.path.abspath(gltf_path))
    scene = bpy.context.scene
    cameras = [o for o in scene.objects if o.type == "CAMERA"]
    if camera is not None:
        cameras = [o for o in cameras if camera in (o.name, o.data.name)]
    if not cameras:
        raise SystemExit(f"{gltf_path}: no camera {camera or ''} in the file")
    scene.camera = cameras[0]
    # glTF's punctual lights are points: the importer leaves Blender's default radius, which
    # would make them small spheres (softer shadows, another near field).
    for o in scene.objects:
        if o.type == "LIGHT" and o.data.type in ("POINT", "SPOT"):
            o.data.shadow_soft_size = 0.0
    # glTF has no background; the factory world is grey.
    scene.world = None
    # The importer gives each bone a custom shape (a mesh object for drawing it in the
    # viewport): it is no part of the file's scene and must not render.
    for o in scene.objects:
        if o.type == "ARMATURE":
            for pb in o.pose.bones:
                if pb.custom_shape is not None:
                    pb.custom_shape.hide_render = True
    return scene


def at_frame(scene, frame, shutter):
    """The imported scene at `frame` (glTF time frame / fps: the importer keys time t at frame
    t · fps), with motion blur over `shutter` frames from the frame on (position START, which is
    mcctrace's `--shutter 0..shutter`; 0 is none). Objects keep Blender's default motion steps
    (Steps 1: 3 steps), deformation blur on."""
    scene.frame_set(int(frame), subframe=frame - int(frame))
    scene.render.use_motion_blur = shutter > 0.0
    scene.render.motion_blur_shutter = max(shutter, 0.0)
    scene.render.motion_blur_position = "START"
    scene.cycles.rolling_shutter_type = "NONE"


def environment(scene, path):
    """A world lit by the equirectangular image at `path` (strength 1), as `--env-map` is."""
    world = bpy.data.worlds.new("environment")
    world.use_nodes = True
    nodes = world.node_tree.nodes
    texture = nodes.new("ShaderNodeTexEnvironment")
    texture.image = bpy.data.images.load(os.path.abspath(path))
    world.node_tree.links.new(texture.outputs["Color"], nodes["Background"].inputs["Color"])
    nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world


def uniform_sky(scene, radiance):
    """A world of constant radiance (a Background node of that grey, strength 1), as mcctrace's
    `--sky` gives a model without light; Cycles samples it as a light, as mcctrace does."""
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (radiance, radiance, radiance, 1.0)
    background.inputs["Strength"].default_value = 1.0
    scene.world = world


def configure(scene, size, spp, depth, seed, threads, denoise=False, guiding=False):
    scene.render.engine = "CYCLES"
    c = scene.cycles
    bounces = depth - 1
    settings = {
        "device": "CPU",
        "samples": spp,
        "seed": seed,
        "use_animated_seed": False,
        "use_adaptive_sampling": False,
        "use_denoising": False,
        "sample_clamp_direct": 0.0,
        "sample_clamp_indirect": 0.0,
        "light_sampling_threshold": 0.0,
        "blur_glossy": 0.0,
        "caustics_reflective": True,
        "caustics_refractive": True,
        # Path guiding (Open PGL) ships off; `--guiding` turns it on with its default training.
        "use_guiding": guiding,
        "max_bounces": bounces,
        "diffuse_bounces": bounces,
        "glossy_bounces": bounces,
        "transmission_bounces": bounces,
        "volume_bounces": 0,
        # An alpha-masked hole is a transparent bounce in Cycles and no vertex in mcctrace.
        "transparent_max_bounces": 64,
        "min_light_bounces": 0,
        "min_transparent_bounces": 0,
        "pixel_filter_type": "BOX",
        "filter_width": 1.0,
    }
    if denoise:
        # Cycles' own OIDN denoiser on the final render, guided by albedo and normal with its
        # accurate prefilter (the comparison of docs/performance.md, "Denoising").
        settings.update({
            "use_denoising": True,
            "denoiser": "OPENIMAGEDENOISE",
            "denoising_input_passes": "RGB_ALBEDO_NORMAL",
            "denoising_prefilter": "ACCURATE",
            "denoising_use_gpu": False,
        })
    for name, value in settings.items():
        setattr(c, name, value)
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.render.film_transparent = False
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    s = scene.render.image_settings
    s.file_format = "OPEN_EXR"
    s.color_depth = "32"
    s.color_mode = "RGB"
    s.exr_codec = "ZIP"


def render(scene, out):
    scene.render.filepath = os.path.abspath(out)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return time.perf_counter() - t0


def load_rgb(path):
    image = bpy.data.images.load(os.path.abspath(path), check_existing=False)
    w, h = image.size
    pixels = np.empty(w * h * image.channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    rgb = pixels.reshape(h, w, image.channels)[:, :, :3].astype(np.float64)
    bpy.data.images.remove(image)
    return rgb


def rel_mse(x, r):
    return float(np.mean((x - r) ** 2 / (r * r + 0.01)))


def noise_of(out, second, n, m):
    """Estimated relMSE of the N-spp image against the truth from a second, independent M-spp
    render: with per-sample variance σ² (noise falling as 1/spp), E[relMSE(out, second)] =
    σ²/N + σ²/M, so relMSE(out) ≈ relMSE(out, second) · M / (N + M). Cycles' quasi-random
    sampling converges a little faster than 1/spp, which makes this an overestimate."""
    return rel_mse(out, second) * m / (n + m)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("gltf")
    p.add_argument("out")
    p.add_argument("--size", required=True, help="W,H in pixels")
    p.add_argument("--spp", type=int, required=True)
    p.add_argument("--depth", type=int, default=8, help="mcctrace's scattering vertices")
    p.add_argument("--camera")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--reference")
    p.add_argument("--noise-spp", type=int)
    p.add_argument("--denoise", action="store_true", help="Cycles' OIDN denoiser on (albedo+normal)")
    p.add_argument("--env-map", help="an equirectangular image lighting the scene (a world)")
    p.add_argument("--guiding", action="store_true", help="Cycles' path guiding on")
    p.add_argument("--sky", type=float, help="a uniform world of this radiance (mcctrace's --sky)")
    a = p.parse_args(argv)
    size = tuple(int(v) for v in a.size.split(","))
    scene = import_scene(a.gltf, a.camera)
    changed = one_sided_emission(a.gltf)
    if changed:
        print(f"one-sided emission (doubleSided: false) restored on: {', '.join(changed)}")
    if a.env_map:
        environment(scene, a.env_map)
    configure(scene, size, a.spp, a.depth, a.seed, a.threads, a.denoise, a.guiding)
    if a.sky is not None:
        uniform_sky(scene, a.sky)
    seconds = render(scene, a.out)
    image = load_rgb(a.out)
    print(f"{a.out}: {a.spp} spp in {seconds:.2f} s, channel means {image.mean(axis=(0, 1))}")
    err = ""
    if a.reference:
        ref = load_rgb(a.reference)
        err = f"{rel_mse(image, ref):.4e}"
        print(f"against {a.reference}: relMSE {err}, reference means {ref.mean(axis=(0, 1))}")
    if a.noise_spp:
        second_path = os.path.splitext(a.out)[0] + ".noise.exr"
        scene.cycles.samples = a.noise_spp
        scene.cycles.seed = a.seed + 1
        render(scene, second_path)
        second = load_rgb(second_path)
        os.remove(second_path)
        print(f"estimated own noise of {a.out}: relMSE {noise_of(image, second, a.spp, a.noise_spp):.3e}")
    print("spp,seconds,rel_mse")
    print(f"{a.spp},{seconds:.3f},{err}")


if __name__ == "__main__":
    main()
