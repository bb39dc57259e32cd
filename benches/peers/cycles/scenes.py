"""The Cycles parity scenes (docs/cycles.md): authored here through `bpy`, exported with
Blender's glTF exporter to tests/data/cycles/<name>/, and rendered by Cycles from the exported
glTF (imported back with Blender's importer, as `render.py` does for any file) into
tests/data/cycles/<name>/reference.exr. Each scene isolates one thing; all share a floor, a back
wall and a camera. `tests/cycles_parity.rs` renders them with mcctrace and compares.

    benches/peers/cycles/run.sh scenes.py [--only NAME,NAME] [--no-render] [--spp N]

References: 96×72, 8 scattering vertices, `--spp` (default 512) with seed 0, rendered on 2
threads; the script appends name, spp, seconds to tests/data/cycles/references.csv. With
`--noise`, a second render at a quarter of the samples (seed 1) estimates each reference's own
relMSE (otherwise the column is nan).
"""

import argparse
import json
import math
import os
import shutil
import sys

import bpy
import numpy as np
from mathutils import Quaternion

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render as peer  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
DATA = os.path.join(ROOT, "tests", "data", "cycles")
SIZE = (96, 72)
DEPTH = 8
# The wall: dark blue and light grey checker squares (sRGB texels).
BLUE_GREY = ((60, 90, 140), (230, 230, 230))


def srgb_to_linear(c):
    c = c / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def image(folder, name, size, texel, colorspace="sRGB", alpha=False):
    """A PNG of `size`² texels, texel(x, y) → RGB(A) bytes, saved in `folder` and loaded."""
    img = bpy.data.images.new(name, size, size, alpha=alpha)
    px = np.zeros((size, size, 4), dtype=np.float32)
    for y in range(size):
        for x in range(size):
            v = texel(x, y)
            px[y, x, : len(v)] = np.array(v, dtype=np.float32) / 255.0
            if len(v) == 3:
                px[y, x, 3] = 1.0
    img.pixels.foreach_set(px.ravel())
    img.filepath_raw = os.path.join(folder, name + ".png")
    img.file_format = "PNG"
    img.save()
    img.colorspace_settings.name = colorspace
    return img


