#!/usr/bin/env bash
# Scenario tests of `plume simulate` with many feathers (issue 14): a 3-feather scene on a
# turning body writes one merged mesh per frame, each feather's barb-level JSON, the body
# per frame and a summary with the counts; --duration and --frames-every override the
# scene; bad scenes name the JSON path, exit non-zero and write nothing.
# Usage: scene_many.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"

blue=$source_dir/examples/franco-walter/blue.json
# Three blue feathers: two on a sphere that turns about z (one on the top pole, one on the
# bottom pole, upside down), one held by a handle on its own prefixed group far away.
cat >"$scratch/three.json" <<JSON
{
  "body": {"mesh": {"shape": "ellipsoid", "center": [0, 0, 0], "radii": [0.05, 0.05, 0.05], "segments": 16},
           "keyframes": [{"time": 0}, {"time": 0.1, "rotation_axis": [0, 0, 1], "rotation_deg": 30}]},
  "feathers": [
    {"feather": "$blue", "name": "top", "position": [0, 0, 0.05], "follicle": {}},
    {"feather": "$blue", "name": "bottom", "position": [0, 0, -0.05], "rotation_axis": [1, 0, 0], "rotation_deg": 180,
     "follicle": {}},
    {"feather": "$blue", "position": [0.5, 0, 0], "mesh": {"edge_length": 0.012}}
  ],
  "mesh": {"edge_length": 0.01},
  "handles": [{"group": "f2/rachis_clamp"}],
  "gravity": [0, 0, -9.81],
  "cycle_period": 0.2,
  "duration": 1.0,
  "frame_every": 100
}
JSON
out=$scratch/three
"$plume" simulate "$scratch/three.json" -o "$out" --duration 0.055 --frames-every 2 >"$scratch/out.txt" 2>"$scratch/err.txt"
succeeded "simulate a 3-feather scene"
for f in mesh.obj body.obj feathers.json feathers/top.json feathers/top.bin stats.csv \
	summary.json frames/0000.obj frames/0003.obj frames/body-0000.obj frames/body-0003.obj; do
	check "writes $f" test -s "$out/$f"
done
check "no feather.json for a list of feathers" test ! -e "$out/feather.json"
# Three copies of one feather: one dump (tests/cli/render_many.sh has more).
check "one dump for three copies" test "$(ls "$out/feathers")" = "$(printf 'top.bin\ntop.json')"
check "--frames-every 2 over 5 steps: frames 0, 2, 4 and the last" test ! -e "$out/frames/0004.obj"
check "one merged mesh per frame" test "$(grep -c '^v ' "$out/frames/0003.obj")" -eq "$(grep -c '^v ' "$out/mesh.obj")"
check "summary: counts, --duration, cycles" /usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["completed"] and s["steps"] == 5 and s["frames"] == 4, s
assert s["feather_count"] == 3 and s["duration"] == 0.055, s
names = [f["name"] for f in s["feathers"]]
assert names == ["top", "bottom", "f2"], names
assert s["vertex_count"] == sum(f["vertex_count"] for f in s["feathers"]) == s["vertices"], s
assert s["feathers"][1]["vertex_offset"] == s["feathers"][0]["vertex_count"], s
assert s["newton_iterations"] >= 5 and s["wall_seconds"] > 0, s
assert s["vane_max_out_of_plane"] is None and 0.99 < s["vane_min_principal_stretch"] <= 1 + 1e-9, s
# 0.055 s simulated of a 0.2 s cycle: the wall time of a cycle is wall_seconds * 0.2 / 0.055.
assert abs(s["seconds_per_cycle"] - s["wall_seconds"] * 0.2 / 0.055) <= 1e-6 * s["seconds_per_cycle"], s
# No contact: its figures are left out, no made-up numbers. The independent intersection
# check runs on every output frame of a scene with several feathers or a body.
for key in ("contact_pairs_max", "min_distance"):
    assert key not in s, key
assert s["intersecting_pairs"] == 0 and s["frames_checked"] == 4 and s["first_intersecting_step"] is None, s
' "$out/summary.json"
# The top feather's calamus turns with the body: 16.5 degrees at t = 0.055 s (30 degrees in 0.1 s).
check "the body carries the calamus, the body frames turn with it" /usr/bin/python3 -c '
import json, math, sys
def vertices(path):
    return [tuple(map(float, l.split()[1:4])) for l in open(path) if l.startswith("v ")]
