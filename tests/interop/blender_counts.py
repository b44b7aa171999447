# Imports one file into Debian's Blender 3.4 and prints what arrived as one
# JSON line: objects, distinct meshes, vertices, edges, faces, shape keys and
# the animation's frame range. Run as
#   blender -b --factory-startup --python tests/interop/blender_counts.py -- IMPORTER FILE
# with IMPORTER one of obj (bpy.ops.wm.obj_import, the default importer),
# obj-legacy (bpy.ops.import_scene.obj) or gltf (bpy.ops.import_scene.gltf).
#
# glTF: Blender 3.4's importer with Debian 12's numpy 1.24 fails in its default
# "NORMALS" shading mode (it uses np.bool, removed in numpy 1.24), so the import
# asks for import_shading="SMOOTH" (Blender computes smooth normals instead of
# guessing flat faces from the file's normals).
import json
import sys

import bpy

importer, path = sys.argv[sys.argv.index("--") + 1:][:2]
bpy.ops.wm.read_factory_settings(use_empty=True)
if importer == "obj":
    bpy.ops.wm.obj_import(filepath=path)
elif importer == "obj-legacy":
    bpy.ops.import_scene.obj(filepath=path)
elif importer == "gltf":
    bpy.ops.import_scene.gltf(filepath=path, import_shading="SMOOTH")
else:
    sys.exit(f"unknown importer {importer}: obj, obj-legacy or gltf")
objects = [o for o in bpy.context.scene.objects if o.type == "MESH"]
result = {
    "importer": importer,
    "objects": len(objects),
    "meshes": len({o.data.name for o in objects}),
    "vertices": sum(len(o.data.vertices) for o in objects),
    "edges": sum(len(o.data.edges) for o in objects),
    "faces": sum(len(o.data.polygons) for o in objects),
    "shape_keys": 0,
    "frame_range": None,
}
for o in objects:
    keys = o.data.shape_keys
    if keys is not None:
        result["shape_keys"] += len(keys.key_blocks)
        action = keys.animation_data.action if keys.animation_data else None
        if action is not None:
            result["frame_range"] = list(action.frame_range)
print("PLUME_COUNTS " + json.dumps(result))