def checker(folder, name, colours, size=64, square=8):
    a, b = colours
    return image(folder, name, size, lambda x, y: a if (x // square + y // square) % 2 else b)


def material(name, base=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5, specular=0.5, ior=1.5,
             emission=None, strength=1.0, transmission=0.0, base_texture=None, normal_texture=None,
             alpha_texture=None, one_sided=False, coat=0.0, coat_roughness=0.03, sheen=None,
             sheen_roughness=0.5, anisotropy=0.0, anisotropy_rotation=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    p = nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*base, 1.0)
    p.inputs["Metallic"].default_value = metallic
    p.inputs["Roughness"].default_value = roughness
    p.inputs["Specular IOR Level"].default_value = specular
    p.inputs["IOR"].default_value = ior
    p.inputs["Transmission Weight"].default_value = transmission
    # The exporter writes KHR_materials_clearcoat for a coat weight above 0 (IOR 1.5, tint white).
    p.inputs["Coat Weight"].default_value = coat
    p.inputs["Coat Roughness"].default_value = coat_roughness
    if sheen is not None:
        # The exporter writes KHR_materials_sheen (colour = weight × tint, roughness); the
        # importer reads it back as weight 1 and that tint.
        p.inputs["Sheen Weight"].default_value = 1.0
        p.inputs["Sheen Tint"].default_value = (*sheen, 1.0)
        p.inputs["Sheen Roughness"].default_value = sheen_roughness
    # The exporter writes KHR_materials_anisotropy from these two values (the rotation in turns
    # becomes radians); the Tangent input stays unlinked, so Cycles uses its default tangent.
    p.inputs["Anisotropic"].default_value = anisotropy
    p.inputs["Anisotropic Rotation"].default_value = anisotropy_rotation
    if emission is not None:
        p.inputs["Emission Color"].default_value = (*emission, 1.0)
        p.inputs["Emission Strength"].default_value = strength
    if base_texture is not None or alpha_texture is not None:
        t = nodes.new("ShaderNodeTexImage")
        t.image = base_texture or alpha_texture
        links.new(t.outputs["Color"], p.inputs["Base Color"])
        if alpha_texture is not None:
            # glTF alphaMode MASK, cutoff 0.5, in the form Blender's exporter recognises:
            # alpha = 1 − (a < 0.5).
            less = peer.math_node(m.node_tree, "LESS_THAN", t.outputs["Alpha"], 0.5)
            one_minus = peer.math_node(m.node_tree, "SUBTRACT", 1.0, less.outputs[0])
            links.new(one_minus.outputs[0], p.inputs["Alpha"])
    if normal_texture is not None:
        t = nodes.new("ShaderNodeTexImage")
        t.image = normal_texture
        nm = nodes.new("ShaderNodeNormalMap")
        links.new(t.outputs["Color"], nm.inputs["Color"])
        links.new(nm.outputs["Normal"], p.inputs["Normal"])
    # The exporter writes `doubleSided: false` for a material with backface culling.
    m.use_backface_culling = one_sided
    return m


def add(obj, mat, uv_scale=1.0):
    obj.data.materials.append(mat)
    if uv_scale != 1.0:
        for loop in obj.data.uv_layers.active.data:
            loop.uv = (loop.uv[0] * uv_scale, loop.uv[1] * uv_scale)
    return obj


def plane(name, size, location, rotation=(0.0, 0.0, 0.0)):
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=location, rotation=rotation)
    o = bpy.context.active_object
    o.name = name
    o.scale = size
    bpy.ops.object.transform_apply(scale=True)
    return o


def sphere(name, radius, location):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=radius, location=location)
    o = bpy.context.active_object
    o.name = name
    bpy.ops.object.shade_smooth()
    return o


def point(name, location, watts, colour=(1.0, 1.0, 1.0)):
    light = bpy.data.lights.new(name, "POINT")
    light.energy = watts
    light.color = colour
    light.shadow_soft_size = 0.0
    o = bpy.data.objects.new(name, light)
    o.location = location
    bpy.context.scene.collection.objects.link(o)
    return o


def spot(name, location, rotation, watts, size_deg, blend):
    light = bpy.data.lights.new(name, "SPOT")
    light.energy = watts
    light.spot_size = math.radians(size_deg)
    light.spot_blend = blend
    light.shadow_soft_size = 0.0
    o = bpy.data.objects.new(name, light)
    o.location = location
    o.rotation_euler = rotation
    bpy.context.scene.collection.objects.link(o)
    return o


def room(floor, wall, floor_uv=1.0, wall_uv=1.0):
    """A 6 × 6 floor at z = 0, a 6 × 4 back wall at y = 2 facing the camera, and the camera."""
    add(plane("floor", (6.0, 6.0, 1.0), (0.0, 0.0, 0.0)), floor, floor_uv)
    add(plane("wall", (6.0, 4.0, 1.0), (0.0, 2.0, 2.0), (math.pi / 2, 0.0, 0.0)), wall, wall_uv)
    cam = bpy.data.cameras.new("camera")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(35.0)
    o = bpy.data.objects.new("camera", cam)
    o.location = (0.0, -6.0, 1.6)
    direction = np.array([0.0, 0.0, 0.9]) - np.array(o.location)
    o.rotation_euler = (math.atan2(math.hypot(direction[0], direction[1]), -direction[2]), 0.0, 0.0)
    bpy.context.scene.collection.objects.link(o)
    bpy.context.scene.camera = o


def grey(v=0.8):
    return material("grey", base=(v, v, v), roughness=1.0, specular=0.0)


