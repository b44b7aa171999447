#!/usr/bin/env bash
# Scenario tests of the outputs of many-feather runs (issue 14): `plume simulate` writes one dump
# per distinct feather and feathers.json; `plume render` of the run folder draws every feather at
# barb level and the body of each frame; --glb-feather puts every feather (and the body) in
# sim.glb; a folder with a missing dump or body frame is refused, naming the file.
# Usage: render_many.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"

blue=$source_dir/examples/franco-walter/blue.json
differs() { ! cmp -s "$1" "$2"; }
# Another feather: the same spec with another seed.
/usr/bin/python3 -c '
import json, sys
spec = json.load(open(sys.argv[1]))
spec["seed"] = 5
json.dump(spec, open(sys.argv[2], "w"))
' "$blue" "$scratch/blue5.json"
# Three feathers far apart along x: two copies of one spec ("top" on a sphere that turns, "mid"
# free) and another feather ("far"), without gravity so that they stay apart.
cat >"$scratch/three.json" <<JSON
{
  "body": {"mesh": {"shape": "ellipsoid", "center": [0, 0, 0], "radii": [0.05, 0.05, 0.05], "segments": 12},
           "keyframes": [{"time": 0}, {"time": 0.1, "rotation_axis": [0, 0, 1], "rotation_deg": 30}]},
  "feathers": [
    {"feather": "$blue", "name": "top", "position": [0, 0, 0.05], "follicle": {}},
    {"feather": "$blue", "name": "mid", "position": [0.4, 0, 0]},
    {"feather": "$scratch/blue5.json", "name": "far", "position": [0.8, 0, 0]}
  ],
  "mesh": {"edge_length": 0.015},
  "gravity": [0, 0, 0],
  "duration": 0.022
}
JSON
run=$scratch/run
"$plume" simulate "$scratch/three.json" -o "$run" --glb-feather >/dev/null 2>"$scratch/err.txt"
succeeded "simulate three feathers, two of one spec, with --glb-feather"
check "one dump per distinct feather" test "$(cd "$run/feathers" && ls)" = "$(printf 'far.bin\nfar.json\ntop.bin\ntop.json')"
check "feathers.json: every feather, its dump and placement" /usr/bin/python3 -c '
import json, sys
index = json.load(open(sys.argv[1] + "/feathers.json"))
summary = json.load(open(sys.argv[1] + "/summary.json"))
entries = index["feathers"]
assert [e["name"] for e in entries] == ["top", "mid", "far"], entries
assert [e["dump"] for e in entries] == ["top.json", "top.json", "far.json"], entries
assert entries[1]["translation"] == [0.4, 0, 0] and entries[1]["rotation"] == [1, 0, 0, 0, 1, 0, 0, 0, 1], entries[1]
for e, s in zip(entries, summary["feathers"]):
    assert all(e[k] == s[k] for k in ("vertex_offset", "vertex_count", "face_offset", "face_count")), (e, s)
# The dumps are version 2: JSON structure, numbers in the binary sidecar.
assert json.load(open(sys.argv[1] + "/feathers/top.json"))["version"] == 2
' "$run"

# The glb: the shell, a feather_NAME node per feather, the body, every frame as the OBJ frames.
check "sim.glb: the frames of the shell and the body" /usr/bin/python3 "$source_dir/tests/glb_check.py" frames \
	"$run/sim.glb" "$run/frames"
check "sim.glb: three feathers and the body" /usr/bin/python3 -c '
import json, subprocess, sys
counts = json.loads(subprocess.check_output([sys.executable, sys.argv[1], "counts", sys.argv[2]]))
assert counts["node_names"] == ["shell", "feather_top", "feather_mid", "feather_far", "body"], counts
assert counts["lines"] > 10000 and counts["animation_keys"] == 3, counts
' "$source_dir/tests/glb_check.py" "$run/sim.glb"

# plume render of the run folder: every feather at barb level, side by side from the front.
"$plume" render "$run" -o "$scratch/picture" --size 240x120 --spp 1 >/dev/null 2>"$scratch/err.txt"
succeeded "render a many-feather run folder"
for f in 0000.png 0002.png 0002-top.obj 0002-mid.usda 0002-far.obj; do
	check "render writes frames/$f" test -s "$scratch/picture/frames/$f"
done
# Columns holding anything but the background, in runs: one run per feather (the body sits with "top").
check "every feather drawn: three groups of columns" /usr/bin/python3 -c '
import sys
import matplotlib.image
image = matplotlib.image.imread(sys.argv[1])
background = image[0, 0, :3]
drawn = (abs(image[:, :, :3] - background).sum(axis=2) > 0.05).any(axis=0)
groups, inside = 0, False
for column in drawn:
    groups += bool(column) and not inside
    inside = bool(column)
assert groups == 3, (groups, "".join("#" if c else "." for c in drawn))
' "$scratch/picture/frames/0002.png"
# The body is drawn: the same folder without it gives another picture.
cp -r "$run" "$scratch/nobody"
rm "$scratch/nobody/body.obj" "$scratch/nobody"/frames/body-*.obj
"$plume" render "$scratch/nobody" -o "$scratch/nobody-picture" --size 240x120 --spp 1 -f png --frames 2:2 >/dev/null 2>&1
check "the body is drawn" differs "$scratch/picture/frames/0002.png" "$scratch/nobody-picture/frames/0002.png"
# --frames renders a range of a many-feather run as well.
"$plume" render "$run" -o "$scratch/range" --size 240x120 --spp 1 -f png --frames 1:1 >/dev/null 2>&1
check "--frames 1:1: frame 1 alone" test "$(ls "$scratch/range/frames")" = "0001.png"

# A folder with a dump or a body frame missing: the file named, exit 4, nothing written.
cp -r "$run" "$scratch/nodump"
rm "$scratch/nodump/feathers/top.json"
expect_no_output "missing dump" 4 "feathers/top.json: missing; feather \"top\" of" "$scratch/o1" \
	"$plume" render "$scratch/nodump" -o "$scratch/o1" --size 48x24 --spp 1
cp -r "$run" "$scratch/nobodyframe"
rm "$scratch/nobodyframe/frames/body-0001.obj"
expect_no_output "missing body frame" 4 "frames/body-0001.obj: missing" "$scratch/o2" \
	"$plume" render "$scratch/nobodyframe" -o "$scratch/o2" --size 48x24 --spp 1

finish
