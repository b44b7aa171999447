# Renders a .glb as Blender imports it (docs/formats.md's pictures): Blender's
# own glTF importer, Cycles on the CPU (no GPU or display needed), a camera
# that frames the imported objects from a given direction.
#   blender -b --factory-startup --python blender_render.py -- IN.glb OUT.png
#           [--size WxH] [--samples N] [--frame last|N] [--view AZIMUTH,ELEVATION]
import math
import sys

import bpy
from mathutils import Vector

args = sys.argv[sys.argv.index("--") + 1 :]
source, target = args[0], args[1]
options = dict(zip(args[2::2], args[3::2]))
width, height = (int(x) for x in options.get("--size", "480x640").split("x"))
azimuth, elevation = (math.radians(float(x)) for x in options.get("--view", "0,10").split(","))

bpy.ops.wm.read_factory_settings(use_empty=True)
# Shading "Smooth": the default runs code that Debian 12's numpy 1.24 breaks (docs/formats.md).
bpy.ops.import_scene.gltf(filepath=source, import_shading="SMOOTH")
scene = bpy.context.scene
if "--frame" in options:
    scene.frame_set(scene.frame_end if options["--frame"] == "last" else int(options["--frame"]))

# Bounds of what is shown at this frame (shape keys applied).
depsgraph = bpy.context.evaluated_depsgraph_get()
lo = Vector((math.inf,) * 3)
hi = Vector((-math.inf,) * 3)
for obj in scene.objects:
    if obj.type != "MESH":
        continue
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    for v in mesh.vertices:
        p = evaluated.matrix_world @ v.co
        lo = Vector(map(min, lo, p))
        hi = Vector(map(max, hi, p))
    evaluated.to_mesh_clear()
center = (lo + hi) / 2
radius = (hi - lo).length / 2

# glTF's +Z (plume's front) is Blender's -Y after import; +Y up is +Z.
direction = Vector((math.sin(azimuth) * math.cos(elevation), -math.cos(azimuth) * math.cos(elevation), math.sin(elevation)))
camera_data = bpy.data.cameras.new("camera")
camera_data.lens = 50
camera = bpy.data.objects.new("camera", camera_data)
scene.collection.objects.link(camera)
fov = 2 * math.atan(18 / camera_data.lens) * min(1.0, width / height)
distance = 1.02 * radius / math.tan(fov / 2)
camera.location = center + direction * distance
camera.rotation_euler = (-direction).to_track_quat("-Z", "Y").to_euler()
camera_data.clip_start = distance / 100
camera_data.clip_end = distance * 100
scene.camera = camera

sun_data = bpy.data.lights.new("sun", "SUN")
sun_data.energy = 3.0
sun = bpy.data.objects.new("sun", sun_data)
scene.collection.objects.link(sun)
sun.rotation_euler = (direction + Vector((0.4, 0, 0.5))).to_track_quat("Z", "Y").to_euler()  # from in front, above
world = bpy.data.worlds.new("world")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.18, 0.19, 0.21, 1)  # a grey sky: fill light
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
scene.world = world

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = int(options.get("--samples", "16"))
scene.cycles.use_denoising = False
scene.render.resolution_x = width
scene.render.resolution_y = height
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "PNG"
scene.render.filepath = target
bpy.ops.render.render(write_still=True)