def scene_textured_diffuse(folder):
    """Lambert (no specular) with checker textures; one point light."""
    tex = checker(folder, "checker_warm", ((200, 120, 40), (40, 60, 90)))
    wall = checker(folder, "checker_blue_grey", BLUE_GREY)
    room(material("floor", specular=0.0, roughness=1.0, base_texture=tex),
         material("wall", specular=0.0, roughness=1.0, base_texture=wall), floor_uv=3.0, wall_uv=2.0)
    point("light", (1.0, -1.5, 3.0), 300.0)


def scene_textured_rough_dielectric(folder):
    """The issue's wall: base colour texture (60, 90, 140) / (230, 230, 230), metallic 0,
    roughness 0.8, Blender's default specular (IOR 1.5, level 0.5); floor likewise."""
    wall = checker(folder, "checker_blue_grey", BLUE_GREY)
    m = material("rough_dielectric", roughness=0.8, base_texture=wall)
    room(m, m, floor_uv=3.0, wall_uv=2.0)
    point("light", (1.0, -1.5, 3.0), 300.0)


def scene_rough_dielectric(folder):
    """The same material untextured (the dark blue alone): tells the BSDF from the texture."""
    blue = tuple(srgb_to_linear(c) for c in BLUE_GREY[0])
    m = material("rough_dielectric", base=blue, roughness=0.8)
    room(m, m)
    point("light", (1.0, -1.5, 3.0), 300.0)


def scene_smooth_metal(folder):
    """A nearly smooth gold sphere under a large panel: its reflection and the caustic it throws
    are found by BSDF sampling (a point light would leave the caustic to rare fireflies)."""
    room(grey(), grey(0.6))
    add(sphere("ball", 0.8, (0.0, 0.0, 0.8)), material("gold", base=(0.95, 0.65, 0.3), metallic=1.0, roughness=0.1))
    panel = plane("panel", (3.0, 2.0, 1.0), (0.0, -1.0, 3.0), (math.pi, 0.0, 0.0))
    add(panel, material("panel", base=(0.0, 0.0, 0.0), specular=0.0, emission=(1.0, 1.0, 1.0), strength=3.0,
                        one_sided=True))


def scene_rough_metal(folder):
    room(grey(), grey(0.6))
    add(sphere("ball", 0.8, (0.0, 0.0, 0.8)), material("copper", base=(0.9, 0.45, 0.3), metallic=1.0, roughness=0.5))
    point("light", (1.5, -2.0, 3.0), 300.0)


def scene_point_light(folder):
    room(grey(), material("wall", base=(0.2, 0.5, 0.7), roughness=1.0, specular=0.0))
    point("light", (-1.0, 0.5, 1.5), 100.0, (1.0, 0.8, 0.6))


def scene_spot_light(folder):
    room(grey(), grey(0.6))
    spot("spot", (0.0, -1.0, 3.5), (math.radians(20.0), 0.0, 0.0), 800.0, 50.0, 0.3)


def scene_area_light(folder):
    """A one-sided emissive quad (doubleSided: false), tilted so that the camera sees its back."""
    room(grey(), grey(0.6))
    quad = plane("panel", (1.2, 1.2, 1.0), (0.0, 0.5, 2.2), (math.radians(-135.0), 0.0, 0.0))
    add(quad, material("panel", base=(0.0, 0.0, 0.0), specular=0.0, emission=(1.0, 0.9, 0.7), strength=8.0,
                       one_sided=True))


def scene_emission(folder):
    """A two-sided emissive sphere is the only light."""
    room(grey(), grey(0.6))
    add(sphere("lamp", 0.5, (0.0, 0.0, 0.9)),
        material("lamp", base=(0.0, 0.0, 0.0), specular=0.0, emission=(1.0, 0.5, 0.2), strength=6.0))


def scene_normal_map(folder):
    """Ripples by a tangent-space normal map on a glossy floor, lit at a grazing angle."""
    def ripple(x, y):
        a = 2.0 * math.pi * x / 16.0
        n = np.array([-0.5 * math.cos(a), 0.0, 1.0])
        n /= np.linalg.norm(n)
        return tuple(int(round((c * 0.5 + 0.5) * 255.0)) for c in n)
    nmap = image(folder, "ripples", 64, ripple, colorspace="Non-Color")
    room(material("floor", base=(0.7, 0.7, 0.7), roughness=0.4, normal_texture=nmap), grey(0.6), floor_uv=2.0)
    point("light", (-3.0, 0.5, 0.8), 150.0)


