"""Blender data from plume objects: feathers as curves, coats as instances, simulations as shape keys.

Plain functions over bpy and the plume package, used by the operators and by the headless test.
"""

from __future__ import annotations

import json
import os
import tempfile

import bpy
import numpy as np
from mathutils import Matrix, Vector

import plume

MODELS = ("franco-walter", "streit-heidrich", "zhang-kanai")


def preset_folder() -> str:
    """The presets: bundled in the add-on's zip, else the plume source tree's examples/."""
    here = os.path.dirname(os.path.abspath(__file__))
    bundled = os.path.join(here, "presets")
    if os.path.isdir(bundled):
        return bundled
    return os.path.normpath(os.path.join(here, "..", "..", "examples"))


def presets(model: str) -> list[str]:
    folder = os.path.join(preset_folder(), model)
    return sorted(f[:-5] for f in os.listdir(folder) if f.endswith(".json")) if os.path.isdir(folder) else []


def preset_path(model: str, name: str) -> str:
    return os.path.join(preset_folder(), model, name + ".json")


def preset_spec(model: str, name: str) -> dict:
    with open(preset_path(model, name)) as f:
        return json.load(f)


def _curves_of(feather: plume.Feather):
    """(points, widths) of every curve of the feather: shaft, barbs, barbules, then the afterfeather's."""
    yield feather.shaft_points, feather.shaft_widths
    points, widths = feather.points, feather.widths
    for start, count in zip(feather.barb_starts, feather.barb_counts):
        yield points[start : start + count], widths[start : start + count]
    for start, count in zip(feather.barbule_offsets, feather.barbule_counts):
        yield points[start : start + count], widths[start : start + count]
    after = feather.afterfeather
    if after is not None:
        yield from _curves_of(after)


def feather_material() -> bpy.types.Material:
    """One shared material, plume's ray tracer's hawk brown (plume_raytrace_default_def's barb colour)."""
    material = bpy.data.materials.get("plume feather")
    if material is None:
        material = bpy.data.materials.new("plume feather")
        material.diffuse_color = (0.45, 0.33, 0.22, 1.0)
        material.use_nodes = True
        bsdf = material.node_tree.nodes.get("Principled BSDF")
        if bsdf is not None:
            bsdf.inputs["Base Color"].default_value = (0.45, 0.33, 0.22, 1.0)
            bsdf.inputs["Roughness"].default_value = 0.6
    return material


def feather_curve(feather: plume.Feather, name: str) -> bpy.types.Curve:
    """A curve data-block: one poly spline per shaft, barb and barbule, point radius = half the width
    (bevel depth 1, so the tubes are as thick as the feather's curves), metres."""
    curve = bpy.data.curves.new(name, "CURVE")
    curve.dimensions = "3D"
    curve.bevel_depth = 1.0
    curve.bevel_resolution = 0
    curve.use_fill_caps = False
    curve.materials.append(feather_material())
    for points, widths in _curves_of(feather):
        n = len(points)
        if n < 2:
            continue
        spline = curve.splines.new("POLY")
        spline.points.add(n - 1)
        co = np.ones((n, 4))
        co[:, :3] = points
        spline.points.foreach_set("co", co.ravel())
        spline.points.foreach_set("radius", (0.5 * widths).astype(np.float32))
    return curve


def ribbon_material() -> bpy.types.Material:
    """Base colour from the ribbon mesh's "Col" attribute (plume's banded texture), two-sided."""
    material = bpy.data.materials.get("plume ribbon")
    if material is None:
        material = bpy.data.materials.new("plume ribbon")
        material.use_nodes = True
        nodes = material.node_tree.nodes
        bsdf = nodes.get("Principled BSDF")
        attribute = nodes.new("ShaderNodeAttribute")
        attribute.attribute_name = "Col"
        if bsdf is not None:
            material.node_tree.links.new(attribute.outputs["Color"], bsdf.inputs["Base Color"])
        material.use_backface_culling = False
    return material


