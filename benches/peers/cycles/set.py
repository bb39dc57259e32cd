"""The benchmark set (docs/performance.md §1): mcctrace and Cycles side by side on every Cycles
parity scene, the café's three views and the glass and glossy sample models, two seeds each, in
one run, interleaved; then per scene each renderer's time × relMSE and their ratio, where the
error sits (the top 1 % of pixels' share, a variance map), a table and a plot.

    benches/peers/cycles/run.sh set.py [OUT] [--only NAME,...] [--spp-scale F] [--guiding]
        [--report-only]

OUT (default target/peers/set, or target/peers/set-guiding with --guiding) receives each
render, `times.csv`, `table.csv`, `table.md`, `ratios.svg` and `maps/NAME.png`. mcctrace is
timed as a whole process (start-up, load, BVH, render, writing); Cycles by its render call alone
(`render.py`), as `cafe.sh` does. Both run at 2 threads, box filter, 8 scattering vertices.
relMSE is the variance part from a renderer's two seeds: mean over pixels and channels of
(a − b)² / 2 / (r² + 0.01), r the mean of all four renders (error.py's estimator), so a bias
between the renderers does not count; the channel means are printed to catch one.

The sample models carry no camera and no light: each is copied to OUT/models/ with a camera
framing its bounds added to its JSON, and lit by `sky.exr`, an environment the harness writes
whose radiance depends on elevation only (a sky gradient and a sun at the zenith), so the two
renderers' different longitude conventions cannot matter. Needs a release build
(`cargo build --release`) and `setup.sh`.
"""

import argparse
import csv
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import time
import zlib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
SAMPLES = os.path.join(os.path.dirname(ROOT), "shared", "gltf-samples")
DEPTH = 8
SEEDS = (1, 2)

# name, glTF, camera, size, spp, mcctrace's extra flags, environment (sample models only).
PARITY = (128, 96, 128)
CAFE = (("wide", 240, 135, 256), ("left", 480, 270, 64), ("right", 480, 270, 64))
MODELS = (("TransmissionTest", 320, 240, 128), ("TransmissionRoughnessTest", 320, 240, 128),
          ("NormalTangentMirrorTest", 320, 240, 128))


def entries(out):
    """Every scene of the set as (name, gltf, camera, (w, h), spp, mcctrace flags, env)."""
    found = []
    data = os.path.join(ROOT, "tests", "data", "cycles")
    for name in sorted(os.listdir(data)):
        gltf = os.path.join(data, name, name + ".gltf")
        if os.path.isfile(gltf):
            w, h, spp = PARITY
            found.append((name, gltf, "camera", (w, h), spp, [], None))
    cafe = os.path.join(ROOT, "scenes", "cafe", "cafe.gltf")
    for view, w, h, spp in CAFE:
        # The café is not from Blender: mcctrace fades its spot as Cycles can (cafe.sh).
        found.append((f"cafe-{view}", cafe, view, (w, h), spp, ["--spot-falloff", "blender"], None))
    sky = os.path.join(out, "sky.exr")
    for model, w, h, spp in MODELS:
        source = os.path.join(SAMPLES, model, "glTF", model + ".gltf")
        if os.path.isfile(source):
            found.append((model, framed_copy(source, os.path.join(out, "models", model), w / h),
                          "camera", (w, h), spp, [], sky))
    return found