def scene_alpha_mask(folder):
    """A quad with round holes (alphaMode MASK) in front of the wall casts a patterned shadow."""
    def holes(x, y):
        cx, cy = x % 16 - 7.5, y % 16 - 7.5
        return (200, 80, 60, 0 if cx * cx + cy * cy < 25.0 else 255)
    tex = image(folder, "holes", 64, holes, alpha=True)
    room(grey(), grey(0.6))
    add(plane("screen", (2.0, 2.0, 1.0), (0.0, 0.8, 1.2), (math.pi / 2, 0.0, 0.0)),
        material("screen", roughness=1.0, specular=0.0, alpha_texture=tex))
    point("light", (0.8, -2.5, 2.5), 300.0)


def scene_transmission(folder):
    """A smooth glass sphere (transmission 1, IOR 1.5) over a checker floor."""
    tex = checker(folder, "checker_warm", ((200, 120, 40), (40, 60, 90)))
    room(material("floor", specular=0.0, roughness=1.0, base_texture=tex), grey(0.6), floor_uv=3.0)
    add(sphere("glass", 0.7, (0.0, 0.0, 0.7)), material("glass", base=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0))
    point("light", (1.5, -2.0, 3.0), 300.0)


def scene_half_metal_glass(folder):
    """Issue 39's probe: a smooth sphere, metallic 0.5 and transmission 1, over the checker floor:
    half mirror, half glass, no diffuse part (Principled: metal m, glass (1 − m)·T). Lit by a
    large panel, as smooth_metal is: the mirror's caustic of a point light would be fireflies."""
    tex = checker(folder, "checker_warm", ((200, 120, 40), (40, 60, 90)))
    room(material("floor", specular=0.0, roughness=1.0, base_texture=tex), grey(0.6), floor_uv=3.0)
    probe = material("probe", base=(1.0, 1.0, 1.0), metallic=0.5, roughness=0.0, transmission=1.0)
    add(sphere("probe", 0.7, (0.0, 0.0, 0.7)), probe)
    panel = plane("panel", (3.0, 2.0, 1.0), (0.0, -1.0, 3.0), (math.pi, 0.0, 0.0))
    add(panel, material("panel", base=(0.0, 0.0, 0.0), specular=0.0, emission=(1.0, 1.0, 1.0), strength=3.0,
                        one_sided=True))


def scene_coat(folder):
    """KHR_materials_clearcoat: a red diffuse sphere under a full, fairly smooth coat, and a copper
    sphere under a half-weight rougher one, lit by a point light and a panel whose reflection the
    coats show."""
    room(grey(), grey(0.6))
    red = material("coated_red", base=(0.8, 0.1, 0.08), roughness=0.6, coat=1.0, coat_roughness=0.15)
    add(sphere("red", 0.6, (-0.7, 0.0, 0.6)), red)
    copper = material("coated_copper", base=(0.9, 0.45, 0.3), metallic=1.0, roughness=0.5, coat=0.5,
                      coat_roughness=0.3)
    add(sphere("copper", 0.6, (0.7, 0.2, 0.6)), copper)
    # The light stays clear of the panel's plane: at its edge, shadow rays would graze the panel.
    point("light", (1.6, -2.0, 2.5), 200.0)
    panel = plane("panel", (2.0, 2.0, 1.0), (-0.6, -1.0, 3.0), (math.pi, 0.0, 0.0))
    add(panel, material("panel", base=(0.0, 0.0, 0.0), specular=0.0, emission=(1.0, 1.0, 1.0), strength=3.0,
                        one_sided=True))