def feather_ribbons(feather: plume.Feather, name: str) -> bpy.types.Mesh:
    """A mesh data-block: barbs and shaft as flat ribbons (plume.ribbons) with the feather's UVs and
    a per-vertex colour "Col" from plume's banded texture (the shaft in plume's horn colour)."""
    r = plume.ribbons(feather)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(r["vertices"].tolist(), [], r["quads"].tolist())
    loops = np.zeros(len(mesh.loops), dtype=np.int64)
    mesh.loops.foreach_get("vertex_index", loops)
    mesh.uv_layers.new(name="UVMap").data.foreach_set("uv", r["uv"][loops].astype(np.float32).ravel())
    colors = np.empty((len(r["vertices"]), 4))
    barb_vertices = r["side"] < 2
    colors[barb_vertices] = np.repeat(plume.banded_colors(feather), 2, axis=0)
    colors[~barb_vertices] = (0.78, 0.72, 0.62, 1.0)  # plume_raytrace_default_def's shaft colour
    attribute = mesh.color_attributes.new("Col", "FLOAT_COLOR", "POINT")
    attribute.data.foreach_set("color", colors.astype(np.float32).ravel())
    mesh.materials.append(ribbon_material())
    return mesh


def add_feather(context, spec, name: str, seed: int | None = None, stage: float | None = None,
                stage_kind: str = "growth", ribbons: bool = False) -> bpy.types.Object:
    """Generates the spec (a dict, or a file path: specs may name other files relative to
    themselves) and links it to the scene as a curve object (or a ribbon mesh) that remembers
    its spec."""
    feather = plume.generate(spec, seed=seed, stage=stage, stage_kind=stage_kind)
    data = feather_ribbons(feather, name) if ribbons else feather_curve(feather, name)
    obj = bpy.data.objects.new(name, data)
    # A path is kept as a JSON string, a dict as its JSON object text.
    obj["plume_spec"] = json.dumps(spec if isinstance(spec, dict) else os.path.abspath(spec))
    obj["plume_seed"] = -1 if seed is None else seed
    obj["plume_model"] = (spec if isinstance(spec, dict) else json.load(open(spec))).get("model", "")
    obj.location = context.scene.cursor.location
    context.collection.objects.link(obj)
    return obj


# --- coats -------------------------------------------------------------------------------

def _write_world_obj(obj: bpy.types.Object, path: str, depsgraph) -> None:
    """The evaluated mesh, triangulated, in world coordinates, as Wavefront OBJ."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    matrix = obj.matrix_world
    with open(path, "w") as f:
        for v in mesh.vertices:
            p = matrix @ v.co
            f.write(f"v {p.x:.9g} {p.y:.9g} {p.z:.9g}\n")
        # The same mesh must give the same coat, and plume's Poisson layout walks the faces in
        # order; but Blender's polygon order and each polygon's first corner vary from run to run
        # (and loop_triangles come from several threads). So: each polygon rotated to start at
        # its smallest vertex index (winding kept), polygons sorted, a fan per polygon (Blender's
        # faces are convex in practice).
        polygons = []
        for polygon in mesh.polygons:
            v = list(polygon.vertices)
            first = v.index(min(v))
            polygons.append(tuple(v[first:] + v[:first]))
        for v in sorted(polygons):
            for k in range(1, len(v) - 1):
                f.write(f"f {v[0] + 1} {v[k] + 1} {v[k + 1] + 1}\n")
    evaluated.to_mesh_clear()


def _frame(feather: plume.Feather) -> tuple[Matrix, Vector]:
    """Rotation (columns binormal, normal, tangent) and origin of the feather at its base."""
    s = feather.shaft[0]
    b, n, t = (Vector(s[k].tolist()) for k in ("binormal", "normal", "tangent"))
    return Matrix((b, n, t)).transposed(), Vector(s["position"].tolist())


def coat_spec(context, surface: bpy.types.Object, spacing: float, key_names: list[str], seed: int,
              lift_deg: float, folder: str) -> dict:
    """A coat spec for the selected mesh: Poisson follicles, key feathers (streit-heidrich presets) at
    the mesh's extreme vertices along +Z, +X, -X, +Y, ..., feathers flowing down (-Z)."""
    path = os.path.join(folder, "surface.obj")
    _write_world_obj(surface, path, context.evaluated_depsgraph_get())
    world = np.array([surface.matrix_world @ v.co for v in surface.data.vertices])
    directions = [(0, 0, 1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, -1)]
    keys = []
    for i, name in enumerate(key_names[:16]):
        d = np.array(directions[i % len(directions)], dtype=float)
        keys.append({"at": world[np.argmax(world @ d)].tolist(), "feather": preset_path("streit-heidrich", name)})
    return {
        "model": "coat",
        "seed": seed,
        "surface": {"type": "mesh", "obj": path},
        "follicles": {"layout": "poisson", "spacing": spacing},
        "key_feathers": keys,
        "interpolation": "inverse-distance",
        "direction": {"along": [0, 0, -1]},
        "lift_deg": lift_deg,
    }


