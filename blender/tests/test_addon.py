"""Headless test of the add-on in Blender:
    blender -b --factory-startup --python blender/tests/test_addon.py -- ADDON.zip [RENDER.png]
(blender/tests/run.sh sets it up). Installs and enables the zip, adds every preset (object, spline
and point counts against the plume package), grooms a coat on a sphere (instance count against the
package's coat), bakes a short simulation (frames, and final positions against the package's own
Simulation of the same scene) and, given RENDER.png, renders the groomed sphere with Cycles."""

import json
import sys
import traceback

import bpy
import numpy as np

args = sys.argv[sys.argv.index("--") + 1 :]
failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what)
    if not condition:
        failures.append(what)


def main():
    bpy.ops.preferences.addon_install(filepath=args[0], overwrite=True)
    bpy.ops.preferences.addon_enable(module="plume_feathers")
    check("plume_feathers" in bpy.context.preferences.addons, "the add-on is enabled")
    import plume  # the add-on put its bundled package on sys.path (or an installed one is used)
    from plume_feathers import build

    print("plume from", plume.__file__, "library", plume.library_path)
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)

    # Every preset of every model: splines = shaft + barbs + barbules (+ afterfeather's), points likewise.
    count = 0
    for model in build.MODELS:
        for preset in build.presets(model):
            before = set(bpy.data.objects)
            result = bpy.ops.plume.add_feather(model=model, preset=preset)
            added = set(bpy.data.objects) - before
            check(result == {"FINISHED"} and len(added) == 1, f"{model}/{preset}: one object added")
            obj = added.pop()
            feather = plume.generate(build.preset_path(model, preset))
            splines = points = 0
            f = feather
            while f is not None:
                splines += 1 + f.barb_count + f.barbule_count
                points += f.info["shaft_sample_count"] + f.info["point_count"]
                f = f.afterfeather
            got_points = sum(len(s.points) for s in obj.data.splines)
            check(len(obj.data.splines) == splines and got_points == points,
                  f"{model}/{preset}: {len(obj.data.splines)} splines, {got_points} points (package {splines}, {points})")
            first = obj.data.splines[1].points[0]
            check(abs(first.radius - feather.widths[feather.barb_starts[0]] / 2) < 1e-9,
                  f"{model}/{preset}: barb radius is half the width")
            bpy.data.objects.remove(obj)
            count += 1
    check(count >= 20, f"{count} presets added")

    # A spec file, and a bad one: the operator reports plume's message (file and JSON path).
    import tempfile as _tempfile

    with _tempfile.TemporaryDirectory() as folder:
        good, bad = f"{folder}/mine.json", f"{folder}/bad.json"
        with open(good, "w") as f:
            json.dump({"model": "franco-walter", "segments": [{"barb_count": 5}, {"barb_count": 7}]}, f)
        with open(bad, "w") as f:
            json.dump({"model": "franco-walter", "segments": [{"barb_count": 6000}, {}]}, f)
        check(bpy.ops.plume.add_feather(filepath=good) == {"FINISHED"}, "spec file: added")
        obj = bpy.data.objects["mine"]
        check(len(obj.data.splines) == 1 + 24, f"spec file: {len(obj.data.splines)} splines (shaft + 2 x 12 barbs)")
        bpy.data.objects.remove(obj)
        try:
            bpy.ops.plume.add_feather(filepath=bad)
            message = ""
        except RuntimeError as e:
            message = str(e)
        check("$.segments[0].barb_count is 6000" in message and "bad.json" in message,
              f"bad spec file: the error names the file and the key ({message.strip()})")

    # Ribbon meshes: two vertices per barb and shaft point, a quad per segment, the feather's UVs.
    for model, preset in (("franco-walter", "figure6a"), ("zhang-kanai", "figure11-expansion")):
        before = set(bpy.data.objects)
        check(bpy.ops.plume.add_feather(model=model, preset=preset, geometry="RIBBONS") == {"FINISHED"},
              f"ribbons {preset}: added")
        obj = (set(bpy.data.objects) - before).pop()
        feather = plume.generate(build.preset_path(model, preset))
        points = int(feather.barb_counts.sum()) + feather.info["shaft_sample_count"]
        quads = points - feather.barb_count - 1
        mesh = obj.data
        check(len(mesh.vertices) == 2 * points and len(mesh.polygons) == quads,
              f"ribbons {preset}: {len(mesh.vertices)} vertices, {len(mesh.polygons)} quads (expected {2 * points}, "
              f"{quads})")
        uv = np.zeros(2 * len(mesh.loops), dtype=np.float32)
        mesh.uv_layers[0].data.foreach_get("uv", uv)
        loops = np.zeros(len(mesh.loops), dtype=np.int64)
        mesh.loops.foreach_get("vertex_index", loops)
        expected_uv = plume.ribbons(feather)["uv"][loops].astype(np.float32)
        check(np.array_equal(uv.reshape(-1, 2), expected_uv), f"ribbons {preset}: UVs are the feather's")
        check("Col" in mesh.color_attributes, f"ribbons {preset}: colour attribute")
        bpy.data.objects.remove(obj)

    # A coat on a sphere.
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.04, segments=24, ring_count=12, location=(0, 0, 0))
    sphere = bpy.context.active_object
    result = bpy.ops.plume.groom_coat(spacing=0.012, key_feathers="contour,semiplume", seed=3)
    check(result == {"FINISHED"}, "groom_coat finished")
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        spec = build.coat_spec(bpy.context, sphere, 0.012, ["contour", "semiplume"], 3, 15.0, folder)
        expected = len(plume.coat(spec))
    collection = bpy.data.collections[f"{sphere.name} coat"]
    instances = list(collection.objects)
    check(len(instances) == expected and expected > 20, f"coat: {len(instances)} instances, package {expected}")
    check(len({o.data.name for o in instances}) == 2, "coat: instances share the two key feathers' curves")
    radii = [o.matrix_world.translation.length for o in instances]
    # Roots on the UV sphere's faces: within its radius, and no deeper than its flattest face's centre.
    check(0.036 < min(radii) and max(radii) < 0.0401,
          f"coat: feathers rooted on the sphere (root distances {min(radii):.4f} to {max(radii):.4f} m)")

    # The same coat, sparser, as interpolated curves: every feather its own shape.
    result = bpy.ops.plume.groom_coat(spacing=0.024, key_feathers="contour,semiplume", seed=3, instances="CURVES")
    check(result == {"FINISHED"}, "groom_coat (curves) finished")
    with tempfile.TemporaryDirectory() as folder:
        coat = plume.coat(build.coat_spec(bpy.context, sphere, 0.024, ["contour", "semiplume"], 3, 15.0, folder))
    curves = sorted(bpy.data.collections[f"{sphere.name} coat.001"].objects, key=lambda o: o.name)
    check(len(curves) == len(coat) and len({o.data.name for o in curves}) == len(coat),
          f"coat curves: {len(curves)} objects with their own curves, package {len(coat)}")
    check(all(len(o.data.splines) == 1 + f.barb_count + f.barbule_count + (
        0 if f.afterfeather is None else 1 + f.afterfeather.barb_count) for o, f in zip(curves, coat.feathers)),
          "coat curves: each object has its feather's shaft and barbs")
    for obj in curves:
        bpy.data.objects.remove(obj)

    if len(args) > 1:
        scene = bpy.context.scene
        bpy.ops.object.camera_add(location=(0.0, -0.32, 0.1))
        camera = bpy.context.active_object
        camera.rotation_euler = (1.27, 0, 0)
        scene.camera = camera
        bpy.ops.object.light_add(type="SUN", location=(0.3, -0.3, 0.5))
        bpy.context.active_object.data.energy = 4.0
        scene.render.engine = "CYCLES"
        scene.cycles.samples = 16
        scene.cycles.device = "CPU"
        scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
        scene.render.resolution_x = scene.render.resolution_y = 400
        scene.render.filepath = args[1]
        world = bpy.data.worlds.new("plume") if scene.world is None else scene.world
        scene.world = world
        world.use_nodes = True
        world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.75, 0.78, 0.82, 1.0)
        skin = bpy.data.materials.new("skin")
        skin.diffuse_color = (0.55, 0.45, 0.40, 1.0)
        sphere.data.materials.append(skin)
        bpy.ops.render.render(write_still=True)
        print("rendered", args[1])

    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)

    # A short simulation baked to shape keys.
    frames = 5
    bpy.ops.plume.add_feather(model="franco-walter", preset="blue")
    feather_obj = bpy.context.scene.objects[-1] if bpy.context.active_object is None else None
    feather_obj = [o for o in bpy.data.objects if "plume_spec" in o][0]
    bpy.context.view_layer.objects.active = feather_obj
    result = bpy.ops.plume.simulate(frames=frames, edge_length=0.01)
    check(result == {"FINISHED"}, "simulate finished")
    baked = [o for o in bpy.data.objects if o.name.endswith("simulated")][0]
    keys = baked.data.shape_keys.key_blocks
    check(len(keys) == frames + 1, f"bake: {len(keys) - 1} frames")
    fcurves = baked.data.shape_keys.animation_data.action.fcurves
    check(len(fcurves) == frames, "bake: every shape key is keyframed")
    spec = json.loads(feather_obj["plume_spec"])
    fps = bpy.context.scene.render.fps / bpy.context.scene.render.fps_base
    with plume.Simulation({"feather": spec, "mesh": {"edge_length": 0.01}, "handles": [{"group": "rachis_clamp"}],
                           "gravity": [0, 0, -9.81], "time_step": 1 / fps, "duration": frames / fps}) as sim:
        sim.run()
        reference = sim.positions.copy()
    final = np.array(baked["plume_final_positions"]).reshape(-1, 3)
    check(final.shape == reference.shape and np.abs(final - reference).max() <= 1e-9,
          f"bake: final positions equal the package's to 1e-9 m (largest difference "
          f"{np.abs(final - reference).max():.3g} m)")
    co = np.zeros(3 * len(keys[-1].data), dtype=np.float32)
    keys[-1].data.foreach_get("co", co)
    check(np.array_equal(co.reshape(-1, 3), reference.astype(np.float32)),
          "bake: the last shape key holds the package's positions rounded to float32 (largest difference "
          f"{np.abs(co.reshape(-1, 3) - reference).max():.3g} m)")
    check(np.abs(co.reshape(-1, 3) - np.array([v.co for v in baked.data.vertices])).max() > 1e-5,
          "bake: the feather moved under gravity")

    # A keyframed handle: the feather object is animated (moved up and turned about its shaft);
    # the calamus follows, the rest of the feather lags behind.
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    bpy.ops.plume.add_feather(model="franco-walter", preset="blue")
    feather_obj = [o for o in bpy.data.objects if "plume_spec" in o][0]
    start = bpy.context.scene.frame_start
    feather_obj.location = (0, 0, 0)
    feather_obj.rotation_euler = (0, 0, 0)
    feather_obj.keyframe_insert("location", frame=start)
    feather_obj.keyframe_insert("rotation_euler", frame=start)
    feather_obj.location = (0, 0, 0.05)
    feather_obj.rotation_euler = (0, 0.6, 0)
    feather_obj.keyframe_insert("location", frame=start + frames)
    feather_obj.keyframe_insert("rotation_euler", frame=start + frames)
    bpy.context.view_layer.objects.active = feather_obj
    check(bpy.ops.plume.simulate(frames=frames, edge_length=0.01) == {"FINISHED"}, "animated: simulate finished")
    baked = [o for o in bpy.data.objects if o.name.endswith("simulated")][0]
    scene_spec = json.loads(baked["plume_scene"])
    check(len(scene_spec["handles"][0]["keyframes"]) == frames + 1, "animated: one handle keyframe per frame")
    with plume.Simulation(scene_spec) as sim:
        sim.run()
        reference = sim.positions.copy()
        rest = sim.mesh.vertices.copy()
        clamp = sim.mesh.groups["rachis_clamp"].copy()
        tip = sim.mesh.groups["rachis_tip"].copy()
    final = np.array(baked["plume_final_positions"]).reshape(-1, 3)
    check(np.abs(final - reference).max() == 0, "animated: final positions equal the package's")
    bpy.context.scene.frame_set(start)
    first = np.array(feather_obj.matrix_world, dtype=np.float64)
    bpy.context.scene.frame_set(start + frames)
    motion = np.linalg.solve(first, np.array(feather_obj.matrix_world, dtype=np.float64))
    held = rest[clamp] @ motion[:3, :3].T + motion[:3, 3]
    check(np.abs(final[clamp] - held).max() < 1e-9,
          f"animated: the calamus follows the object (largest difference {np.abs(final[clamp] - held).max():.2g} m)")
    rigid_tip = rest[tip] @ motion[:3, :3].T + motion[:3, 3]
    lag = np.abs(final[tip] - rigid_tip).max()
    check(lag > 1e-6, f"animated: the tip departs from a rigid motion ({lag:.3g} m: the shell deforms)")


try:
    main()
except Exception:
    traceback.print_exc()
    failures.append("exception")
print(f"{len(failures)} failures" if failures else "all checks passed")
sys.exit(1 if failures else 0)