def scene_sheen(folder):
    """KHR_materials_sheen: a rose sheen of roughness 0.3 over a dark blue diffuse sphere and a
    pale rough sheen (0.8) over a green one, lit by a point light in front and one behind them,
    low, so that the fibres' grazing rims show against the wall."""
    room(grey(), grey(0.6))
    rose = material("sheen_rose", base=(0.04, 0.04, 0.08), roughness=0.6, sheen=(0.9, 0.3, 0.5),
                    sheen_roughness=0.3)
    add(sphere("rose", 0.6, (-0.7, 0.0, 0.6)), rose)
    pale = material("sheen_pale", base=(0.15, 0.3, 0.1), roughness=0.8, sheen=(0.8, 0.8, 0.7),
                    sheen_roughness=0.8)
    add(sphere("pale", 0.6, (0.7, 0.2, 0.6)), pale)
    point("light", (1.6, -2.0, 2.5), 200.0)
    point("rim", (0.0, 1.3, 1.4), 120.0)


def scene_anisotropy(folder):
    """KHR_materials_anisotropy: two brushed-metal UV spheres (roughness 0.45, anisotropy 0.8), the
    left one's grain along its tangent, the right one's turned by 30 degrees, lit by a point light
    and a panel whose stretched highlights show the grain. Blender's importer leaves the Tangent
    input unlinked (Cycles' default: around the object's Z axis), which on a UV sphere is the
    direction of its u coordinate, the MikkTSpace tangent mcctrace generates."""
    room(grey(), grey(0.6))
    gold = material("brushed_gold", base=(0.95, 0.7, 0.4), metallic=1.0, roughness=0.45, anisotropy=0.8)
    add(sphere("gold", 0.6, (-0.7, 0.0, 0.6)), gold)
    steel = material("brushed_steel", base=(0.8, 0.8, 0.82), metallic=1.0, roughness=0.45, anisotropy=0.8,
                     anisotropy_rotation=1.0 / 12.0)
    add(sphere("steel", 0.6, (0.7, 0.2, 0.6)), steel)
    point("light", (1.6, -2.0, 2.5), 200.0)
    panel = plane("panel", (2.0, 2.0, 1.0), (-0.6, -1.0, 3.0), (math.pi, 0.0, 0.0))
    add(panel, material("panel", base=(0.0, 0.0, 0.0), specular=0.0, emission=(1.0, 1.0, 1.0), strength=3.0,
                        one_sided=True))


def panel_light(strength=3.0):
    """The large one-sided panel above the scene that smooth_metal uses: glass reflects and
    transmits it by BSDF sampling, without the fireflies a point light's caustic would make."""
    panel = plane("panel", (3.0, 2.0, 1.0), (0.0, -1.0, 3.0), (math.pi, 0.0, 0.0))
    add(panel, material("panel", base=(0.0, 0.0, 0.0), specular=0.0, emission=(1.0, 1.0, 1.0), strength=strength,
                        one_sided=True))


def scene_rough_glass(folder):
    """A frosted glass sphere (transmission 1, roughness 0.3, IOR 1.5) over the checker floor:
    Cycles' microfacet glass (GGX, energy-compensated), lit by the panel."""
    tex = checker(folder, "checker_warm", ((200, 120, 40), (40, 60, 90)))
    room(material("floor", specular=0.0, roughness=1.0, base_texture=tex), grey(0.6), floor_uv=3.0)
    add(sphere("glass", 0.7, (0.0, 0.0, 0.7)), material("glass", base=(1.0, 1.0, 1.0), roughness=0.3, transmission=1.0))
    panel_light()


def scene_absorbing_glass(folder):
    """A smooth glass sphere filled with a coloured absorbing medium (KHR_materials_volume,
    attenuation colour (0.9, 0.5, 0.2) at distance 0.5: Blender's importer builds a Volume
    Absorption node of that colour and density 2), over the checker floor, lit by the panel.
    Blender's exporter writes the extension only from its glTF Material Output group, so
    `VOLUME_PATCHES` adds it to the exported file, which both renderers then read."""
    tex = checker(folder, "checker_warm", ((200, 120, 40), (40, 60, 90)))
    room(material("floor", specular=0.0, roughness=1.0, base_texture=tex), grey(0.6), floor_uv=3.0)
    add(sphere("glass", 0.7, (0.0, 0.0, 0.7)), material("glass", base=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0))
    panel_light()


