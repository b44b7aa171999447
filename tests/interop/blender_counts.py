# Runs inside Blender: imports a file with the named importer into an empty
# scene and reports what Blender holds afterwards. No judgement here: the
# counts are compared with what plume wrote by interop.py.
#   blender -b --factory-startup --python THIS -- JOBS.json RESULTS.json
#       every job {"path", "importer", ...} of JOBS.json, results to RESULTS.json
#   blender -b --factory-startup --python THIS -- IMPORTER FILE
#       one file; prints "PLUME_COUNTS {json}" (docs/formats.md)
# IMPORTER: obj (bpy.ops.wm.obj_import, the default), obj-legacy
# (bpy.ops.import_scene.obj), gltf (bpy.ops.import_scene.gltf), gltf-default.
import json
import sys

import bpy

IMPORTERS = {
    # Blender 3.4's default OBJ importer (C++) and the legacy Python one.
    "obj": lambda path: bpy.ops.wm.obj_import(filepath=path),
    "obj-legacy": lambda path: bpy.ops.import_scene.obj(filepath=path, split_mode="OFF"),
    # Shading "Smooth": the default ("Normals") runs code of Blender 3.4.1's
    # importer that uses numpy.bool, which Debian 12's numpy 1.24 no longer has
    # (AttributeError; docs/formats.md). The normals are imported either way.
    "gltf": lambda path: bpy.ops.import_scene.gltf(filepath=path, import_shading="SMOOTH"),
    "gltf-default": lambda path: bpy.ops.import_scene.gltf(filepath=path),
}


def counts():
    objects = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    meshes = {o.data for o in objects}
    frames = 0
    shape_keys = 0
    for o in objects:
        keys = o.data.shape_keys
        if keys is not None:
            shape_keys = max(shape_keys, len(keys.key_blocks) - 1)
            action = keys.animation_data.action if keys.animation_data else None
            if action is not None:
                frames = max([frames] + [len(c.keyframe_points) for c in action.fcurves])
        if o.animation_data and o.animation_data.action:
            frames = max([frames] + [len(c.keyframe_points) for c in o.animation_data.action.fcurves])
    return {
        "objects": len(objects),
        "meshes": len(meshes),
        # Per object, so node instances of one mesh count once each.
        "vertices": sum(len(o.data.vertices) for o in objects),
        "edges": sum(len(o.data.edges) for o in objects),
        "faces": sum(len(o.data.polygons) for o in objects),
        "triangles": sum(len(p.vertices) - 2 for o in objects for p in o.data.polygons),
        "loose_edges": sum(sum(1 for e in o.data.edges if e.is_loose) for o in objects),
        "uv_layers": min([len(o.data.uv_layers) for o in objects] or [0]),
        "shape_keys": shape_keys,
        "frames": frames,
    }


def main():
    args = sys.argv[sys.argv.index("--") + 1 :]
    if args[0] in IMPORTERS:
        jobs = [{"importer": args[0], "path": args[1]}]
    else:
        jobs = json.load(open(args[0]))
    results = []
    for job in jobs:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        try:
            outcome = IMPORTERS[job["importer"]](job["path"])
            result = counts() if "FINISHED" in outcome else {"error": str(outcome)}
        except Exception as error:  # an importer that throws is a result too
            result = {"error": "%s: %s" % (type(error).__name__, error)}
        results.append(dict(job, blender=result))
    if args[0] in IMPORTERS:
        print("PLUME_COUNTS " + json.dumps(results[0]["blender"]))
        sys.exit(1 if "error" in results[0]["blender"] else 0)
    json.dump(results, open(args[1], "w"), indent=1)


main()