def node_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T
    t = np.eye(4)
    t[:3, 3] = node.get("translation", [0, 0, 0])
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    r = np.eye(4)
    r[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    s = np.diag(list(node.get("scale", [1, 1, 1])) + [1])
    return t @ r @ s


def bounds(doc):
    """World-space bounds of the default scene's meshes, from their POSITION accessors' min/max."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    scene = doc["scenes"][doc.get("scene", 0)]
    stack = [(n, np.eye(4)) for n in scene["nodes"]]
    while stack:
        index, parent = stack.pop()
        node = doc["nodes"][index]
        m = parent @ node_matrix(node)
        if "mesh" in node:
            for prim in doc["meshes"][node["mesh"]]["primitives"]:
                acc = doc["accessors"][prim["attributes"]["POSITION"]]
                a, b = np.array(acc["min"]), np.array(acc["max"])
                for corner in range(8):
                    p = np.where([(corner >> k) & 1 for k in range(3)], b, a)
                    q = (m @ np.append(p, 1.0))[:3]
                    lo, hi = np.minimum(lo, q), np.maximum(hi, q)
        stack.extend((c, m) for c in node.get("children", []))
    return lo, hi


def framed_copy(source, folder, aspect):
    """`source`'s folder copied to `folder`, its glTF given a camera `camera` that frames its
    bounds from the front (+Z), a little above; returns the copy's glTF path."""
    if os.path.isdir(folder):
        shutil.rmtree(folder)
    shutil.copytree(os.path.dirname(source), folder)
    path = os.path.join(folder, os.path.basename(source))
    with open(path) as f:
        doc = json.load(f)
    lo, hi = bounds(doc)
    centre, radius = (lo + hi) / 2, float(np.linalg.norm(hi - lo)) / 2
    yfov = 0.6
    direction = np.array([0.0, 0.35, 1.0]) / np.linalg.norm([0.0, 0.35, 1.0])
    eye = centre + direction * radius / math.sin(yfov / 2) * 1.05
    # Rotation about +X that turns −Z (the camera's view) to −direction.
    pitch = -math.atan2(direction[1], direction[2])
    doc.setdefault("cameras", []).append({"type": "perspective", "name": "camera", "perspective": {
        "yfov": yfov, "aspectRatio": aspect, "znear": radius * 0.01}})
    doc["nodes"].append({"name": "camera", "camera": len(doc["cameras"]) - 1,
                         "translation": [float(v) for v in eye],
                         "rotation": [math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2)]})
    doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 1)
    with open(path, "w") as f:
        json.dump(doc, f)
    return path


def write_sky(path):
    """An equirectangular environment whose radiance depends on elevation only: ground 0.05,
    a sky from 0.9 (horizon) to 0.25 (zenith), bluish, and a sun of 2° radius at the zenith."""
    w, h = 512, 256
    rows = np.zeros((h, 3), dtype=np.float32)
    for y in range(h):  # top row first: row 0 is the zenith
        elevation = (0.5 - (y + 0.5) / h) * math.pi
        if elevation < 0:
            rows[y] = (0.05, 0.05, 0.05)
        else:
            t = elevation / (math.pi / 2)
            rows[y] = np.array((0.9, 0.95, 1.0)) * (1 - t) + np.array((0.15, 0.25, 0.45)) * t
        if math.pi / 2 - elevation < math.radians(2.0):
            rows[y] = (2000.0, 1900.0, 1700.0)
    write_exr(path, np.repeat(rows[:, None, :], w, axis=1))