def column_mesh(name, radius, height, rings, segments=32):
    """A closed, smooth-shaded cylinder standing on z = 0: `rings` + 1 rings of `segments`
    vertices (enough to bend smoothly), caps of one fan each."""
    verts, faces = [], []
    for r in range(rings + 1):
        z = height * r / rings
        for s in range(segments):
            a = 2.0 * math.pi * s / segments
            verts.append((radius * math.cos(a), radius * math.sin(a), z))
    for r in range(rings):
        for s in range(segments):
            a, b = r * segments + s, r * segments + (s + 1) % segments
            faces.append((a, b, b + segments, a + segments))
    faces.append(tuple(reversed(range(segments))))
    faces.append(tuple(rings * segments + s for s in range(segments)))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    o = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(o)
    for poly in mesh.polygons:
        poly.use_smooth = True
    return o


def rigged_column(location, bones=4, height=2.0, radius=0.22):
    """A character-like rig: a column of `bones` chained bones standing at `location`, skinned
    with smooth weights (each vertex shared by the two bones nearest its height, a linear
    ramp between their centres), as a limb is. Returns (armature, mesh, pose bones)."""
    scene = bpy.context.scene
    arm = bpy.data.armatures.new("rig")
    rig = bpy.data.objects.new("rig", arm)
    rig.location = location
    scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    step = height / bones
    parent = None
    for i in range(bones):
        eb = arm.edit_bones.new(f"bone{i}")
        eb.head, eb.tail = (0.0, 0.0, i * step), (0.0, 0.0, (i + 1) * step)
        if parent is not None:
            eb.parent, eb.use_connect = parent, True
        parent = eb
    bpy.ops.object.mode_set(mode="OBJECT")
    body = column_mesh("body", radius, height, rings=8 * bones)
    body.parent = rig
    modifier = body.modifiers.new("skin", "ARMATURE")
    modifier.object = rig
    groups = [body.vertex_groups.new(name=f"bone{i}") for i in range(bones)]
    for v in body.data.vertices:
        # The bone coordinate u: bone i spans [i, i + 1); weights ramp between centres.
        u = min(max(v.co.z / step - 0.5, 0.0), bones - 1.0)
        i = min(int(u), bones - 2)
        f = u - i
        for j, w in ((i, 1.0 - f), (i + 1, f)):
            if w > 0.0:
                groups[j].add([v.index], w, "REPLACE")
    return rig, body, rig.pose.bones


def key_bends(bones, keys):
    """Keys each pose bone's rotation about its local Z (the camera's line of sight, Blender's
    world Y, for these bones along world Z: a bone's local Y runs along it) at the given frames:
    keys = [(frame, [angle in degrees per bone]), ...], linear in between."""
    for frame, angles in keys:
        for pb, angle in zip(bones, angles):
            pb.rotation_mode = "QUATERNION"
            pb.rotation_quaternion = Quaternion((0.0, 0.0, 1.0), math.radians(angle))
            pb.keyframe_insert("rotation_quaternion", frame=frame)
    linear_keys()


def linear_keys():
    for action in bpy.data.actions:
        for curve in fcurves_of(action):
            for k in curve.keyframe_points:
                k.interpolation = "LINEAR"


def fcurves_of(action):
    """An action's F-curves (Blender 5 keeps them in layered channel bags)."""
    if hasattr(action, "fcurves") and len(action.fcurves):
        return list(action.fcurves)
    return [c for layer in action.layers for strip in layer.strips for bag in strip.channelbags
            for c in bag.fcurves]


