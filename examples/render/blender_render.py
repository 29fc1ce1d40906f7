# Blender side of the ManiSoft renderer adapter (the paper rendered with
# Blender): renders a folder written by include/manisoft/render/blender_export.hpp (scene.json,
# frames.json, meshes/*.obj, rod_<k>.obj) headless, one Blender process for the whole trajectory:
#
#   blender -b --factory-startup --python-exit-code 1 -P blender_render.py -- \
#       --dir EXPORT --out OUT [--engine workbench|cycles] [--samples 16] [--masks 1]
#
# Writes OUT/rgb_<k>.png and, with --masks 1, OUT/mask_<k>.png: a cheap second Workbench pass with
# flat object colours, id i drawn as sRGB (16 (i mod 16) + 8, 16 (i div 16) + 8, 0), background
# black (decoded by examples/render/blender_run.hpp). The camera follows scene.json's OpenCV
# calibration (R world->camera; Blender's camera looks down its -z with y up). Cycles denoising is
# off: Debian's Blender has no OpenImageDenoise.
import argparse
import json
import math
import os
import sys

import bpy
from mathutils import Matrix

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
parser = argparse.ArgumentParser(description="Render a ManiSoft export with Blender")
parser.add_argument("--dir", required=True)
parser.add_argument("--out", required=True)
parser.add_argument("--engine", default="workbench", choices=["workbench", "cycles"])
parser.add_argument("--samples", type=int, default=16)
parser.add_argument("--masks", type=int, default=1)
args = parser.parse_args(argv)

with open(os.path.join(args.dir, "scene.json")) as f:
    desc = json.load(f)
with open(os.path.join(args.dir, "frames.json")) as f:
    frames = json.load(f)
os.makedirs(args.out, exist_ok=True)

scene = bpy.context.scene
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)


def srgb_to_linear(c):
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def load_obj(path, name):
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                verts.append(tuple(float(x) for x in line.split()[1:4]))
            elif line.startswith("f "):
                faces.append(tuple(int(tok.split("/")[0]) - 1 for tok in line.split()[1:]))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
    return mesh


def make_material(name, m):
    mat = bpy.data.materials.new(name)
    base = list(m["base_color"]) + [1.0]
    mat.diffuse_color = base  # Workbench (color_type MATERIAL)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = base
    bsdf.inputs["Roughness"].default_value = max(0.05, 1.0 - float(m.get("specular", 0.2)))
    kind = m.get("texture", "none")
    if kind != "none":
        coords = nodes.new("ShaderNodeTexCoord")
        mix = nodes.new("ShaderNodeMixRGB")
        mix.inputs["Color1"].default_value = base
        mix.inputs["Color2"].default_value = list(m["secondary_color"]) + [1.0]
        scale = float(m.get("texture_scale", 10.0))
        if kind == "checker":
            tex = nodes.new("ShaderNodeTexChecker")
            tex.inputs["Scale"].default_value = scale / 2.0  # Blender's checker has 2 squares per unit
            links.new(coords.outputs["Object"], tex.inputs["Vector"])
        elif kind in ("wood", "marble"):
            tex = nodes.new("ShaderNodeTexWave")
            tex.wave_type = "RINGS" if kind == "wood" else "BANDS"
            tex.inputs["Scale"].default_value = scale / 6.0
            tex.inputs["Distortion"].default_value = 3.0 if kind == "wood" else 12.0
            links.new(coords.outputs["Object"], tex.inputs["Vector"])
        else:  # noise, fabric
            tex = nodes.new("ShaderNodeTexNoise")
            tex.inputs["Scale"].default_value = scale
            links.new(coords.outputs["Object"], tex.inputs["Vector"])
        links.new(tex.outputs["Fac"], mix.inputs["Fac"])
        links.new(mix.outputs["Color"], bsdf.inputs["Base Color"])
    return mat


