#!/usr/bin/env bash
# Scenario tests of the glTF outputs: `generate/mesh/coat --format glb` and
# `simulate`'s sim.glb, read back by tests/glb_check.py (struct + json, not
# plume's code): the animation's frames equal the OBJ frames to 1e-6 m, the
# coat has one instance per feather, counts match the feather's.
# Usage: gltf.sh PLUME_BINARY SOURCE_DIR
# (Each status is saved before `check`: a $(...) in the check's name would reset $?.)
source "$(dirname "$0")/../cli_support.sh" "$@"
py=/usr/bin/python3
checker="$source_dir/tests/glb_check.py"
field() { # field FILE.glb KEY: one count from glb_check.py counts
	"$py" "$checker" counts "$1" | "$py" -c "import json,sys; print(json.load(sys.stdin)['$2'])"
}

# A feather: feather.glb beside the OBJ; ribbons have two vertices per curve point.
"$plume" generate "$source_dir/examples/franco-walter/blue.json" -o "$scratch/blue" --format glb,obj >/dev/null 2>"$scratch/err.txt"
status=$?
check "generate --format glb: exit 0 ($(cat "$scratch/err.txt"))" test "$status" -eq 0
check "generate writes feather.glb" test -s "$scratch/blue/feather.glb"
check "generate writes only what was asked" test ! -e "$scratch/blue/feather.png"
obj_points=$(grep -c '^v ' "$scratch/blue/feather.obj")
check "ribbons: 2 vertices per OBJ vertex ($obj_points)" test "$(field "$scratch/blue/feather.glb" vertices)" -eq $((2 * obj_points))
expect_failure "unknown format" 2 "allowed: png, svg, pdf, obj, usda, json, glb" \
	"$plume" generate "$source_dir/examples/franco-walter/blue.json" -o "$scratch/bad" --format gltf
check "unknown format: nothing written" test ! -e "$scratch/bad"

# --texture: the image embedded in feather.glb, read through TEXCOORD_1 at Franco & Walter's positions.
"$plume" generate "$source_dir/examples/franco-walter/blue.json" -o "$scratch/textured" --format glb --texture "$source_dir/examples/textures/bands.png" >/dev/null 2>"$scratch/err.txt"
status=$?
check "generate --texture --format glb: exit 0 ($(cat "$scratch/err.txt"))" test "$status" -eq 0
"$py" "$checker" texture "$scratch/textured/feather.glb" "$source_dir/examples/textures/bands.png" >"$scratch/out.txt" 2>&1
status=$?
check "textured feather.glb: image, materials and coordinates ($(tail -1 "$scratch/out.txt"))" test "$status" -eq 0
check "textured feather.glb: the same geometry" test "$(field "$scratch/textured/feather.glb" vertices)" -eq "$(field "$scratch/blue/feather.glb" vertices)"

# A shell.
"$plume" mesh "$source_dir/examples/franco-walter/blue.json" -o "$scratch/mesh" --format glb -e 0.01 >/dev/null 2>"$scratch/err.txt"
status=$?
check "mesh --format glb: exit 0 ($(cat "$scratch/err.txt"))" test "$status" -eq 0
check "mesh writes mesh.glb and not mesh.obj" test -s "$scratch/mesh/mesh.glb" -a ! -e "$scratch/mesh/mesh.obj"
faces=$("$py" -c "import json; print(json.load(open('$scratch/mesh/report.json'))['face_count'])")
check "mesh.glb has the report's $faces faces" test "$(field "$scratch/mesh/mesh.glb" triangles)" -eq "$faces"
expect_failure "mesh --format json" 2 "a mesh writes obj, png, glb" \
	"$plume" mesh "$source_dir/examples/franco-walter/blue.json" -o "$scratch/bad" --format json

