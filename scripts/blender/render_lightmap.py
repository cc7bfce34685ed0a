"""Blender side of the lightmap check: imports a `--lightmap` .glb as a
user does (File > Import > glTF 2.0, its defaults), reports how each
material's Emission is wired, renders the model from the program's camera
and, given the program's own picture, prints how the two differ.

    blender -b --factory-startup --python render_lightmap.py -- \
        MODEL.glb OUT.png --eye X,Y,Z --look-at X,Y,Z [--up X,Y,Z] \
        [--fov DEG] [--size WxH] [--engine cycles|eevee] [--samples N] \
        [--light-paths camera|default] [--view-transform NAME] \
        [--world R,G,B] [--compare PICTURE.png]

The camera options mean what the program's options of those names mean
(scene coordinates, +y up as in glTF; a vertical field of view in
degrees). The defaults are the guide's settings: no lamps, the world
black, Color Management's View Transform Standard; --view-transform and
--world show what other settings do. Cycles runs on the CPU; by default
(--light-paths camera) it draws the camera's first hit only, with no
bounce and the model seen by no other ray, since the baked light already
holds every bounce and Cycles would otherwise light the model again from
its own emission (--light-paths default keeps Blender's light paths).
EEVEE adds no such light; it needs an OpenGL context.

With --compare, prints `relative block error: P %`: the mean absolute
difference of 4 x 4-pixel block means in linear light, relative to the
program's picture, as the project's browser test measures it. Exits 1 if a
material is not wired Emission <- lightmap image (sRGB, strength 1) <-
second UV map.
"""

import argparse
import math
import os
import sys

import bpy
import mathutils


def parse():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser(prog="render_lightmap.py")
    ap.add_argument("model")
    ap.add_argument("out")
    triple = lambda t: [float(v) for v in t.split(",")]
    ap.add_argument("--eye", type=triple, required=True)
    ap.add_argument("--look-at", type=triple, required=True)
    ap.add_argument("--up", type=triple, default=[0.0, 1.0, 0.0])
    ap.add_argument("--fov", type=float, default=45.0)
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--engine", choices=["eevee", "cycles"], default="cycles")
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--light-paths", choices=["camera", "default"], default="camera")
    ap.add_argument("--view-transform", default="Standard")
    ap.add_argument("--world", type=triple, default=[0.0, 0.0, 0.0])
    ap.add_argument("--compare")
    return ap.parse_args(argv)


def import_model(path):
    """File > Import > glTF 2.0 with its defaults. Debian 12's Blender
    3.4.1 with numpy 1.24 fails in the default Shading mode ("Use Normal
    Data": `module 'numpy' has no attribute 'bool'`); Shading "Flat" avoids
    that code and changes nothing an emission-only render shows."""
    import warnings

    import numpy

    options = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        has_bool = hasattr(numpy, "bool")
    if not has_bool:
        print("note: this numpy has no numpy.bool; importing with Shading: Flat")
        options["import_shading"] = "FLAT"
    bpy.ops.import_scene.gltf(filepath=path, **options)


def wiring():
    """Each material's Emission source as (material, image, its colour
    space, UV map name, strength), and the problems found."""
    rows, problems = [], []
    for m in bpy.data.materials:
        if not m.use_nodes:
            continue
        nodes = m.node_tree.nodes
        bsdf = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
        if bsdf is None:
            problems.append(f"{m.name}: no Principled BSDF")
            continue
        # Blender 4 renamed the input "Emission Color".
        emission = bsdf.inputs.get("Emission Color") or bsdf.inputs["Emission"]
        strength = bsdf.inputs["Emission Strength"].default_value
        if not emission.is_linked:
            problems.append(f"{m.name}: Emission is not wired")
            continue
        tex = emission.links[0].from_node
        if tex.type != "TEX_IMAGE" or tex.image is None:
            problems.append(f"{m.name}: Emission comes from {tex.type}, not an image")
            continue
        vector = tex.inputs["Vector"]
        uv = vector.links[0].from_node if vector.is_linked else None
        uv_name = uv.uv_map if uv is not None and uv.type == "UVMAP" else "(the first)"
        rows.append((m.name, tex.image.name, tex.image.colorspace_settings.name, uv_name, strength))
    for obj in bpy.context.scene.objects:
        if obj.type != "MESH":
            continue
        names = [uv.name for uv in obj.data.uv_layers]
        for name, _, _, uv_name, _ in rows:
            if any(s.material and s.material.name == name for s in obj.material_slots):
                if len(names) < 2 or uv_name != names[1]:
                    problems.append(f"{obj.name}/{name}: lightmap on UV map {uv_name}, "
                                    f"the second is {names[1:2]}")
    for name, image, space, _, strength in rows:
        if image != "lightmap":
            problems.append(f"{name}: Emission shows image {image}, not the lightmap")
        if space != "sRGB":
            problems.append(f"{name}: lightmap read as {space}, not sRGB")
        if abs(strength - 1.0) > 1e-6:
            problems.append(f"{name}: Emission Strength {strength}, not 1")
    return rows, problems