def groom(context, surface: bpy.types.Object, spacing: float, key_names: list[str], seed: int = 1,
          lift_deg: float = 15.0, instances: bool = True) -> tuple[bpy.types.Collection, plume.Coat]:
    """Grooms a coat on surface. Every coat feather becomes an instance (an object sharing its key
    feather's curve data) placed by the coat feather's base frame and scaled by its shaft length, the
    key feather nearest its follicle giving the shape (plume interpolates shapes; instances keep the
    scene light). With instances False, every coat feather is its own curve object with plume's
    interpolated shape, in world coordinates. Returns the collection and the coat."""
    if not key_names:
        raise ValueError("no key feathers")
    with tempfile.TemporaryDirectory(prefix="plume-groom-") as folder:
        spec = coat_spec(context, surface, spacing, key_names, seed, lift_deg, folder)
        coat = plume.coat(spec)
    coat_keys = spec["key_feathers"]
    collection = bpy.data.collections.new(f"{surface.name} coat")
    context.scene.collection.children.link(collection)
    if not instances:
        for i, placed in enumerate(coat.feathers):
            collection.objects.link(bpy.data.objects.new(f"feather {i:05d}", feather_curve(placed, f"feather {i:05d}")))
        return collection, coat
    local = {}
    for name in dict.fromkeys(key_names[:16]):
        feather = plume.generate(preset_path("streit-heidrich", name))
        local[name] = (feather_curve(feather, f"key {name}"), _frame(feather), feather.info["shaft_length"])
    spec_keys = key_names[:16]
    key_at = np.array([k["at"] for k in coat_keys])
    follicles = coat.follicles
    for i, placed in enumerate(coat.feathers):
        name = spec_keys[int(np.argmin(np.linalg.norm(key_at - follicles[i], axis=1)))]
        curve, (r_local, o_local), length = local[name]
        r_world, o_world = _frame(placed)
        scale = placed.info["shaft_length"] / length
        rotation = (r_world @ r_local.transposed()).to_4x4()
        matrix = Matrix.Translation(o_world) @ rotation @ Matrix.Scale(scale, 4) @ Matrix.Translation(-o_local)
        obj = bpy.data.objects.new(f"feather {i:05d}", curve)
        obj.matrix_world = matrix
        collection.objects.link(obj)
    return collection, coat


# --- simulation --------------------------------------------------------------------------

