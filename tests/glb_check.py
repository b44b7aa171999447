#!/usr/bin/env python3
"""Reads plume's .glb files back without plume's code (struct + json only).

  glb_check.py frames SIM.glb FRAMES_DIR   each frame (base + morph target k) equals
                                           FRAMES_DIR/kkkk.obj's vertices to 1e-6 m (and the
                                           node "body" FRAMES_DIR/body-kkkk.obj's, when there are)
  glb_check.py texture FILE.glb IMAGE.png  the embedded image has IMAGE's pixels (decoded by
                                           matplotlib), both curve materials read it through
                                           TEXCOORD_1, and TEXCOORD_1 is Franco & Walter's
                                           image position of TEXCOORD_0 (s, t): u = (1 -/+ s) / 2
                                           on the left/right vane, v = 1 - t
  glb_check.py counts FILE.glb             prints JSON: nodes, meshes, primitives,
                                           vertices (per-primitive, summed), triangles,
                                           lines, morph targets, animation keys, node names
"""
import json
import os
import struct
import sys

COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
FORMATS = {5126: "f", 5125: "I", 5123: "H"}


def load(path):
    data = open(path, "rb").read()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF" or version != 2 or length != len(data):
        sys.exit(f"{path}: not a glTF 2.0 binary (magic {magic!r}, version {version}, length {length})")
    json_length, json_type = struct.unpack_from("<I4s", data, 12)
    if json_type != b"JSON":
        sys.exit(f"{path}: first chunk is {json_type!r}, not JSON")
    doc = json.loads(data[20:20 + json_length])
    at = 20 + json_length
    binary = b""
    if at < len(data):
        bin_length, bin_type = struct.unpack_from("<I4s", data, at)
        if bin_type != b"BIN\0":
            sys.exit(f"{path}: second chunk is {bin_type!r}, not BIN")
        binary = data[at + 8:at + 8 + bin_length]
    return doc, binary


