#!/usr/bin/env bash
# Scenario tests of contact in scenes (issue 14, docs/contact.md "Contact in scenes"): a
# feather dropped across a held one, and a feather dropped onto a body that carries
# another at its follicle. Without contact the surfaces pass through each other and the
# independent intersection check (exact triangle-triangle tests at every output frame)
# must see it; with contact it must count zero pairs at every frame, with the closest
# distance inside the barrier's reach and the barb strain under 1e-8.
# Usage: contact_scene.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"

blue=$source_dir/examples/franco-walter/blue.json
# The upper feather, tilted 20 degrees about its width, falls 17 mm in 0.06 s across the
# held one 4 mm below it: without contact its base crosses the held vane at t = 0.029 s.
cat >"$scratch/across.json" <<JSON
{
  "feathers": [
    {"feather": "$blue", "name": "below", "position": [0, 0, 0]},
    {"feather": "$blue", "name": "above", "position": [0.004, 0.01, 0.004], "rotation_axis": [1, 0, 0],
     "rotation_deg": 20}
  ],
  "mesh": {"edge_length": 0.01},
  "handles": [{"group": "below/rachis_clamp"}],
  "gravity": [0, 0, -9.81],
  "time_step": 0.005,
  "duration": 0.06,
  "frame_every": 1,
  "contact": {"enabled": CONTACT}
}
JSON
# A sphere carries one feather at its top pole; another, turned edge-on, falls onto its
# side (gravity along +x) from 9 mm away.
cat >"$scratch/body.json" <<JSON
{
  "body": {"mesh": {"shape": "ellipsoid", "center": [0, 0, 0], "radii": [0.05, 0.05, 0.05], "segments": 16}},
  "feathers": [
    {"feather": "$blue", "name": "carried", "position": [0, 0, 0.05], "follicle": {}},
    {"feather": "$blue", "name": "falling", "position": [-0.055, -0.03, -0.02], "rotation_axis": [0, 1, 0],
     "rotation_deg": -90}
  ],
  "mesh": {"edge_length": 0.01},
  "gravity": [9.81, 0, 0],
  "time_step": 0.005,
  "duration": 0.08,
  "contact": {"enabled": CONTACT}
}
JSON
for scene in across body; do
	for contact in false true; do
		sed "s/CONTACT/$contact/" "$scratch/$scene.json" >"$scratch/$scene-$contact.json"
		"$plume" simulate "$scratch/$scene-$contact.json" -o "$scratch/$scene-$contact" >"$scratch/out.txt" \
			2>"$scratch/err.txt"
		succeeded "simulate $scene with contact $contact"
	done
	check "$scene without contact: the check sees the surfaces pass through each other" /usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["completed"] and s["intersecting_pairs"] > 0 and s["first_intersecting_step"] > 0, s
assert "contact_pairs_max" not in s and s["frames_checked"] == s["steps"] + 1, s
' "$scratch/$scene-false/summary.json"
	check "$scene with contact: no intersecting pair at any frame, pairs within reach, barbs exact" /usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["completed"] and s["intersecting_pairs"] == 0 and s["first_intersecting_step"] is None, s
assert s["frames_checked"] == s["steps"] + 1, s
assert s["contact_pairs_max"] > 0 and 0 < s["min_distance"] < 1.2e-4, s
assert s["max_barb_strain"] < 1e-8, s
' "$scratch/$scene-true/summary.json"
	check "$scene: stats.csv has the barrier energy with contact, none without" /usr/bin/python3 -c '
import csv, sys
on = [float(r["contact_energy"]) for r in csv.DictReader(open(sys.argv[1]))]
off = [float(r["contact_energy"]) for r in csv.DictReader(open(sys.argv[2]))]
assert min(on) >= 0 and max(on) > 0 and set(off) == {0.0}, (on, off)
' "$scratch/$scene-true/stats.csv" "$scratch/$scene-false/stats.csv"
done

# The two examples of issue 14, shortened: the flapping bird's first 30 ms (its feathers
# meet from step 4 on, where without contact they pass through each other) and the coat's
# first 20 ms on the body.
"$plume" simulate "$source_dir/examples/scenes/bird-flap.json" -o "$scratch/bird" --duration 0.03 \
	--frames-every 3 >"$scratch/out.txt" 2>"$scratch/err.txt"
succeeded "simulate bird-flap.json for 30 ms"
check "bird-flap: 20 feathers, contact, no intersecting pair" /usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["completed"] and s["feather_count"] == 20 and s["steps"] == 30, s
assert s["intersecting_pairs"] == 0 and s["frames_checked"] == 11 and s["contact_pairs_max"] > 0, s
assert 0 < s["min_distance"] < 1.2e-4 and s["max_barb_strain"] < 1e-8, s
' "$scratch/bird/summary.json"
# Determinism: the same scene on one thread writes the same frames, byte for byte.
OMP_NUM_THREADS=1 "$plume" simulate "$source_dir/examples/scenes/bird-flap.json" -o "$scratch/bird-1" \
	--duration 0.03 --frames-every 3 >"$scratch/out.txt" 2>"$scratch/err.txt"
succeeded "simulate bird-flap.json for 30 ms on one thread"
check "bird-flap: the same frames on 1 thread as on the default threads" \
	diff -r "$scratch/bird/frames" "$scratch/bird-1/frames"
"$plume" simulate "$source_dir/examples/scenes/coat-settle.json" -o "$scratch/coat" --duration 0.02 \
	>"$scratch/out.txt" 2>"$scratch/err.txt"
succeeded "simulate coat-settle.json for 20 ms"
check "coat-settle: 64 feathers on the body, no intersecting pair" /usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["completed"] and s["feather_count"] == 64 and s["intersecting_pairs"] == 0, s
assert s["max_barb_strain"] < 1e-8, s
' "$scratch/coat/summary.json"

# The contact object's bad values name the key and the range, and nothing is written.
sed 's/"enabled": CONTACT/"distance": -1/' "$scratch/across.json" >"$scratch/bad.json"
expect_no_output "a negative contact distance" 3 '$.contact.distance is -1, allowed' "$scratch/bad-out" \
	"$plume" simulate "$scratch/bad.json" -o "$scratch/bad-out"
sed 's/"enabled": CONTACT/"stiffnes": 1/' "$scratch/across.json" >"$scratch/bad.json"
expect_no_output "an unknown contact key" 3 'stiffnes' "$scratch/bad-out" \
	"$plume" simulate "$scratch/bad.json" -o "$scratch/bad-out"

finish
