#!/usr/bin/env python3
"""Writes the seed corpus in fuzz/corpus/<target>/ (pure Python 3, no packages).

Run from anywhere: `python3 fuzz/make_seeds.py`. It rewrites every seed it owns (the files it
names below) and leaves other files alone, so a committed seed found by a fuzzer and kept by
hand survives. Seeds are small valid examples of each format plus a few malformed ones; the
whole corpus stays well under 1 MB.

There is no JPEG seed (a JPEG encoder is beyond a seed script): the collage seeds are PNG and
TIFF, the formats collages are saved in.
"""

import base64
import json
import math
import os
import struct
import zipfile
import io
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CORPUS = os.path.join(HERE, "corpus")
# Must match harness.rs SEPARATOR.
SEPARATOR = b"\n#%%mcctrace-fuzz%%\n"


def put(target, name, data):
    d = os.path.join(CORPUS, target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


# ------------------------------------------------------------------------------------------------
# Ray files (crates/mcc/src/ray_file/mod.rs)

MAGIC = b"\x89MCR\r\n\x1a\n"


def mcr(w, h, rays, frame=0, camera=0, flags=0, version=1):
    head = MAGIC + struct.pack("<6I", version, w, h, frame, camera, flags)
    return head + b"".join(struct.pack("<6f", *r) for r in rays)


def unit(x, y, z):
    n = math.sqrt(x * x + y * y + z * z)
    return (x / n, y / n, z / n)


def ray_seeds():
    rays = [(0.0, 1.0, 5.0) + unit(-0.1, 0.05, -1.0), (0.0, 1.0, 5.0) + unit(0.1, 0.05, -1.0)]
    good = mcr(2, 1, rays, frame=3, camera=2)
    put("ray_file", "bin_2x1.mcr", good)
    put("ray_file", "bin_2x1_computed.mcr", mcr(2, 1, rays, flags=1))
    put("ray_file", "bin_truncated.mcr", good[:-4])
    put("ray_file", "bin_trailing.mcr", good + b"\0")
    put("ray_file", "bin_version2.mcr", mcr(2, 1, rays, version=2))
    put("ray_file", "bin_unknown_flag.mcr", mcr(2, 1, rays, flags=6))
    put("ray_file", "bin_huge_header.mcr", mcr(65536, 2048, []))
    put("ray_file", "bin_zero_width.mcr", mcr(0, 1, []))
    put("ray_file", "bin_nonunit.mcr", mcr(1, 1, [(0, 0, 0, 0, 0, 2.0)]))
    put("ray_file", "bin_nan.mcr", mcr(1, 1, [(float("nan"), 0, 0, 0, 0, 1.0)]))
    put("ray_file", "bin_header_only.mcr", good[:32])
    put("ray_file", "bin_short_magic.mcr", MAGIC[:8] + b"\x01\0")

    def line(i, j, r):
        return "%d %d %s\n" % (i, j, " ".join(repr(v) for v in r))

    text = "2 2\n" + line(1, 0, rays[1]) + "\n" + line(0, 0, rays[0]) + line(0, 1, rays[0]) + line(1, 1, rays[1])
    put("ray_file", "text_2x2.txt", text)
    put("ray_file", "text_crlf.txt", "1 1\r\n0 0 -0 0 0 0 0 1\r\n")
    put("ray_file", "text_exponents.txt", "1 1\n0 0 1e-45 -3.4028235e38 0 0 -1 0\n")
    put("ray_file", "text_duplicate.txt", "2 1\n0 0 0 0 0 0 0 1\n0 0 0 0 0 0 0 1\n")
    put("ray_file", "text_missing.txt", "2 1\n0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1 9\n")
    put("ray_file", "text_nan.txt", "1 1\n0 0 0 0 0 NaN 0 1\n")
    put("ray_file", "text_inf.txt", "1 1\n0 0 inf 0 0 0 0 1\n")
    put("ray_file", "text_nonunit.txt", "1 1\n0 0 0 0 0 0 0 1.001\n")
    put("ray_file", "text_outside.txt", "1 1\n1 0 0 0 0 0 0 1\n")
    put("ray_file", "text_header_only.txt", "3 2\n")
    put("ray_file", "text_big_header.txt", "65536 65536\n0 0 0 0 0 0 0 1\n")
    put("ray_file", "text_bad_utf8.txt", b"1 1\n0 0 0 0 0 0 0 1\xff\n")


# ------------------------------------------------------------------------------------------------
# Images (collage decoding; also textures in the scene seeds)


def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png(w, h, rows, colour_type, depth=8, palette=None, trns=None, compress=True):
    """rows: list of raw row byte strings (no filter byte)."""
    raw = b"".join(b"\0" + r for r in rows)
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, colour_type, 0, 0, 0))
    if palette is not None:
        out += chunk(b"PLTE", b"".join(bytes(c) for c in palette))
    if trns is not None:
        out += chunk(b"tRNS", trns)
    out += chunk(b"IDAT", zlib.compress(raw, 9 if compress else 0))
    return out + chunk(b"IEND", b"")