def handle_keyframes(context, obj: bpy.types.Object, frames: int, dt: float, substeps: int = 1) -> list[dict]:
    """The object's animation as a scene handle's keyframes, in its own frame at the first frame:
    at frame start + f the calamus goes where the animated object takes it (x -> L x, L the motion
    from the first frame's transform to frame f's). Empty when the object is not animated."""
    if obj.animation_data is None or obj.animation_data.action is None:
        return []
    scene = context.scene
    start, current = scene.frame_start, scene.frame_current
    scene.frame_set(start)
    first = np.array(obj.matrix_world, dtype=np.float64)
    keys = []
    for f in range(frames + 1):
        scene.frame_set(start + f)
        motion = np.linalg.solve(first, np.array(obj.matrix_world, dtype=np.float64))
        rotation = motion[:3, :3]
        angle = float(np.arccos(np.clip((np.trace(rotation) - 1) / 2, -1.0, 1.0)))
        axis = np.array([rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0],
                         rotation[1, 0] - rotation[0, 1]])
        if np.linalg.norm(axis) < 1e-12:
            axis, angle = np.array([0.0, 0.0, 1.0]), 0.0
        # The time of the step that ends frame f, computed as plume computes it (n dt), so the
        # pose at each step is a key exactly.
        keys.append({"time": (f * substeps) * dt, "translation": motion[:3, 3].tolist(),
                     "rotation_axis": (axis / np.linalg.norm(axis)).tolist(), "rotation_deg": np.degrees(angle)})
    scene.frame_set(current)
    return keys


def simulate(context, feather_obj: bpy.types.Object, frames: int, edge_length: float,
             substeps: int = 1) -> tuple[bpy.types.Object, plume.Simulation]:
    """Simulates the feather held at its calamus (group rachis_clamp) under gravity (world -Z seen in
    the feather's frame) for `frames` frames at the scene's frame rate, and bakes every frame to a
    shape key of a new mesh object (keyframed so frame f shows shape key f). When the feather object
    is animated, its motion moves the calamus (a keyframed handle; handle_keyframes) and the baked
    object stays where the feather was at the first frame. Shape keys are float32; the final
    positions in double precision are kept in the object's "plume_final_positions"."""
    spec = json.loads(feather_obj["plume_spec"])
    seed = int(feather_obj.get("plume_seed", -1))
    fps = context.scene.render.fps / context.scene.render.fps_base
    dt = 1.0 / fps / substeps
    current = context.scene.frame_current
    keyframes = handle_keyframes(context, feather_obj, frames, dt, substeps)
    if keyframes:
        context.scene.frame_set(context.scene.frame_start)
    # In double precision (mathutils is float32): world -Z seen in the feather's own frame.
    rotation = np.array(feather_obj.matrix_world.to_3x3().normalized(), dtype=np.float64)
    gravity = np.linalg.solve(rotation, np.array([0.0, 0.0, -9.81]))
    scene = {
        "feather": spec,
        "mesh": {"edge_length": edge_length},
        "handles": [{"group": "rachis_clamp", "keyframes": keyframes} if keyframes else {"group": "rachis_clamp"}],
        "gravity": gravity.tolist(),
        "time_step": dt,
        "duration": frames * substeps * dt,
    }
    if seed >= 0:
        scene["seed"] = seed
    sim = plume.Simulation(scene)
    shell = sim.mesh
    mesh = bpy.data.meshes.new(f"{feather_obj.name} shell")
    mesh.from_pydata(shell.vertices.tolist(), [], shell.triangles.tolist())
    uv = mesh.uv_layers.new(name="UVMap")
    loops = shell.uv[np.array([l.vertex_index for l in mesh.loops])]
    uv.data.foreach_set("uv", loops.astype(np.float32).ravel())
    obj = bpy.data.objects.new(f"{feather_obj.name} simulated", mesh)
    obj.matrix_world = feather_obj.matrix_world
    context.collection.objects.link(obj)
    obj.shape_key_add(name="Basis", from_mix=False)
    start = context.scene.frame_start
    for frame in range(1, frames + 1):
        for _ in range(substeps):
            sim.step()
        key = obj.shape_key_add(name=f"frame {frame:04d}", from_mix=False)
        key.data.foreach_set("co", sim.positions.astype(np.float32).ravel())
        for f, value in ((start + frame - 1, 0.0), (start + frame, 1.0), (start + frame + 1, 0.0)):
            key.value = value
            key.keyframe_insert("value", frame=f)
    obj["plume_final_positions"] = sim.positions.ravel().tolist()
    obj["plume_scene"] = json.dumps(scene)
    if keyframes:
        context.scene.frame_set(current)
    obj["plume_frames"] = frames
    return obj, sim