def set_camera(a, width, height, reach):
    """The program's camera in Blender's axes (the importer turns glTF's
    +y up into Blender's +z: (x, y, z) -> (x, -z, y))."""
    to_blender = lambda v: mathutils.Vector((v[0], -v[2], v[1]))
    eye, target, up = to_blender(a.eye), to_blender(a.look_at), to_blender(a.up)
    forward = (target - eye).normalized()
    right = forward.cross(up).normalized()
    true_up = right.cross(forward)
    # A Blender camera looks down its local -z with +y up.
    basis = mathutils.Matrix((right, true_up, -forward)).transposed()
    data = bpy.data.cameras.new("program camera")
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(a.fov)
    # The default clip end (100 m) cuts a model in millimetres.
    data.clip_start = reach * 1e-5
    data.clip_end = reach * 4
    cam = bpy.data.objects.new("program camera", data)
    cam.matrix_world = mathutils.Matrix.Translation(eye) @ basis.to_4x4()
    bpy.context.scene.collection.objects.link(cam)
    bpy.context.scene.camera = cam


def set_render(a, width, height):
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.color_depth = "8"
    scene.render.dither_intensity = 0.0
    # The guide's settings: the world black, View Transform Standard.
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = False
    world.color = a.world
    scene.view_settings.view_transform = a.view_transform
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    if a.engine == "eevee":
        scene.render.engine = "BLENDER_EEVEE"
        scene.eevee.taa_render_samples = a.samples
    else:
        scene.render.engine = "CYCLES"
        scene.cycles.device = "CPU"
        scene.cycles.samples = a.samples
        scene.cycles.use_denoising = False
        if a.light_paths == "camera":
            # The camera's first hit shows its emission only, as in the
            # program's picture: no bounce, and the model seen by no ray
            # but the camera's, so its emission lights nothing.
            scene.cycles.max_bounces = 0
            for obj in scene.objects:
                if obj.type == "MESH":
                    obj.visible_diffuse = False
                    obj.visible_glossy = False
                    obj.visible_transmission = False
                    obj.visible_volume_scatter = False
                    obj.visible_shadow = False


def linear_blocks(path, width, height):
    """The picture at `path` as 4 x 4 block sums of linear light (RGB
    together), decoding sRGB codes as the browser test does."""
    image = bpy.data.images.load(path)
    image.colorspace_settings.name = "Non-Color"
    if tuple(image.size) != (width, height):
        sys.exit(f"{path} is {image.size[0]}x{image.size[1]}, not {width}x{height}")
    pixels = list(image.pixels)
    channels = image.channels

    def linear(e):
        e = round(e * 255.0) / 255.0
        return e / 12.92 if e <= 0.04045 else ((e + 0.055) / 1.055) ** 2.4

    table = {}
    blocks = [[0.0] * (width // 4) for _ in range(height // 4)]
    for y in range(height // 4 * 4):
        # Blender's rows run bottom to top.
        row = (height - 1 - y) * width * channels
        line = blocks[y // 4]
        for x in range(width // 4 * 4):
            at = row + x * channels
            s = 0.0
            for c in range(3):
                v = pixels[at + c]
                if v not in table:
                    table[v] = linear(v)
                s += table[v]
            line[x // 4] += s
    return blocks


def main():
    a = parse()
    width, height = (int(v) for v in a.size.split("x"))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    import_model(os.path.abspath(a.model))
    rows, problems = wiring()
    for name, image, space, uv, strength in rows:
        print(f"material {name}: Emission <- image {image} ({space}) <- UV map {uv}, "
              f"strength {strength:g}")
    corners = [o.matrix_world @ mathutils.Vector(c) for o in bpy.context.scene.objects
               if o.type == "MESH" for c in o.bound_box]
    centre = sum(corners, mathutils.Vector()) / max(len(corners), 1)
    size = max(((c - centre).length for c in corners), default=1.0)
    eye = mathutils.Vector((a.eye[0], -a.eye[2], a.eye[1]))
    set_camera(a, width, height, size + (eye - centre).length)
    set_render(a, width, height)
    bpy.context.scene.render.filepath = os.path.abspath(a.out)
    bpy.ops.render.render(write_still=True)
    print(f"rendered {a.out} ({bpy.context.scene.render.engine}, {a.samples} samples)")
    if problems:
        for p in problems:
            print(f"problem: {p}")
        sys.exit(1)
    if a.compare:
        want = linear_blocks(os.path.abspath(a.compare), width, height)
        got = linear_blocks(os.path.abspath(a.out), width, height)
        diff = sum(abs(p - q) for wr, gr in zip(want, got) for p, q in zip(wr, gr))
        total = sum(sum(r) for r in want)
        print(f"relative block error: {100.0 * diff / total:.2f} %")


if __name__ == "__main__":
    main()
