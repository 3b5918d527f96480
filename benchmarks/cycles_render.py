"""Runs inside Blender (blender -b --factory-startup -P cycles_render.py -- job.json) for
benchmarks/compare_cycles.py: imports the glTF file, renders it with Cycles from the job's camera
under a white world of strength 1, then compares the Ember EXR of the same view over the pixels
Cycles renders opaque, and writes a side-by-side PNG. Prints one line "RESULT {json}"."""
import json
import math
import sys

import bpy
import numpy as np
from mathutils import Vector

np.bool = bool  # Blender 3.4's glTF importer still uses numpy.bool, gone from numpy 1.24

job = json.load(open(sys.argv[sys.argv.index("--") + 1]))
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=job["model"])
scene = bpy.context.scene
if job.get("single_scatter"):
    # glTF's Appendix B is single-scattering GGX; Blender's Principled BSDF defaults to Kulla-Conty
    # multiple scattering, which keeps the energy rough metals lose.
    for material in bpy.data.materials:
        for node in material.node_tree.nodes if material.node_tree else []:
            if node.type == "BSDF_PRINCIPLED":
                node.distribution = "GGX"


def to_blender(p):
    """glTF is +y up, Blender +z up: the importer maps (x, y, z) to (x, -z, y)."""
    return Vector((p[0], -p[2], p[1]))


camera_data = bpy.data.cameras.new("framing")
camera_data.sensor_fit = "VERTICAL"
camera_data.angle_y = math.radians(40.0)
camera_data.clip_start = 1e-4
camera_data.clip_end = 1e6
camera = bpy.data.objects.new("framing", camera_data)
scene.collection.objects.link(camera)
origin, target = to_blender(job["origin"]), to_blender(job["target"])
camera.location = origin
camera.rotation_euler = (target - origin).to_track_quat("-Z", "Y").to_euler()
scene.camera = camera

world = bpy.data.worlds.new("white")
world.use_nodes = True
background = world.node_tree.nodes["Background"]
background.inputs[0].default_value = (1.0, 1.0, 1.0, 1.0)
background.inputs[1].default_value = 1.0
scene.world = world

render = scene.render
render.engine = "CYCLES"
render.resolution_x, render.resolution_y, render.resolution_percentage = job["width"], job["height"], 100
render.film_transparent = True
render.threads_mode = "FIXED"
render.threads = job["threads"]
render.image_settings.file_format = "OPEN_EXR"
render.image_settings.color_depth = "32"
render.image_settings.color_mode = "RGBA"
render.filepath = job["cycles_exr"]
cycles = scene.cycles
cycles.device = "CPU"
cycles.samples = job["spp"]
cycles.use_adaptive_sampling = False
cycles.use_denoising = False
cycles.pixel_filter_type = "BOX"
cycles.filter_width = 1.0
for bounces in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces",
                "transparent_max_bounces"):
    setattr(cycles, bounces, 1024)
bpy.ops.render.render(write_still=True)


def pixels(path):
    image = bpy.data.images.load(path)
    w, h = image.size
    return np.array(image.pixels[:], dtype=np.float64).reshape(h, w, 4)


cyc = pixels(job["cycles_exr"])
emb = pixels(job["ember_exr"])
mask = cyc[..., 3] > 0.99
ratio = [float(emb[..., c][mask].mean() / max(cyc[..., c][mask].mean(), 1e-12)) for c in range(3)]

# Side by side, Ember left: Cycles' transparent film composited over the white world (its EXR
# holds premultiplied colour), both clamped to [0, 1] and sRGB-encoded alike.
over = cyc[..., :3] + (1.0 - cyc[..., 3:4])
both = np.concatenate([emb[..., :3], over], axis=1).clip(0.0, 1.0)
srgb = np.where(both <= 0.0031308, 12.92 * both, 1.055 * np.power(both, 1.0 / 2.4) - 0.055)
h, w2 = srgb.shape[:2]
rgba = np.concatenate([srgb, np.ones((h, w2, 1))], axis=2)
side = bpy.data.images.new("side-by-side", width=w2, height=h)
side.pixels = rgba.ravel().tolist()
side.filepath_raw = job["png"]
side.file_format = "PNG"
side.save()
print("RESULT " + json.dumps({"ratio": ratio, "pixels": int(mask.sum())}))