def scene_skinned_rig(folder):
    """A character rig: a column of four chained bones with smooth skin weights, bending like
    a limb (keys at frames 0, 12 and 24); rendered at three frames (`ANIMATED`)."""
    room(grey(), grey(0.6))
    _, body, bones = rigged_column((0.0, 0.3, 0.0))
    body.data.materials.append(material("skin", base=(0.8, 0.35, 0.25), roughness=0.6))
    key_bends(bones, [(0, [0, 0, 0, 0]), (12, [15, 30, 35, 30]), (24, [-10, -35, -40, -45])])
    point("light", (1.5, -2.5, 3.0), 300.0)


def scene_shape_keys(folder):
    """Shape keys: a sphere with two keys (a bulge upwards, a squash sideways) whose values are
    keyed at frames 0, 10 and 20 (linear); rendered at frame 7, between keys."""
    room(grey(), grey(0.6))
    ball = sphere("ball", 0.6, (0.0, 0.0, 0.7))
    ball.shape_key_add(name="Basis")
    up, wide = ball.shape_key_add(name="up"), ball.shape_key_add(name="wide")
    for i, v in enumerate(ball.data.vertices):
        x, y, z = v.co
        up.data[i].co = (x, y, z + 0.8 * max(z, 0.0) ** 2 / 0.6)
        wide.data[i].co = (1.7 * x, y, 0.6 * z)
    ball.data.materials.append(material("clay", base=(0.3, 0.6, 0.3), roughness=0.5))
    for frame, (a, b) in ((0, (0.0, 0.0)), (10, (1.0, 0.2)), (20, (0.1, 1.0))):
        up.value, wide.value = a, b
        up.keyframe_insert("value", frame=frame)
        wide.keyframe_insert("value", frame=frame)
    linear_keys()
    point("light", (1.5, -2.5, 3.0), 300.0)


def scene_deforming_blur(folder):
    """Deformation motion blur: the rig swinging fast (each bone 15° a frame: its tip sweeps
    about 1 m while the shutter is open; frame 2, START, 0.5 frames: `ANIMATED`)."""
    room(grey(), grey(0.6))
    _, body, bones = rigged_column((0.0, 0.3, 0.0))
    body.data.materials.append(material("skin", base=(0.8, 0.35, 0.25), roughness=0.6))
    key_bends(bones, [(0, [-30, -30, -30, -30]), (4, [30, 30, 30, 30])])
    point("light", (1.5, -2.5, 3.0), 300.0)


def scene_rigid_blur(folder):
    """Rigid motion blur: a cube sliding along x (1 m per frame, linear keys) in front of the
    wall, a static sphere beside it (frame 6, START, 0.5 frames: `ANIMATED`)."""
    room(grey(), grey(0.6))
    bpy.ops.mesh.primitive_cube_add(size=0.8, location=(0.0, 0.0, 0.8))
    cube = bpy.context.active_object
    cube.name = "cube"
    add(cube, material("cube", base=(0.2, 0.3, 0.8), roughness=0.5))
    add(sphere("ball", 0.4, (1.4, 0.5, 0.4)), material("ball", base=(0.8, 0.6, 0.2), roughness=0.5))
    for frame, x in ((0, -2.5), (12, 2.5)):
        cube.location.x = x
        cube.keyframe_insert("location", frame=frame)
    linear_keys()
    point("light", (1.5, -2.5, 3.0), 300.0)


def scene_rigid_spin(folder):
    """Rigid rotation blur: a bar spinning about the camera's line of sight (Blender's Y, 40° a
    frame, linear keys) in front of the wall, so that it turns 20° in the image plane while the
    shutter is open (frame 6, START, 0.5 frames: `ANIMATED`). Its ends sweep arcs, which the
    renderers draw by interpolating its rotation (mcctrace by slerp, Cycles its decomposed
    transforms) between the motion steps."""
    room(grey(), grey(0.6))
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, 1.0))
    bar = bpy.context.active_object
    bar.name = "bar"
    bar.scale = (1.6, 0.3, 0.3)
    bpy.ops.object.transform_apply(scale=True)
    add(bar, material("bar", base=(0.2, 0.3, 0.8), roughness=0.5))
    bar.rotation_mode = "XYZ"
    for frame, degrees in ((0, 0.0), (12, 480.0)):
        bar.rotation_euler = (0.0, math.radians(degrees), 0.0)
        bar.keyframe_insert("rotation_euler", frame=frame)
    linear_keys()
    point("light", (1.5, -2.5, 3.0), 300.0)