# A coat: one node instance per feather, plus the surface.
"$plume" coat "$source_dir/examples/coats/figure15-hexagonal.json" -o "$scratch/coat" --format glb >"$scratch/out.txt" 2>"$scratch/err.txt"
status=$?
check "coat --format glb: exit 0 ($(cat "$scratch/err.txt"))" test "$status" -eq 0
feathers=$(grep -c '^o ' <("$plume" coat "$source_dir/examples/coats/figure15-hexagonal.json" -o "$scratch/coat-obj" --format obj >/dev/null 2>&1; cat "$scratch/coat-obj/coat.obj"))
check "coat says its instances" grep -q "coat.glb: $feathers feather instances" "$scratch/out.txt"
check "coat.glb: $feathers feathers + the surface" test "$(field "$scratch/coat/coat.glb" mesh_instances)" -eq $((feathers + 1))

# A simulation: one animated file whose frames are the OBJ frames.
cat >"$scratch/swing.json" <<JSON
{
  "feather": "$source_dir/examples/franco-walter/blue.json",
  "mesh": {"edge_length": 0.01},
  "handles": [{"group": "rachis_clamp"}],
  "gravity": [0, 0, -9.81],
  "duration": 0.055,
  "frame_every": 2
}
JSON
"$plume" simulate "$scratch/swing.json" -o "$scratch/swing" >/dev/null 2>"$scratch/err.txt"
status=$?
check "simulate: exit 0 ($(cat "$scratch/err.txt"))" test "$status" -eq 0
check "simulate writes sim.glb" test -s "$scratch/swing/sim.glb"
check "sim.usda has 4 time samples of the points" test "$(sed -n '/points.timeSamples/,/^    }/p' "$scratch/swing/sim.usda" | grep -c ': \[')" -eq 4
"$py" "$checker" frames "$scratch/swing/sim.glb" "$scratch/swing/frames" >"$scratch/out.txt" 2>&1
status=$?
check "sim.glb frames = OBJ frames to 1e-6 m ($(cat "$scratch/out.txt"))" test "$status" -eq 0
check "sim.glb: 4 animation keys" test "$(field "$scratch/swing/sim.glb" animation_keys)" -eq 4

# sim.glb's weights are stored sparsely: the file grows with the frames, not their square
# (4 keys of 4 weights each here; glb_check.py above expands them and finds key k on target k).
check "sim.glb: sparse weights" "$py" -c "
import json, struct, sys
d = open('$scratch/swing/sim.glb', 'rb').read()
doc = json.loads(d[20:20 + struct.unpack_from('<I', d, 12)[0]])
a = doc['accessors'][doc['animations'][0]['samplers'][0]['output']]
sys.exit(0 if 'bufferView' not in a and a['count'] == 16 and a['sparse']['count'] == 4 else 1)"

# A body: sim.usda holds it as prim "body" beside the shell, sampled at the same frames, as
# sim.glb has node "body" (whose frames glb_check.py compares with frames/body-NNNN.obj).
cat >"$scratch/body.json" <<JSON
{"body": {"mesh": {"shape": "ellipsoid", "center": [0, 0, 0], "radii": [0.05, 0.05, 0.05], "segments": 8},
          "keyframes": [{"time": 0}, {"time": 0.1, "rotation_axis": [0, 0, 1], "rotation_deg": 30}]},
 "feathers": [{"feather": "$source_dir/examples/franco-walter/blue.json", "position": [0, 0, 0.05], "follicle": {}}],
 "mesh": {"edge_length": 0.015}, "duration": 0.033}