def id_color(i):
    r, g = 16 * (i % 16) + 8, 16 * (i // 16) + 8
    return (srgb_to_linear(r / 255.0), srgb_to_linear(g / 255.0), 0.0, 1.0)


mesh_cache = {}
objects = []  # (object, object_id)
for k, inst in enumerate(desc["instances"]):
    if inst["mesh"] not in mesh_cache:
        mesh_cache[inst["mesh"]] = load_obj(os.path.join(args.dir, inst["mesh"]), inst["mesh"])
    obj = bpy.data.objects.new("%s_%d" % (inst["name"], k), mesh_cache[inst["mesh"]])
    obj.data.materials.clear()
    obj.active_material_index = 0
    scene.collection.objects.link(obj)
    # Per-object material slot so instances sharing a mesh keep their own material.
    obj.material_slots  # noqa: B018 (ensures slots exist)
    if not obj.data.materials:
        obj.data.materials.append(None)
    obj.material_slots[0].link = "OBJECT"
    obj.material_slots[0].material = make_material("mat_%d" % k, inst["material"])
    obj.color = id_color(inst["object_id"])
    objects.append(obj)

rod_obj = None
if desc["rod"]["present"]:
    rod_obj = bpy.data.objects.new("rod", bpy.data.meshes.new("rod_empty"))
    scene.collection.objects.link(rod_obj)
    rod_material = make_material("rod", desc["rod"]["material"])
    rod_obj.color = id_color(desc["rod"]["object_id"])

goal_objs = []
for axis, color in zip("xyz", [(0.85, 0.1, 0.1), (0.1, 0.7, 0.1), (0.1, 0.2, 0.9)]):
    g = bpy.data.objects.new("goal_" + axis, load_obj(os.path.join(args.dir, "meshes", "goal_%s.obj" % axis), "goal_" + axis))
    g.data.materials.append(make_material("goal_" + axis, {"base_color": color}))
    g.color = id_color(desc["goal"]["object_id"])
    scene.collection.objects.link(g)
    goal_objs.append(g)

# Camera from the OpenCV calibration: Blender camera axes (x right, y up, looking down -z) are
# (R row 0, -R row 1, -R row 2) in world coordinates.
cam_desc = desc["camera"]
R = cam_desc["R"]
cam_data = bpy.data.cameras.new("camera")
cam_data.sensor_fit = "VERTICAL"
cam_data.angle_y = math.radians(cam_desc["fov_y_deg"])
cam_data.clip_start = cam_desc["near"]
cam_data.clip_end = cam_desc["far"]
cam = bpy.data.objects.new("camera", cam_data)
rot = Matrix(((R[0][0], -R[1][0], -R[2][0]), (R[0][1], -R[1][1], -R[2][1]), (R[0][2], -R[1][2], -R[2][2])))
cam.matrix_world = Matrix.Translation(cam_desc["position"]) @ rot.to_4x4()
scene.collection.objects.link(cam)
scene.camera = cam

light_desc = desc["light"]
d = light_desc["direction"]
to_light = [-x for x in d]
if light_desc["kind"] == "spot":
    light_data = bpy.data.lights.new("light", "SPOT")
    light_data.spot_size = math.radians(2 * light_desc["spot_cone_deg"])
    light_data.energy = 800.0 * light_desc["intensity"]
else:
    light_data = bpy.data.lights.new("light", "SUN")
    light_data.energy = 3.0 * light_desc["intensity"]
    light_data.angle = math.radians(2.0)
light_data.color = light_desc["color"]
light = bpy.data.objects.new("light", light_data)
# Point the light's -z along the travel direction.
z = Matrix(((0, 0, 0), (0, 0, 0), (0, 0, 0)))
from mathutils import Vector  # noqa: E402

travel = Vector(d).normalized()
light.rotation_euler = (-travel).to_track_quat("Z", "Y").to_euler()
light.location = light_desc["position"] if light_desc["kind"] == "spot" else (0.4, 0.0, 3.0)
scene.collection.objects.link(light)

world = bpy.data.worlds.new("world")
scene.world = world
bg = desc["background"]
world.color = bg
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = list(bg) + [1.0]
world.node_tree.nodes["Background"].inputs["Strength"].default_value = light_desc["ambient_intensity"] * 2.0

render = scene.render
render.resolution_x = cam_desc["width"]
render.resolution_y = cam_desc["height"]
render.resolution_percentage = 100
render.image_settings.file_format = "PNG"
render.image_settings.color_mode = "RGB"
render.image_settings.color_depth = "8"
render.dither_intensity = 0.0
render.film_transparent = False
scene.view_settings.view_transform = "Standard"
scene.view_settings.look = "None"
scene.view_settings.exposure = 0.0
scene.view_settings.gamma = 1.0
scene.display.light_direction = (to_light[0], to_light[1], to_light[2])


def set_rgb_engine():
    if args.engine == "cycles":
        render.engine = "CYCLES"
        scene.cycles.device = "CPU"
        scene.cycles.samples = args.samples
        scene.cycles.use_denoising = False
        scene.cycles.use_adaptive_sampling = False
        scene.cycles.seed = 0
    else:
        render.engine = "BLENDER_WORKBENCH"
        shading = scene.display.shading
        shading.light = "STUDIO"
        shading.color_type = "MATERIAL"
        shading.show_shadows = True
        shading.shadow_intensity = 0.5
        shading.show_cavity = False
        shading.show_object_outline = False
        shading.show_specular_highlight = True
        scene.display.render_aa = "8"
    world.color = bg


def set_mask_engine():
    render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light = "FLAT"
    shading.color_type = "OBJECT"
    shading.show_shadows = False
    shading.show_cavity = False
    shading.show_object_outline = False
    shading.show_specular_highlight = False
    shading.show_backface_culling = False
    shading.show_xray = False
    scene.display.render_aa = "OFF"
    world.color = (0.0, 0.0, 0.0)


for k, frame in enumerate(frames):
    for obj, rows in zip(objects, frame["instances"]):
        obj.matrix_world = Matrix([rows[0:4], rows[4:8], rows[8:12], rows[12:16]])
    if rod_obj is not None:
        old = rod_obj.data
        if frame["rod"]:
            rod_obj.data = load_obj(os.path.join(args.dir, frame["rod"]), "rod_%05d" % k)
            rod_obj.data.materials.append(rod_material)
            rod_obj.hide_render = False
        else:
            rod_obj.hide_render = True
        if old.users == 0:
            bpy.data.meshes.remove(old)
    for g in goal_objs:
        if frame["goal"]:
            m = frame["goal"]
            g.matrix_world = Matrix([m[0:4], m[4:8], m[8:12], m[12:16]])
            g.hide_render = False
        else:
            g.hide_render = True
    set_rgb_engine()
    render.filepath = os.path.join(args.out, "rgb_%05d.png" % k)
    bpy.ops.render.render(write_still=True)
    if args.masks:
        set_mask_engine()
        render.filepath = os.path.join(args.out, "mask_%05d.png" % k)
        bpy.ops.render.render(write_still=True)
print("manisoft blender_render: %d frame(s) -> %s" % (len(frames), args.out))