def accessor(doc, binary, index):
    a = doc["accessors"][index]
    n = a["count"] * COMPONENTS[a["type"]]
    c = COMPONENTS[a["type"]]
    if "bufferView" in a:
        view = doc["bufferViews"][a["bufferView"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        values = list(struct.unpack_from("<%d%s" % (n, FORMATS[a["componentType"]]), binary, start))
    else:  # zeros (glTF 2.0 3.6.2.3), the sparse entries below replacing some
        values = [0] * n
    sparse = a.get("sparse")
    if sparse is not None:
        k = sparse["count"]
        iv, vv = doc["bufferViews"][sparse["indices"]["bufferView"]], doc["bufferViews"][sparse["values"]["bufferView"]]
        indices = struct.unpack_from("<%d%s" % (k, FORMATS[sparse["indices"]["componentType"]]), binary,
                                     iv.get("byteOffset", 0) + sparse["indices"].get("byteOffset", 0))
        stored = struct.unpack_from("<%d%s" % (k * c, FORMATS[a["componentType"]]), binary,
                                    vv.get("byteOffset", 0) + sparse["values"].get("byteOffset", 0))
        for i, at in enumerate(indices):
            values[at * c:(at + 1) * c] = stored[i * c:(i + 1) * c]
    return [values[i:i + c] for i in range(0, n, c)] if c > 1 else list(values)


def obj_vertices(path):
    with open(path) as f:
        return [tuple(map(float, line.split()[1:4])) for line in f if line.startswith("v ")]


def node_mesh(doc, name):
    for node in doc.get("nodes", []):
        if node.get("name") == name and "mesh" in node:
            return doc["meshes"][node["mesh"]]
    return None


def check_frames(doc, binary, glb_path, mesh, files, frames_dir):
    """Each file k equals the mesh's base + morph target k; returns the largest difference."""
    primitive = mesh["primitives"][0]
    base = accessor(doc, binary, primitive["attributes"]["POSITION"])
    targets = primitive.get("targets", [])
    if len(targets) != len(files):
        sys.exit(f"{glb_path}: {mesh['name']}: {len(targets)} morph targets, {frames_dir} has {len(files)} frames")
    worst = 0.0
    for i, name in enumerate(files):
        d = accessor(doc, binary, targets[i]["POSITION"])
        want = obj_vertices(os.path.join(frames_dir, name))
        if len(want) != len(base):
            sys.exit(f"{name}: {len(want)} vertices, the .glb's {mesh['name']} has {len(base)}")
        for b, dv, w in zip(base, d, want):
            worst = max(worst, max(abs(b[c] + dv[c] - w[c]) for c in range(3)))
    return worst, len(base)


def frames(glb_path, frames_dir):
    """The shell (mesh 0) against FRAMES_DIR/NNNN.obj, and the node "body", when there is one,
    against FRAMES_DIR/body-NNNN.obj; every animated node is keyed by the one sampler."""
    doc, binary = load(glb_path)
    listing = sorted(os.listdir(frames_dir))
    # By number: simulate writes %04d, so 10000.obj comes after 9999.obj.
    files = sorted((f for f in listing if f.endswith(".obj") and f[:-4].isdigit()), key=lambda f: int(f[:-4]))
    sampler = doc["animations"][0]["samplers"][0]
    times = accessor(doc, binary, sampler["input"])
    weights = accessor(doc, binary, sampler["output"])
    k = len(files)
    if len(times) != k or len(weights) != k * k:
        sys.exit(f"{glb_path}: {len(times)} keys and {len(weights)} weights for {k} frames")
    for i in range(k):
        if any(weights[i * k + j] != (1.0 if i == j else 0.0) for j in range(k)):
            sys.exit(f"{glb_path}: key {i} does not select target {i} alone")
    for channel in doc["animations"][0]["channels"]:
        node = doc["nodes"][channel["target"]["node"]]
        count = len(doc["meshes"][node["mesh"]]["primitives"][0].get("targets", []))
        if channel["sampler"] != 0 or count != k:
            sys.exit(f"{glb_path}: node {node['name']} has {count} morph targets for {k} keys")
    worst, vertices = check_frames(doc, binary, glb_path, doc["meshes"][0], files, frames_dir)
    body = node_mesh(doc, "body")
    bodies = ["body-" + f for f in files if "body-" + f in listing]
    if body is not None or bodies:
        if body is None:
            sys.exit(f"{glb_path}: {frames_dir} has body frames, the .glb no node \"body\"")
        worst_body, body_vertices = check_frames(doc, binary, glb_path, body, bodies, frames_dir)
        worst = max(worst, worst_body)
        print(f"body: {len(bodies)} frames, {body_vertices} vertices")
    print(f"{k} frames, {vertices} vertices, largest difference {worst:.3g} m")
    if worst > 1e-6:
        sys.exit(f"{glb_path}: frames differ from the OBJ frames by {worst:.3g} m > 1e-6 m")


def counts(glb_path):
    doc, binary = load(glb_path)
    result = {"nodes": len(doc.get("nodes", [])), "meshes": len(doc.get("meshes", [])), "primitives": 0,
              "vertices": 0, "triangles": 0, "lines": 0, "morph_targets": 0, "animation_keys": 0,
              "mesh_instances": sum(1 for n in doc.get("nodes", []) if "mesh" in n),
              "node_names": [n.get("name", "") for n in doc.get("nodes", [])]}
    for mesh in doc.get("meshes", []):
        for p in mesh["primitives"]:
            result["primitives"] += 1
            result["vertices"] += doc["accessors"][p["attributes"]["POSITION"]]["count"]
            n = doc["accessors"][p["indices"]]["count"]
            mode = p.get("mode", 4)
            result["triangles" if mode == 4 else "lines"] += n // 3 if mode == 4 else n // 2
            result["morph_targets"] += len(p.get("targets", []))
    for animation in doc.get("animations", []):
        for s in animation["samplers"]:
            result["animation_keys"] = max(result["animation_keys"], doc["accessors"][s["input"]]["count"])
    print(json.dumps(result))


def texture(glb_path, image_path):
    import io
    import matplotlib.image
    import numpy as np
    doc, binary = load(glb_path)
    (image,) = doc["images"]
    view = doc["bufferViews"][image["bufferView"]]
    assert image["mimeType"] == "image/png", image
    start = view.get("byteOffset", 0)
    def rgba(pixels):  # Cairo writes an opaque image as RGB
        return pixels if pixels.shape[2] == 4 else np.dstack([pixels, np.ones(pixels.shape[:2], pixels.dtype)])
    embedded = rgba(matplotlib.image.imread(io.BytesIO(binary[start:start + view["byteLength"]]), format="png"))
    original = rgba(matplotlib.image.imread(image_path))
    assert embedded.shape == original.shape and np.array_equal(embedded, original), "embedded image differs"
    assert doc["textures"] == [{"sampler": 0, "source": 0}], doc["textures"]
    for material in doc["materials"]:
        assert material["pbrMetallicRoughness"]["baseColorTexture"] == {"index": 0, "texCoord": 1}, material
    checked = 0
    for node in doc["nodes"]:
        if "mesh" not in node or node["name"] not in ("shaft", "left_vane", "right_vane"):
            continue
        for primitive in doc["meshes"][node["mesh"]]["primitives"]:
            attributes = primitive["attributes"]
            assert "COLOR_0" not in attributes  # glTF would multiply it into the texture's colour
            st = accessor(doc, binary, attributes["TEXCOORD_0"])
            uv = accessor(doc, binary, attributes["TEXCOORD_1"])
            for (s_, t_), (u, v) in zip(st, uv):
                expected = 0.5 * (1 + s_) if node["name"] == "right_vane" else 0.5 * (1 - s_)
                assert abs(u - expected) < 1e-6 and abs(v - (1 - t_)) < 1e-6, (node["name"], u, v, s_, t_)
                checked += 1
    assert checked > 0
    print(f"{checked} texture coordinates checked")


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "texture":
        texture(sys.argv[2], sys.argv[3])
        sys.exit(0)
    if len(sys.argv) == 4 and sys.argv[1] == "frames":
        frames(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 3 and sys.argv[1] == "counts":
        counts(sys.argv[2])
    else:
        sys.exit(__doc__)
