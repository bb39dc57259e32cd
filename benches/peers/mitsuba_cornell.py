"""The peer on this machine: Mitsuba 3 on the Cornell box, timed as
benches/convergence/cornell.rs times ours, so the two can be compared in one session (the
machine is shared, and machines change).

The scene is ours (scenes/cornell/*.obj, materials as in tests/data/cornell/README.md), rendered
as the Mitsuba reference was: path tracer, max_depth 5 (4 scattering vertices), no roulette,
box filter, independent sampler, 256². Each spp is rendered once to compile the kernels, then
timed three times (render and evaluation, the minimum kept); relMSE is the mean of the three
against tests/data/cornell/reference-mitsuba3-16384spp.exr, with relMSE's own definition
(mean over pixels and channels of (x − r)² / (r² + 0.01)).

Set-up (PyPI and Debian, both reachable here; nothing is installed by the tests or CI):
    python3 -m venv /tmp/mi && /tmp/mi/bin/pip install mitsuba==3.9.1 numpy
    apt-get install libllvm19      # llvm_ad_rgb needs it; the default LLVM 15 crashes
Run from the repository root:
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \
        /tmp/mi/bin/python benches/peers/mitsuba_cornell.py [VARIANT] [SPP,SPP,...]
VARIANT defaults to llvm_ad_rgb (the fastest CPU variant); scalar_rgb is the one-path-at-a-time
variant. It prints CSV rows spp,seconds,rel_mse,M samples/s and the time at which relMSE first
reaches 1e-3, interpolated on log–log axes as benches/convergence/cornell.rs does.
"""

import math
import os
import sys
import time

import drjit as dr
import mitsuba as mi
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "scenes", "cornell")
REFERENCE = os.path.join(ROOT, "tests", "data", "cornell", "reference-mitsuba3-16384spp.exr")
TARGET = 1e-3

ALBEDO = {"white": [0.725, 0.725, 0.725], "red": [0.63, 0.065, 0.05], "green": [0.14, 0.45, 0.091]}
PARTS = {
    "floor": "white", "ceiling": "white", "back": "white", "short_box": "white",
    "tall_box": "white", "left_red": "red", "right_green": "green",
}


def scene_dict():
    shapes = {}
    for part, material in PARTS.items():
        shapes[part] = {
            "type": "obj", "filename": os.path.join(SCENE, part + ".obj"), "face_normals": True,
            "bsdf": {"type": "twosided",
                     "b": {"type": "diffuse", "reflectance": {"type": "rgb", "value": ALBEDO[material]}}},
        }
    # One-sided emitter (normal −y), reflecting nothing.
    shapes["light"] = {
        "type": "obj", "filename": os.path.join(SCENE, "light.obj"), "face_normals": True,
        "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}},
        "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [17.0, 12.0, 4.0]}},
    }
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 5, "rr_depth": 5},
        "sensor": {
            "type": "perspective", "fov": 39.30764811610662, "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=[2.78, 2.73, -8.0], target=[2.78, 2.73, 0.0],
                                                        up=[0.0, 1.0, 0.0]),
            "sampler": {"type": "independent"},
            "film": {"type": "hdrfilm", "width": 256, "height": 256, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
        },
        **shapes,
    }


def main():
    variant = sys.argv[1] if len(sys.argv) > 1 else "llvm_ad_rgb"
    spps = [int(s) for s in sys.argv[2].split(",")] if len(sys.argv) > 2 else [16, 32, 64, 128, 256]
    mi.set_variant(variant)
    scene = mi.load_dict(scene_dict())
    reference = np.array(mi.Bitmap(REFERENCE).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32))

    def render(spp, seed):
        t0 = time.perf_counter()
        image = mi.render(scene, spp=spp, seed=seed)
        dr.eval(image)
        dr.sync_thread()
        return time.perf_counter() - t0, np.array(image)[..., :3]

    print(f"Mitsuba {mi.__version__} {variant}, Cornell box 256², max_depth 5, independent sampler")
    print("spp,seconds,rel_mse,M samples/s")
    rows = []
    for spp in spps:
        render(spp, 1000)  # compile the kernels
        runs = [render(spp, seed) for seed in range(3)]
        seconds = min(t for t, _ in runs)
        rel_mse = float(np.mean([np.mean((x - reference) ** 2 / (reference ** 2 + 0.01)) for _, x in runs]))
        rows.append((spp, seconds, rel_mse))
        print(f"{spp},{seconds:.4f},{rel_mse:.4e},{256 * 256 * spp / seconds / 1e6:.2f}", flush=True)
    for (s0, t0, e0), (s1, t1, e1) in zip(rows, rows[1:]):
        if e0 > TARGET >= e1:
            f = math.log(e0 / TARGET) / math.log(e0 / e1)
            t = math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
            print(f"relMSE 1e-3 first reached after {t:.3f} s (log–log interpolation between {s0} and {s1} spp)")
            break
    else:
        print("relMSE 1e-3 not bracketed by these spp")


if __name__ == "__main__":
    main()