JSON
"$plume" simulate "$scratch/body.json" -o "$scratch/body" >/dev/null 2>"$scratch/err.txt"
status=$?
check "simulate a body: exit 0 ($(cat "$scratch/err.txt"))" test "$status" -eq 0
"$py" "$checker" frames "$scratch/body/sim.glb" "$scratch/body/frames" >"$scratch/out.txt" 2>&1
status=$?
check "body: sim.glb frames = OBJ frames ($(cat "$scratch/out.txt"))" test "$status" -eq 0
"$py" - "$scratch/body" >"$scratch/out.txt" 2>&1 <<'PY'
import glob, re, sys
folder = sys.argv[1]
text = open(folder + "/sim.usda").read()
prims = re.findall(r'^def Mesh "(\w+)"', text, re.M)
assert prims == ["shell", "body"], prims
body = text[text.index('def Mesh "body"'):]
samples = re.search(r"point3f\[\] points.timeSamples = \{\n(.*?)\n    \}", body, re.S).group(1).split("\n")
frames = sorted(glob.glob(folder + "/frames/body-*.obj"))
assert len(samples) == len(frames), (len(samples), len(frames))
for sample, name in zip(samples, frames):
    points = [tuple(map(float, p.split(","))) for p in re.findall(r"\(([^()]*)\)", sample.split(": ", 1)[1])]
    vertices = [tuple(map(float, l.split()[1:4])) for l in open(name) if l.startswith("v ")]
    assert len(points) == len(vertices), (name, len(points), len(vertices))
    assert max(abs(a - b) for p, v in zip(points, vertices) for a, b in zip(p, v)) < 1e-6, name
print("ok")
PY
status=$?
check "body: sim.usda prim \"body\" = frames/body-NNNN.obj ($(cat "$scratch/out.txt"))" test "$status" -eq 0

# --glb-feather's memory is in the estimate: the blue feather's 11 frames make a 23 MB
# sim.glb that takes about twice that to write, far past 20M, while the OBJ frames are small.
expect_no_output "--glb-feather past --max-memory" 5 "sim.glb with the carried feathers (--glb-feather) would hold" \
	"$scratch/glbmem" "$plume" simulate "$scratch/swing.json" -o "$scratch/glbmem" --glb-feather --max-memory 20M
"$plume" simulate "$scratch/swing.json" -o "$scratch/glbmem" --max-memory 20M >/dev/null 2>"$scratch/err.txt"
succeeded "without --glb-feather the same limit passes"
# More frames than a GLB's sparse weights can index (65536): refused before the run.
expect_no_output "sim.glb frame limit" 5 "65536 frames" "$scratch/long" \
	"$plume" simulate "$scratch/swing.json" -o "$scratch/long" --duration 720.9 --frames-every 1 --max-memory 1T

# --fields: a .vtu per frame listed by fields.pvd; the handle's vertices are still.
"$plume" simulate "$scratch/swing.json" -o "$scratch/fields" --fields >/dev/null 2>"$scratch/err.txt"
status=$?
check "simulate --fields: exit 0 ($(cat "$scratch/err.txt"))" test "$status" -eq 0
"$py" - "$scratch/fields" >"$scratch/out.txt" 2>&1 <<'PY'
import sys, xml.etree.ElementTree as ET
folder = sys.argv[1]
sets = ET.parse(folder + "/fields.pvd").getroot().find("Collection").findall("DataSet")
assert len(sets) == 4, len(sets)
faces = sum(1 for line in open(folder + "/mesh.obj") if line.startswith("f "))
for d in sets:
    piece = ET.parse(folder + "/" + d.get("file")).getroot().find("UnstructuredGrid/Piece")
    assert int(piece.get("NumberOfCells")) == faces, (piece.get("NumberOfCells"), faces)
    arrays = {a.get("Name"): a.text.split() for a in piece.iter("DataArray")}
    for name in ("green_strain_barb", "pk2_stress_barb"):
        assert len(arrays[name]) == 3 * faces, name
    handle = [int(h) for h in arrays["handle"]]
    velocity = [float(v) for v in arrays["velocity"]]
    held = [i for i, h in enumerate(handle) if h == 0]
    assert held, "no vertex in handle 0"
    assert all(velocity[3 * i + c] == 0.0 for i in held for c in range(3)), "a held vertex moves"
print("ok")
PY
status=$?
check "fields.pvd and .vtu read back ($(cat "$scratch/out.txt"))" test "$status" -eq 0
check "stats.csv has the handle's reaction and displacement" grep -q "handle0_fx,handle0_fy,handle0_fz,handle0_dx,handle0_dy,handle0_dz" "$scratch/fields/stats.csv"
finish