def tag(rgb, camera, bits=2):
    m = (1 << bits) - 1
    return bytes(
        (rgb[k] & ~m & 0xFF) | ((camera >> (k * bits)) & m) for k in range(3)
    )


def collage_rgb():
    rows = []
    for y in range(3):
        row = b""
        for x in range(6):
            if x < 2:
                row += tag((200, 100, 0), 1)
            elif x >= 4:
                row += tag((0, 0, 0), 2)
            else:
                row += b"\0\0\0"
        rows.append(row)
    return png(6, 3, rows, 2)


def tiff_rgb(w, h, pixels):
    """Baseline uncompressed little-endian RGB TIFF."""
    data = bytes(pixels)
    entries = [
        (256, 3, 1, w), (257, 3, 1, h), (258, 3, 3, None), (259, 3, 1, 1), (262, 3, 1, 2),
        (273, 4, 1, None), (277, 3, 1, 3), (278, 3, 1, h), (279, 4, 1, len(data)),
    ]
    ifd_at = 8
    ifd_len = 2 + 12 * len(entries) + 4
    bps_at = ifd_at + ifd_len
    strip_at = bps_at + 6
    out = b"II*\0" + struct.pack("<I", ifd_at) + struct.pack("<H", len(entries))
    for tag_, typ, count, value in entries:
        if tag_ == 258:
            value = bps_at
        if tag_ == 273:
            value = strip_at
        if typ == 3 and count == 1:
            out += struct.pack("<HHIHH", tag_, typ, count, value, 0)
        else:
            out += struct.pack("<HHII", tag_, typ, count, value)
    out += struct.pack("<I", 0) + struct.pack("<3H", 8, 8, 8) + data
    return out


def collage_seeds():
    put("collage", "rgb_6x3.png", collage_rgb())
    rgba = [
        b"".join(tag((10, 200, 30), 3) + b"\xff" if x < 2 else b"\x50\x60\x70\x00" for x in range(4))
        for _ in range(4)
    ]
    put("collage", "rgba_4x4.png", png(4, 4, rgba, 6))
    palette = [(0, 0, 0), tuple(tag((120, 40, 200), 5)), tuple(tag((255, 255, 255), 9))]
    put("collage", "palette_3x2.png", png(3, 2, [b"\0\1\1", b"\2\0\1"], 3, palette=palette))
    put("collage", "palette_trns.png", png(3, 1, [b"\0\1\2"], 3, palette=palette, trns=b"\xff\x00"))
    wide = [b"".join(struct.pack(">3H", *(257 * v for v in tag((200, 100, 0), 1))) for _ in range(3)) for _ in range(2)]
    put("collage", "rgb16_3x2.png", png(3, 2, wide, 2, depth=16))
    off = [struct.pack(">3H", 258, 0, 0) * 2]
    put("collage", "rgb16_not_widened.png", png(2, 1, off, 2, depth=16))
    put("collage", "grey_4x4.png", png(4, 4, [b"\x10\x20\x30\x40"] * 4, 0))
    put("collage", "grey_alpha.png", png(2, 1, [b"\x10\xff\x20\x00"], 4))
    put("collage", "stray_edge.png", png(3, 1, [tag((200, 0, 0), 1) + b"\x64\x64\x64" + tag((0, 0, 0), 7)], 2))
    put("collage", "stored_deflate.png", png(2, 2, [tag((1, 2, 3), 2) * 2] * 2, 2, compress=False))
    good = collage_rgb()
    put("collage", "truncated.png", good[: len(good) - 20])
    bad_crc = bytearray(good)
    bad_crc[29] ^= 0xFF  # inside IHDR's CRC
    put("collage", "bad_crc.png", bytes(bad_crc))
    huge = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 30000, 30000, 8, 2, 0, 0, 0)) + chunk(b"IEND", b"")
    put("collage", "huge_header.png", huge)
    put("collage", "rgb_2x2.tif", tiff_rgb(2, 2, tag((9, 9, 9), 1) * 2 + tag((200, 9, 9), 2) * 2))
    for name in ["collage-mask.png", "collage-mask-regions.png"]:
        with open(os.path.join(ROOT, "scenes", "cafe", name), "rb") as f:
            put("collage", "cafe-" + name, f.read())