# The animated scenes' references: scene → [(suffix, frame, shutter in frames)], written to
# reference-<suffix>.exr. A shutter s is Blender's motion blur at position START with shutter s,
# which is mcctrace's `--shutter 0..s` (README, "Animation").
ANIMATED = {
    "skinned_rig": [("f6", 6, 0.0), ("f12", 12, 0.0), ("f20", 20, 0.0)],
    "shape_keys": [("f7", 7, 0.0)],
    "deforming_blur": [("f2", 2, 0.5)],
    "rigid_blur": [("f6", 6, 0.5)],
    "rigid_spin": [("f6", 6, 0.5)],
}


# KHR_materials_volume added to a material of the exported file: scene → (material, extension).
VOLUME_PATCHES = {
    "absorbing_glass": ("glass", {"thicknessFactor": 1.0, "attenuationDistance": 0.5,
                                  "attenuationColor": [0.9, 0.5, 0.2]}),
}


def patch_volume(path, material_name, extension):
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    for m in doc["materials"]:
        if m.get("name") == material_name:
            m.setdefault("extensions", {})["KHR_materials_volume"] = extension
    used = doc.setdefault("extensionsUsed", [])
    if "KHR_materials_volume" not in used:
        used.append("KHR_materials_volume")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=2)


SCENES = {name[len("scene_"):]: f for name, f in globals().items() if name.startswith("scene_")}


def author(name):
    folder = os.path.join(DATA, name)
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    SCENES[name](folder)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    path = os.path.join(folder, name + ".gltf")
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLTF_SEPARATE", export_cameras=True,
                              export_lights=True, export_yup=True, export_apply=True)
    if name in VOLUME_PATCHES:
        patch_volume(path, *VOLUME_PATCHES[name])
    return path


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    p = argparse.ArgumentParser()
    p.add_argument("--only")
    p.add_argument("--no-render", action="store_true")
    p.add_argument("--spp", type=int, default=512)
    p.add_argument("--noise", action="store_true", help="estimate each reference's noise")
    a = p.parse_args(argv)
    names = a.only.split(",") if a.only else list(SCENES)
    noise = []
    for name in names:
        path = author(name)
        if a.no_render:
            continue
        for suffix, frame, shutter in ANIMATED.get(name, [("", None, 0.0)]):
            scene = peer.import_scene(path, "camera")
            peer.one_sided_emission(path)
            peer.configure(scene, SIZE, a.spp, DEPTH, 0, 2)
            if frame is not None:
                peer.at_frame(scene, frame, shutter)
            out = os.path.join(DATA, name, f"reference-{suffix}.exr" if suffix else "reference.exr")
            seconds = peer.render(scene, out)
            ref = peer.load_rgb(out)
            label = f"{name} {suffix}".strip()
            est = float("nan")
            if a.noise:
                scene.cycles.samples = a.spp // 4
                scene.cycles.seed = 1
                second = os.path.join(DATA, name, "noise.exr")
                peer.render(scene, second)
                est = peer.noise_of(ref, peer.load_rgb(second), a.spp, a.spp // 4)
                os.remove(second)
            print(f"{label}: {a.spp} spp in {seconds:.1f} s, estimated relMSE {est:.2e}, means {ref.mean(axis=(0, 1))}")
            noise.append((label.replace(" ", "@"), a.spp, seconds, est))
    if noise:
        with open(os.path.join(DATA, "references.csv"), "a", encoding="utf-8") as f:
            # name, spp, seconds, estimated relMSE of the reference (nan without --noise)
            for row in noise:
                f.write("%s,%d,%.1f,%.3e\n" % row)


if __name__ == "__main__":
    main()