rest, last = vertices(sys.argv[1] + "/mesh.obj"), vertices(sys.argv[1] + "/frames/0003.obj")
body_rest, body_last = vertices(sys.argv[1] + "/body.obj"), vertices(sys.argv[1] + "/frames/body-0003.obj")
a = math.radians(30 * 0.055 / 0.1)
turn = lambda p: (math.cos(a) * p[0] - math.sin(a) * p[1], math.sin(a) * p[0] + math.cos(a) * p[1], p[2])
worst = max(max(abs(x - y) for x, y in zip(turn(p), q)) for p, q in zip(body_rest, body_last))
assert worst < 1e-12, worst
top = json.load(open(sys.argv[1] + "/summary.json"))["feathers"][0]["vertex_count"]
clamp = [i for i in range(top) if abs(rest[i][1]) < 1e-12 and abs(rest[i][2] - 0.05) < 1e-12]
assert len(clamp) >= 2, clamp
worst = max(max(abs(x - y) for x, y in zip(turn(rest[i]), last[i])) for i in clamp)
assert worst < 1e-12, worst
' "$out"
check "stdout reports the run" grep -q "5 steps" "$scratch/out.txt"
# On a terminal (script(1)): the feathers meshed, then the steps with the feather count.
script -qec "'$plume' simulate '$scratch/three.json' -o '$scratch/tty' --duration 0.022 >/dev/null" /dev/null >"$scratch/tty.txt"
check "progress of the meshing" grep -aq 'plume simulate: meshing feathers: 3/3 (100%)' "$scratch/tty.txt"
check "progress of the steps" grep -aq 'plume simulate: 2/2 (100%), [0-9]* s elapsed, t = 0.022 s, 3 feathers' "$scratch/tty.txt"

# Determinism: the same frames, byte for byte, with one thread and with two.
OMP_NUM_THREADS=1 "$plume" simulate "$scratch/three.json" -o "$scratch/one" --duration 0.033 --frames-every 1 >/dev/null 2>&1
OMP_NUM_THREADS=2 "$plume" simulate "$scratch/three.json" -o "$scratch/two-threads" --duration 0.033 --frames-every 1 >/dev/null 2>&1
check "1 and 2 threads: the same frames" cmp -s "$scratch/one/frames/0003.obj" "$scratch/two-threads/frames/0003.obj"
check "1 and 2 threads: the same feathers" cmp -s "$scratch/one/feathers/top.bin" "$scratch/two-threads/feathers/top.bin"

# --render draws every feather at barb level and the body.
"$plume" simulate "$scratch/three.json" -o "$scratch/render" --duration 0.011 --render --size 64x64 --spp 1 >/dev/null 2>"$scratch/err.txt"
succeeded "--render with three feathers and a body"
check "ray-traced frames" test -s "$scratch/render/frames/0001-rt.png"

# An entry may be a feather dump (plume generate --format json), beside the spec it came from:
# the same feather, so the same mesh (placed 10 cm apart, as feathers at rest must be).
"$plume" generate "$blue" -o "$scratch/dump" --format json >/dev/null 2>&1
printf '{"feathers": [{"feather": "%s/dump/feather.json"}, {"feather": "%s", "position": [0.1, 0, 0]}], "duration": 0.011}\n' \
	"$scratch" "$blue" >"$scratch/dump.json"
"$plume" simulate "$scratch/dump.json" -o "$scratch/dump-out" >/dev/null 2>"$scratch/err.txt"
succeeded "a feather dump as an entry"
check "the dump meshes as its spec" /usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
a, b = s["feathers"]
assert a["vertex_count"] == b["vertex_count"] and a["face_count"] == b["face_count"], s["feathers"]
' "$scratch/dump-out/summary.json"

# The example runs as it is.
"$plume" simulate "$source_dir/examples/scenes/two-feathers.json" -o "$scratch/two" >/dev/null 2>"$scratch/err.txt"
succeeded "examples/scenes/two-feathers.json runs"
check "two-feathers: 2 feathers" grep -q '"feather_count": 2' "$scratch/two/summary.json"

# Overrides that make no sense: usage errors, nothing written.
expect_no_output "zero duration" 2 "--duration takes a time in seconds > 0, got '0'" "$scratch/none" \
	"$plume" simulate "$scratch/three.json" -o "$scratch/none" --duration 0