# ------------------------------------------------------------------------------------------------
# glTF


def data_uri(data):
    return "data:application/octet-stream;base64," + base64.b64encode(data).decode()


def f32s(values):
    return struct.pack("<%df" % len(values), *values)


def triangle_doc(uri=True, extra=None):
    positions = f32s([0, 0, 0, 1, 0, 0, 0, 1, 0])
    normals = f32s([0, 0, 1] * 3)
    uvs = f32s([0, 0, 1, 0, 0, 1])
    indices = struct.pack("<3H", 0, 1, 2) + b"\0\0"
    buf = positions + normals + uvs + indices
    doc = {
        "asset": {"version": "2.0", "generator": "mcctrace fuzz seeds"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0, 3]}],
        "nodes": [
            {"name": "root", "translation": [0, 0, -1], "children": [1, 2]},
            {"mesh": 0, "rotation": [0, 0, 0.3826834, 0.9238795], "scale": [1, 2, 1]},
            {"camera": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1]},
            {"name": "lights", "children": [4, 5, 6]},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 2, 0]},
            {"extensions": {"KHR_lights_punctual": {"light": 1}}, "rotation": [-0.7071068, 0, 0, 0.7071068]},
            {"extensions": {"KHR_lights_punctual": {"light": 2}}},
        ],
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "materials": [
            {
                "name": "glow",
                "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.1, 1], "metallicFactor": 0.1, "roughnessFactor": 0.7},
                "emissiveFactor": [1, 0.5, 0.25],
                "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 2}},
                "doubleSided": True,
            }
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1, "aspectRatio": 1.5}}],
        "extensions": {
            "KHR_lights_punctual": {
                "lights": [
                    {"type": "point", "color": [1, 1, 1], "intensity": 100},
                    {"type": "spot", "intensity": 50, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
                    {"type": "directional", "intensity": 3, "name": "sun"},
                ]
            }
        },
        "buffers": [{"byteLength": len(buf)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 36},
            {"buffer": 0, "byteOffset": 72, "byteLength": 24},
            {"buffer": 0, "byteOffset": 96, "byteLength": 6},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
    }
    if uri:
        doc["buffers"][0]["uri"] = data_uri(buf)
    if extra:
        extra(doc, buf)
    return doc, buf


def glb(doc, bin_chunk):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    out = b""
    out += struct.pack("<II", len(js), 0x4E4F534A) + js
    if bin_chunk is not None:
        bin_chunk += b"\0" * (-len(bin_chunk) % 4)
        out += struct.pack("<II", len(bin_chunk), 0x004E4942) + bin_chunk
    return b"glTF" + struct.pack("<II", 2, 12 + len(out)) + out


def gltf_text(doc):
    return json.dumps(doc, separators=(",", ":"))


def tiny_texture_png():
    return png(2, 2, [b"\xff\0\0\xff\0\xff\0\x80", b"\0\0\xff\xff\xff\xff\xff\0"], 6)


def gltf_seeds():
    doc, _ = triangle_doc()
    put("gltf", "triangle.gltf", gltf_text(doc))
    doc, buf = triangle_doc(uri=False)
    put("gltf", "triangle.glb", glb(doc, buf))

    # Animated: translation LINEAR, rotation CUBICSPLINE, scale STEP on the mesh node.
    def animate(doc, buf):
        times = f32s([0, 0.5, 1])
        trans = f32s([0, 0, 0, 1, 0, 0, 0, 1, 0])
        rot = f32s([0, 0, 0, 0] + [0, 0, 0, 1] + [0, 0, 0, 0] + [0, 0, 0, 0] + [0, 0, 0.7071068, 0.7071068] + [0, 0, 0, 0] + [0, 0, 0, 0] + [0, 0, 1, 0] + [0, 0, 0, 0])
        scale = f32s([1, 1, 1, 2, 2, 2, 1, 1, 1])
        extra = times + trans + rot + scale
        doc["buffers"].append({"byteLength": len(extra), "uri": data_uri(extra)})
        n = len(doc["bufferViews"])
        doc["bufferViews"] += [
            {"buffer": 1, "byteOffset": 0, "byteLength": 12},
            {"buffer": 1, "byteOffset": 12, "byteLength": 36},
            {"buffer": 1, "byteOffset": 48, "byteLength": 144},
            {"buffer": 1, "byteOffset": 192, "byteLength": 36},
        ]
        a = len(doc["accessors"])
        doc["accessors"] += [
            {"bufferView": n, "componentType": 5126, "count": 3, "type": "SCALAR", "min": [0], "max": [1]},
            {"bufferView": n + 1, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": n + 2, "componentType": 5126, "count": 9, "type": "VEC4"},
            {"bufferView": n + 3, "componentType": 5126, "count": 3, "type": "VEC3"},
        ]
        doc["animations"] = [
            {
                "name": "move",
                "samplers": [
                    {"input": a, "output": a + 1, "interpolation": "LINEAR"},
                    {"input": a, "output": a + 2, "interpolation": "CUBICSPLINE"},
                    {"input": a, "output": a + 3, "interpolation": "STEP"},
                ],
                "channels": [
                    {"sampler": 0, "target": {"node": 1, "path": "translation"}},
                    {"sampler": 1, "target": {"node": 5, "path": "rotation"}},
                    {"sampler": 2, "target": {"node": 1, "path": "scale"}},
                ],
            }
        ]

    doc, _ = triangle_doc(extra=animate)
    put("gltf", "animated.gltf", gltf_text(doc))

    # Textured GLB: the image in a buffer view, a sampler, KHR_texture_transform, a normal map,
    # a strip primitive with byte indices and normalised byte texture coordinates.
    def texture(doc, buf):
        image = tiny_texture_png()
        image += b"\0" * (-len(image) % 4)
        buf_total = buf + image
        strip = struct.pack("<4B", 0, 1, 2, 0)
        uv8 = bytes([0, 0, 255, 0, 0, 255, 0, 0])
        tangents = f32s([1, 0, 0, 1] * 3)
        tail = strip + uv8 + tangents
        doc["buffers"][0]["byteLength"] = len(buf_total) + len(tail)
        doc["bufferViews"] += [
            {"buffer": 0, "byteOffset": len(buf), "byteLength": len(image)},
            {"buffer": 0, "byteOffset": len(buf_total), "byteLength": 4},
            {"buffer": 0, "byteOffset": len(buf_total) + 4, "byteLength": 6},
            {"buffer": 0, "byteOffset": len(buf_total) + 12, "byteLength": 48},
        ]
        doc["accessors"] += [
            {"bufferView": 5, "componentType": 5121, "count": 4, "type": "SCALAR"},
            {"bufferView": 6, "componentType": 5121, "normalized": True, "count": 3, "type": "VEC2"},
            {"bufferView": 7, "componentType": 5126, "count": 3, "type": "VEC4"},
        ]
        doc["images"] = [{"bufferView": 4, "mimeType": "image/png", "name": "tiny"}]
        doc["samplers"] = [{"magFilter": 9728, "minFilter": 9729, "wrapS": 33071, "wrapT": 33648}]
        doc["textures"] = [{"source": 0, "sampler": 0}]
        m = doc["materials"][0]
        m["pbrMetallicRoughness"]["baseColorTexture"] = {
            "index": 0,
            "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 0.3, "scale": [2, 2]}},
        }
        m["normalTexture"] = {"index": 0, "scale": 0.5}
        m["alphaMode"] = "MASK"
        m["alphaCutoff"] = 0.4
        doc["materials"].append(
            {
                "name": "glass",
                "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_ior": {"ior": 1.45}, "KHR_materials_specular": {"specularFactor": 0.5}},
            }
        )
        doc["extensionsUsed"] += ["KHR_texture_transform", "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_specular"]
        doc["meshes"][0]["primitives"].append(
            {"attributes": {"POSITION": 0, "TEXCOORD_0": 5, "TANGENT": 6, "NORMAL": 1}, "indices": 4, "mode": 5, "material": 1}
        )
        doc["meshes"][0]["primitives"].append({"attributes": {"POSITION": 0}, "mode": 6})
        texture.bin = buf_total + tail

    doc, _ = triangle_doc(uri=False, extra=texture)
    put("gltf", "textured.glb", glb(doc, texture.bin))

    # The Cornell box with its buffer inlined.
    with open(os.path.join(ROOT, "scenes", "cornell", "cornell.gltf")) as f:
        cornell = json.load(f)
    with open(os.path.join(ROOT, "scenes", "cornell", "cornell.bin"), "rb") as f:
        cornell_bin = f.read()
    for b in cornell["buffers"]:
        b["uri"] = data_uri(cornell_bin)
    put("gltf", "cornell.gltf", gltf_text(cornell))

    # Malformed ones.
    doc, _ = triangle_doc()
    doc["nodes"][1]["children"] = [0]
    put("gltf", "cycle.gltf", gltf_text(doc))
    doc, _ = triangle_doc()
    doc["accessors"][0]["count"] = 1000
    put("gltf", "accessor_out_of_bounds.gltf", gltf_text(doc))
    doc, _ = triangle_doc()
    doc["accessors"][3]["count"] = 2
    put("gltf", "index_count_not_triangles.gltf", gltf_text(doc))
    doc, _ = triangle_doc()
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64,AAA*"
    put("gltf", "bad_base64.gltf", gltf_text(doc))
    doc, _ = triangle_doc()
    doc["cameras"][0] = {"type": "orthographic", "perspective": {"yfov": 1}}
    put("gltf", "camera_without_projection.gltf", gltf_text(doc))
    doc, buf = triangle_doc(uri=False)
    g = bytearray(glb(doc, buf))
    g[8:12] = struct.pack("<I", len(g) + 8)
    put("gltf", "glb_bad_length.glb", bytes(g))
    put("gltf", "not_json.gltf", '{"asset":{"version":"2.0"},"nodes":[{"mesh":')
    put("gltf", "version1.gltf", '{"asset":{"version":"1.0"}}')
    put("gltf", "empty_scene.gltf", '{"asset":{"version":"2.0"},"scenes":[{}]}')


# ------------------------------------------------------------------------------------------------
# OBJ (+ MTL + texture), joined by SEPARATOR lines (harness.rs, `obj`)


def obj_seeds():
    cornell = os.path.join(ROOT, "scenes", "cornell")
    with open(os.path.join(cornell, "cornell.mtl"), "rb") as f:
        mtl = f.read()
    for name in sorted(os.listdir(cornell)):
        if name.endswith(".obj"):
            with open(os.path.join(cornell, name), "rb") as f:
                obj = f.read().replace(b"mtllib cornell.mtl", b"mtllib m.mtl")
            put("obj", "cornell_" + name[:-4] + ".obj", obj + SEPARATOR + mtl)
    textured_obj = b"""mtllib m.mtl
o quad
v -1 -1 0
v 1 -1 0
v 1 1 0
v -1 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
usemtl tex
f 1/1/1 2/2/1 3/3/1 4/4/1
o glass
usemtl glass
f -4//-1 -2//-1 -1//-1
g rest
usemtl nosuch
f 1 2 3
"""
    textured_mtl = b"""newmtl tex
Kd 1 1 1
Ks 0.04 0.04 0.04
Ns 250
map_Kd -o 0.1 0.2 -s 2 2 -clamp on t.png
map_d t.png
map_Bump -bm 0.5 t.png
map_Ke t.png
map_Ks ignored.png
d 0.8
newmtl glass
illum 7
Ni 1.45
Tf 0.9 1 0.9
Tr 0.2
"""
    put("obj", "textured.obj", textured_obj + SEPARATOR + textured_mtl + SEPARATOR + tiny_texture_png())
    put("obj", "polygon_no_mtl.obj", b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 2 0\nv 0 1 0\nf 1 2 3 4 5\n")
    put("obj", "bad_index.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    put("obj", "bad_number.obj", b"v 0 zero 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    put("obj", "nan_vertex.obj", b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    put("obj", "partial_normals.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 2 4 3\n")
    put("obj", "greyscale_bump.obj", b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl g\nf 1 2 3\n" + SEPARATOR
        + b"newmtl g\nbump t.png\nmap_Kd t.png\n" + SEPARATOR + png(1, 1, [b"\x80"], 0))
    put("obj", "bad_texture.obj", b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl g\nf 1 2 3\n" + SEPARATOR
        + b"newmtl g\nmap_Kd -o t.png\n" + SEPARATOR + b"\x89PNG\r\n\x1a\nnot really")

    # What tobj 4.0.5 panicked or overflowed on before the loader's pre-checks (regressions).
    put("obj", "mtl_two_number_colour.obj", b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl g\nf 1 2 3\n"
        + SEPARATOR + b"newmtl g\nKd 0.5\nKe 4 4\n")
    put("obj", "mtl_grey_colour.obj", b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl g\nf 1 2 3\n"
        + SEPARATOR + b"newmtl g\nKd 0.5\nKs 0.04\nNs 50\n")
    put("obj", "index_zero_relative.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/0 2/1 3/1\nf -4 -2 -1\n")

# ------------------------------------------------------------------------------------------------
# Layered collages (crates/mcc/src/layers/): OpenRaster archives and PSD documents


def ora(stack_xml, layers, mimetype=b"image/openraster", deflate_layers=False):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        def add(name, data, method):
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = method
            z.writestr(info, data)
        if mimetype is not None:
            add("mimetype", mimetype, zipfile.ZIP_STORED)
        add("stack.xml", stack_xml, zipfile.ZIP_DEFLATED)
        for name, data in layers:
            add(name, data, zipfile.ZIP_DEFLATED if deflate_layers else zipfile.ZIP_STORED)
    return buf.getvalue()


def rgba_png(w, h, alpha):
    rows = [b"".join(bytes([90, 60, 30, alpha(x, y)]) for x in range(w)) for y in range(h)]
    return png(w, h, rows, 6)


def psd(w, h, records, depth=8):
    """records: top first, each (name, (left, top, lw, lh), alpha rows or None, blend, section, opacity, flags)."""
    recs, data = b"", b""
    for name, (left, top, lw, lh), alpha, blend, section, opacity, flags in reversed(records):
        channels = []
        for cid in (-1, 0, 1, 2):
            if alpha is None or lw * lh == 0:
                channels.append((cid, struct.pack(">H", 0)))
            elif cid == -1:
                rows = [bytes(r) for r in alpha]
                packed = []
                for r in rows:
                    out = b""
                    for b in r:
                        out += bytes([0, b])
                    packed.append(out)
                body = struct.pack(">H", 1) + b"".join(struct.pack(">H", len(p)) for p in packed) + b"".join(packed)
                channels.append((cid, body))
            else:
                channels.append((cid, struct.pack(">H", 0) + bytes([100]) * (lw * lh)))
        rec = struct.pack(">iiiiH", top, left, top + lh, left + lw, len(channels))
        for cid, body in channels:
            rec += struct.pack(">hI", cid, len(body))
        rec += b"8BIM" + blend + bytes([opacity, 0, flags, 0])
        nm = name.encode("latin-1")
        extra = struct.pack(">II", 0, 0) + bytes([len(nm)]) + nm
        while (len(extra) - 8) % 4:
            extra += b"\0"
        if section:
            block = struct.pack(">I", section) + b"8BIMpass"
            extra += b"8BIMlsct" + struct.pack(">I", len(block)) + block
        rec += struct.pack(">I", len(extra)) + extra
        recs += rec
        data += b"".join(body for _, body in channels)
    info = struct.pack(">h", len(records)) + recs + data
    section = struct.pack(">I", len(info)) + info + struct.pack(">I", 0)
    head = b"8BPS" + struct.pack(">H", 1) + b"\0" * 6 + struct.pack(">HIIHH", 4, h, w, depth, 3)
    return head + struct.pack(">II", 0, 0) + struct.pack(">I", len(section)) + section + struct.pack(">H", 0)


def layers_seeds():
    soft = rgba_png(4, 3, lambda x, y: (x * 80 + y * 30) % 256)
    solid = rgba_png(6, 4, lambda x, y: 255)
    black = png(6, 4, [b"\0\0\0" * 6] * 4, 2)
    stack = (b"<?xml version='1.0' encoding='UTF-8'?><image version=\"0.0.5\" w=\"6\" h=\"4\"><stack>"
             b"<layer name=\"sketch\" src=\"data/s.png\" visibility=\"hidden\"/>"
             b"<layer name=\"left (camera 1)\" src=\"data/a.png\" x=\"-1\" y=\"1\" opacity=\"0.8\"/>"
             b"<stack name=\"group\" opacity=\"0.9\" isolation=\"auto\">"
             b"<layer name=\"camera 2\" src=\"data/b.png\" x=\"3\"/></stack>"
             b"<stack name=\"regions\"><layer name=\"sky\" src=\"data/a.png\"/></stack>"
             b"<layer name=\"background\" src=\"data/bg.png\"/></stack></image>")
    layers = [("data/s.png", soft), ("data/a.png", soft), ("data/b.png", solid), ("data/bg.png", black)]
    put("layers", "views.ora", ora(stack, layers))
    put("layers", "deflated.ora", ora(stack, layers, deflate_layers=True))
    put("layers", "no_mimetype.ora", ora(stack, layers, mimetype=None))
    put("layers", "multiply.ora", ora(stack.replace(b"opacity=\"0.8\"", b"composite-op=\"svg:multiply\""), layers))
    put("layers", "truncated.ora", ora(stack, layers)[:-40])
    a = [[(x * 60 + y * 40) % 256 for x in range(4)] for y in range(3)]
    full = [[255] * 6 for _ in range(4)]
    put("layers", "layers.psd", psd(6, 4, [
        ("sketch", (0, 0, 6, 4), full, b"norm", 0, 255, 2),
        ("1", (-1, 1, 4, 3), a, b"norm", 0, 204, 0),
        ("group", (0, 0, 0, 0), None, b"pass", 1, 230, 0),
        ("frame0000camera02.png", (3, 0, 6, 4), full, b"norm", 0, 255, 0),
        ("</Layer group>", (0, 0, 0, 0), None, b"norm", 3, 255, 0),
    ]))
    put("layers", "multiply.psd", psd(6, 4, [("2", (0, 0, 6, 4), full, b"mul ", 0, 255, 0)]))


if __name__ == "__main__":
    ray_seeds()
    collage_seeds()
    gltf_seeds()
    obj_seeds()
    layers_seeds()
    total = 0
    for d, _, files in os.walk(CORPUS):
        total += sum(os.path.getsize(os.path.join(d, f)) for f in files)
    print("corpus: %d bytes" % total)