def write_exr(path, rgb):
    """`rgb` (h × w × 3, top row first) as an uncompressed 32-bit float OpenEXR file. Written
    here rather than by Blender, whose image saving applies its colour management."""
    h, w = rgb.shape[:2]

    def attribute(name, kind, body):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(body)) + body

    channels = b"".join(c + b"\0" + struct.pack("<iBBBBii", 2, 0, 0, 0, 0, 1, 1) for c in (b"B", b"G", b"R"))
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (struct.pack("<ii", 20000630, 2)
              + attribute("channels", "chlist", channels + b"\0")
              + attribute("compression", "compression", b"\0")
              + attribute("dataWindow", "box2i", box) + attribute("displayWindow", "box2i", box)
              + attribute("lineOrder", "lineOrder", b"\0")
              + attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + attribute("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    line = 8 + 3 * 4 * w
    start = len(header) + 8 * h
    table = b"".join(struct.pack("<Q", start + y * line) for y in range(h))
    body = b"".join(struct.pack("<ii", y, 3 * 4 * w)
                    + np.ascontiguousarray(rgb[y, :, ::-1].T, dtype="<f4").tobytes() for y in range(h))
    with open(path, "wb") as f:
        f.write(header + table + body)


def run_mcctrace(entry, seed, out, scale):
    name, gltf, camera, (w, h), spp, flags, env = entry
    exe = os.environ.get("MCCTRACE", os.path.join(ROOT, "target", "release", "mcctrace"))
    cmd = [exe, "render", gltf, "--camera", camera, "--res", f"{w}x{h}", "--spp",
           str(max(1, round(spp * scale))), "--seed", str(seed), "--threads", "2", "--max-depth",
           str(DEPTH), "--out", os.path.join(out, f"mcc-{name}-{seed}.exr")] + flags
    if env:
        cmd += ["--env-map", env]
    start = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"{name}: mcctrace failed:\n{' '.join(cmd)}\n{done.stderr}")
    return seconds


def run_cycles(entry, seed, out, scale, guiding):
    name, gltf, camera, (w, h), spp, _flags, env = entry
    cmd = [os.path.join(HERE, "run.sh"), "render.py", gltf, os.path.join(out, f"cycles-{name}-{seed}.exr"),
           "--size", f"{w},{h}", "--spp", str(max(1, round(spp * scale))), "--camera", camera,
           "--seed", str(seed), "--threads", "2", "--depth", str(DEPTH)]
    if env:
        cmd += ["--env-map", env]
    if guiding:
        cmd += ["--guiding"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{name}: Cycles failed:\n{' '.join(cmd)}\n{done.stdout}\n{done.stderr}")
    return float(done.stdout.strip().splitlines()[-1].split(",")[1])


def png(path, rgb):
    """`rgb` (h × w × 3, 0..1) as an 8-bit PNG, top row first."""
    data = (np.clip(rgb, 0, 1) * 255 + 0.5).astype(np.uint8)
    raw = b"".join(b"\0" + row.tobytes() for row in data)

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    h, w = data.shape[:2]
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def heat(e, top):
    """Per-pixel error on a log scale (1e-4 × top … top) as black → red → yellow → white."""
    t = np.clip((np.log10(np.maximum(e, 1e-30)) - math.log10(top) + 4) / 4, 0, 1)
    return np.stack([np.clip(3 * t, 0, 1), np.clip(3 * t - 1, 0, 1), np.clip(3 * t - 2, 0, 1)], -1)


def report(out, names):
    from render import load_rgb  # Blender's EXR reader, as error.py uses

    seconds = {}
    with open(os.path.join(out, "times.csv")) as f:
        for who, name, _seed, spp, s in csv.reader(f):
            seconds.setdefault((who, name), []).append(float(s))
            seconds[(who, name, "spp")] = int(spp)
    os.makedirs(os.path.join(out, "maps"), exist_ok=True)
    rows = []
    for name in names:
        if (("cycles", name)) not in seconds or len(seconds[("cycles", name)]) < 2:
            continue
        # Blender's loader gives rows bottom-up; flip for the maps.
        images = {w: [load_rgb(os.path.join(out, f"{w}-{name}-{s}.exr"))[::-1] for s in SEEDS]
                  for w in ("mcc", "cycles")}
        r = sum(images["mcc"] + images["cycles"]) / 4.0
        row = {"scene": name}
        errors = {}
        for who, key in (("cycles", "cycles"), ("mcctrace", "mcc")):
            a, b = images[key]
            e = np.mean((a - b) ** 2 / 2.0 / (r * r + 0.01), axis=2)
            errors[who] = e
            flat = np.sort(e.ravel())[::-1]
            top = max(1, flat.size // 100)
            t = float(np.mean(seconds[(who, name)]))
            rel = float(np.mean(e))
            row[who] = {"spp": seconds[(who, name, "spp")], "seconds": t, "rel_mse": rel,
                        "product": t * rel, "top1": float(flat[:top].sum() / max(flat.sum(), 1e-300)),
                        "means": (sum(images[key]) / 2).mean(axis=(0, 1))}
        row["ratio"] = row["mcctrace"]["product"] / row["cycles"]["product"]
        top = max(float(errors["mcctrace"].max()), float(errors["cycles"].max()), 1e-30)
        gap = np.ones((r.shape[0], 4, 3))
        png(os.path.join(out, "maps", f"{name}.png"),
            np.concatenate([heat(errors["mcctrace"], top), gap, heat(errors["cycles"], top)], axis=1))
        rows.append(row)
    with open(os.path.join(out, "table.csv"), "w") as f:
        f.write("scene,renderer,spp,seconds,rel_mse,time_x_rel_mse,top1_share,ratio_to_cycles\n")
        for row in rows:
            for who in ("mcctrace", "cycles"):
                x = row[who]
                f.write(f"{row['scene']},{who},{x['spp']},{x['seconds']:.3f},{x['rel_mse']:.4e},"
                        f"{x['product']:.4e},{x['top1']:.3f},"
                        f"{row['ratio'] if who == 'mcctrace' else 1.0:.3f}\n")
    ratios = [row["ratio"] for row in rows]
    load = open("/proc/loadavg").read().split()[:3] if os.path.exists("/proc/loadavg") else []
    lines = ["| scene | spp | mcctrace s | Cycles s | relMSE mcctrace | relMSE Cycles | "
             "time × relMSE ratio | top 1 % share mcctrace / Cycles |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for row in rows:
        m, c = row["mcctrace"], row["cycles"]
        lines.append(f"| {row['scene']} | {m['spp']} | {m['seconds']:.2f} | {c['seconds']:.2f} | "
                     f"{m['rel_mse']:.3e} | {c['rel_mse']:.3e} | **{row['ratio']:.2f}** | "
                     f"{m['top1']:.0%} / {c['top1']:.0%} |")
    if ratios:
        lines.append("")
        lines.append(f"Median ratio {float(np.median(ratios)):.2f}; {sum(r <= 0.5 for r in ratios)} of "
                     f"{len(ratios)} scenes at ≤ 0.5; load average at the end {' '.join(load)}.")
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    for row in rows:
        print(f"# {row['scene']}: channel means mcctrace {row['mcctrace']['means']}, "
              f"cycles {row['cycles']['means']}")
    svg(os.path.join(out, "ratios.svg"), rows)


def svg(path, rows):
    """Bars of each scene's ratio on a log axis (0.1 … 10), with the 0.5 and 1 lines."""
    w, bar, left = 640, 18, 200
    h = 30 + bar * len(rows) + 20

    def x(v):
        return left + (math.log10(min(max(v, 0.1), 10)) + 1) / 2 * (w - left - 20)

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
             'font-family="sans-serif" font-size="11">',
             '<text x="10" y="16">time × relMSE, mcctrace / Cycles (log scale; left is better)</text>']
    for i, row in enumerate(rows):
        y = 28 + i * bar
        colour = "#2a7" if row["ratio"] <= 0.5 else ("#d92" if row["ratio"] <= 1 else "#c33")
        parts.append(f'<text x="{left - 6}" y="{y + 12}" text-anchor="end">{row["scene"]}</text>')
        parts.append(f'<rect x="{left}" y="{y + 2}" width="{x(row["ratio"]) - left:.1f}" '
                     f'height="{bar - 4}" fill="{colour}"/>')
        parts.append(f'<text x="{x(row["ratio"]) + 4:.1f}" y="{y + 12}">{row["ratio"]:.2f}</text>')
    for v in (0.1, 0.5, 1, 2, 10):
        parts.append(f'<line x1="{x(v):.1f}" y1="24" x2="{x(v):.1f}" y2="{h - 16}" stroke="#888" '
                     'stroke-dasharray="3,3"/>')
        parts.append(f'<text x="{x(v):.1f}" y="{h - 4}" text-anchor="middle">{v}</text>')
    parts.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(parts) + "\n")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", nargs="?")
    p.add_argument("--only", help="comma-separated scene names")
    p.add_argument("--spp-scale", type=float, default=1.0, help="multiply every scene's spp")
    p.add_argument("--guiding", action="store_true", help="Cycles' path guiding on")
    p.add_argument("--report-only", action="store_true", help="the table from renders on disk")
    a = p.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:])
    out = os.path.abspath(a.out or os.path.join(ROOT, "target", "peers",
                                                "set-guiding" if a.guiding else "set"))
    os.makedirs(out, exist_ok=True)
    if not os.path.exists(os.path.join(out, "sky.exr")):
        write_sky(os.path.join(out, "sky.exr"))
    chosen = entries(out)
    if a.only:
        wanted = a.only.split(",")
        unknown = sorted(set(wanted) - {e[0] for e in chosen})
        if unknown:
            raise SystemExit(f"--only: no scene {', '.join(unknown)} in the set "
                             f"({', '.join(e[0] for e in chosen)})")
        chosen = [e for e in chosen if e[0] in wanted]
    if not a.report_only:
        times = os.path.join(out, "times.csv")
        if os.path.exists(times):
            os.remove(times)
        for i, entry in enumerate(chosen):
            name, spp = entry[0], max(1, round(entry[4] * a.spp_scale))
            print(f"[{i + 1}/{len(chosen)}] {name}", flush=True)
            with open(times, "a") as f:
                for seed in SEEDS:  # interleaved: each renderer sees the same machine load
                    f.write(f"mcctrace,{name},{seed},{spp},{run_mcctrace(entry, seed, out, a.spp_scale):.3f}\n")
                    f.write(f"cycles,{name},{seed},{spp},{run_cycles(entry, seed, out, a.spp_scale, a.guiding):.3f}\n")
                    f.flush()
    report(out, [e[0] for e in chosen])


if __name__ == "__main__":
    main()