expect_no_output "negative duration" 2 "--duration takes a time in seconds > 0, got '-1'" "$scratch/none" \
	"$plume" simulate "$scratch/three.json" -o "$scratch/none" --duration -1
expect_no_output "zero frames-every" 2 "--frames-every takes a whole number in [1, 10000000], got '0'" "$scratch/none" \
	"$plume" simulate "$scratch/three.json" -o "$scratch/none" --frames-every 0
expect_no_output "duration past the step limit" 2 "allowed at most 1e+07" "$scratch/none" \
	"$plume" simulate "$scratch/three.json" -o "$scratch/none" --duration 1e9

# Many copies of a feather are held to --max-memory together (each alone is well under it).
/usr/bin/python3 -c '
import json, sys
feathers = [{"feather": sys.argv[1], "position": [0.1 * i, 0, 0]} for i in range(50)]
json.dump({"feathers": feathers}, open(sys.argv[2], "w"))
' "$source_dir/examples/franco-walter/hawk.json" "$scratch/fifty.json"
expect_no_output "feathers past --max-memory together" 5 'the feathers up to here take about' "$scratch/none" \
	"$plume" simulate "$scratch/fifty.json" -o "$scratch/none" --max-memory 100M

# Bad scenes: the JSON path and what is wrong, exit 3, nothing written.
bad() { # bad NAME FRAGMENT JSON
	printf '%s\n' "$3" >"$scratch/bad.json"
	expect_no_output "$1" 3 "$2" "$scratch/bad-out" "$plume" simulate "$scratch/bad.json" -o "$scratch/bad-out"
}
sphere='"body": {"mesh": {"shape": "ellipsoid", "radii": [0.05, 0.05, 0.05], "segments": 16}, "bones": [{"name": "neck", "head": [0, 0, 0.05]}]}'
bad "duplicate names" '$.feathers[1]: the feather name "wing" is also the name of $.feathers[0]' \
	"{\"feathers\": [{\"feather\": \"$blue\", \"name\": \"wing\"}, {\"feather\": \"$blue\", \"name\": \"wing\"}]}"
bad "follicle off the body" "\$.feathers[0].follicle: feather \"f0\"'s follicle (0, 0, 0.07) is 0.02 m from the body's rest surface; allowed at most 0.001 m" \
	"{$sphere, \"feathers\": [{\"feather\": \"$blue\", \"position\": [0, 0, 0.07], \"follicle\": {}}]}"
bad "unknown bone" '$.feathers[0].follicle.bone: unknown bone "nek"; did you mean "neck"?' \
	"{$sphere, \"feathers\": [{\"feather\": \"$blue\", \"position\": [0, 0, 0.05], \"follicle\": {\"bone\": \"nek\"}}]}"
bad "feather through the body" '$.feathers: feather "f0" passes through the body at rest: its face ' \
	"{$sphere, \"feathers\": [{\"feather\": \"$blue\", \"position\": [0, 0, 0.05], \"rotation_axis\": [1, 0, 0], \"rotation_deg\": -90, \"follicle\": {}}]}"
bad "follicle without a body" '$.feathers[0].follicle: the scene has no "body"' \
	"{\"feathers\": [{\"feather\": \"$blue\", \"follicle\": {}}]}"
bad "unknown feather group" '$.handles[0].group: unknown vertex group "f3/rachis_clamp"' \
	"{\"feathers\": [{\"feather\": \"$blue\"}, {\"feather\": \"$blue\", \"position\": [0.1, 0, 0]}], \"handles\": [{\"group\": \"f3/rachis_clamp\"}]}"
bad "feathers through each other at rest" '$.feathers: feathers "f0" and "f1" intersect at rest: face ' \
	"{\"feathers\": [{\"feather\": \"$blue\"}, {\"feather\": \"$blue\", \"position\": [0, 0.01, 0], \"rotation_axis\": [0, 1, 0], \"rotation_deg\": 90}]}"
bad "feather and feathers" 'a scene needs exactly one of "feather" (a feather spec), "feathers"' \
	"{\"feather\": \"$blue\", \"feathers\": [{\"feather\": \"$blue\"}]}"
bad "bad body mesh" '$.body.mesh.radii' \
	"{\"body\": {\"mesh\": {\"shape\": \"ellipsoid\", \"radii\": [0.05, 0, 0.05]}}, \"feathers\": [{\"feather\": \"$blue\"}]}"

finish
