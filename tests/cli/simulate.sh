#!/usr/bin/env bash
# Scenario tests of `plume simulate`: a short scene writes its mesh, feather,
# frames, stats and summary; bad scenes write nothing and name the key.
# Usage: simulate.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"

# A short swing: the blue feather held at its base, 5 steps, PNG frames.
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
out=$scratch/swing
"$plume" simulate "$scratch/swing.json" -o "$out" --png --size 200x200 >"$scratch/out.txt" 2>"$scratch/err.txt"
succeeded "simulate succeeds"
for f in mesh.obj feather.json feather.bin stats.csv summary.json frames/0000.obj frames/0001.obj frames/0002.obj frames/0003.obj \
	frames/0000.png frames/0003.png; do
	check "writes $f" test -s "$out/$f"
done
check "feather.json is version 2, its numbers in feather.bin" grep -q '"buffer": {"uri": "feather.bin"}' "$out/feather.json"
check "frame 3 is the last (steps 0, 2, 4, 5)" test ! -e "$out/frames/0004.obj"
check "stats has a header and 5 steps" test "$(wc -l <"$out/stats.csv")" -eq 6
check "stats has the energies" grep -q "^time,newton_iterations,gradient_norm,energy,max_barb_strain,wall_seconds,kinetic_energy,elastic_energy,gravitational_energy" "$out/stats.csv"
check "summary says completed" grep -q '"completed": true' "$out/summary.json"
check "summary has steps" grep -q '"steps": 5' "$out/summary.json"
check "summary has max_barb_strain" grep -q '"max_barb_strain"' "$out/summary.json"
check "summary has rachis_tip_deflection" grep -q '"rachis_tip_deflection"' "$out/summary.json"
# The vane's shape and the handle's reaction per step, their extremes in the summary:
# a feather held at its clamp sags under gravity (its vane leaves the plane by a little,
# well under its length) and stretches by next to nothing; the clamp carries its weight (+z).
check "stats has the vane's shape" grep -q "^time,.*,gravitational_energy,contact_energy,friction_potential,vane_min_principal_stretch,vane_max_out_of_plane,substeps,handle0_fx," "$out/stats.csv"
check "vane shape and reactions: plausible, summary gives their extremes" /usr/bin/python3 -c '
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
summary = json.load(open(sys.argv[2]))
stretch = [float(r["vane_min_principal_stretch"]) for r in rows]
lift = [float(r["vane_max_out_of_plane"]) for r in rows]
force = [(float(r["handle0_fx"])**2 + float(r["handle0_fy"])**2 + float(r["handle0_fz"])**2) ** 0.5 for r in rows]
assert all(0.999 < s <= 1.0 + 1e-9 for s in stretch), stretch
assert all(1e-6 < z < 0.01 for z in lift), lift
assert all(float(r["handle0_fz"]) > 0 for r in rows)
close = lambda a, b: abs(a - b) <= 1e-8 * abs(b)  # stats.csv has 9 digits, summary.json 10
assert close(summary["vane_min_principal_stretch"], min(stretch)), summary
assert close(summary["vane_max_out_of_plane"], max(lift)), summary
assert len(summary["handle_max_reaction"]) == 1 and close(summary["handle_max_reaction"][0], max(force)), summary
assert summary["max_kinetic_energy"] > 0 and summary["max_elastic_energy"] > 0 and summary["mesh_min_angle_deg"] > 0
' "$out/stats.csv" "$out/summary.json"
check "stdout reports the run" grep -q "5 steps" "$scratch/out.txt"
check "frames keep the mesh's vertex count" test "$(grep -c '^v ' "$out/frames/0003.obj")" -eq "$(grep -c '^v ' "$out/mesh.obj")"

# --png frames a held feather once for the run: the box took the handles' translations but not
# their turns, so a clamp turned 180 degrees about z took the vane out of the picture (the
# calamus alone: 80 of the 1020 pixels the feather covers at rest).
sed 's/"handles": \[{"group": "rachis_clamp"}\],/"handles": [{"group": "rachis_clamp", "keyframes": [{"time": 0}, {"time": 0.033, "rotation_deg": 180}]}],/; s/"duration": 0.055,/"duration": 0.033, "gravity": [0, 0, 0],/; s/"gravity": \[0, 0, -9.81\],//' \
	"$scratch/swing.json" >"$scratch/turn.json"
"$plume" simulate "$scratch/turn.json" -o "$scratch/turn" --png --size 200x200 --frames-every 1 >/dev/null 2>&1
succeeded "a clamp turned 180 degrees"
check "--png: the turned feather stays in the picture" /usr/bin/python3 -c '
import struct, sys, zlib
def pixels(path):  # 8-bit RGB or RGBA PNG, rows unfiltered
    data = open(path, '"'"'rb'"'"').read()
    at, idat = 8, b'"'"''"'"'
    while at < len(data):
        n, kind = struct.unpack('"'"'>I4s'"'"', data[at:at + 8])
        if kind == b'"'"'IHDR'"'"':
            w, h, depth, colour = struct.unpack('"'"'>IIBB'"'"', data[at + 8:at + 18])
        elif kind == b'"'"'IDAT'"'"':
            idat += data[at + 8:at + 8 + n]
        at += 12 + n
    bpp = {2: 3, 6: 4}[colour]
    raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a, b = line[i - bpp] if i >= bpp else 0, prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line)); prev = line
    return [r[i:i + bpp] for r in rows for i in range(0, stride, bpp)]
def drawn(path):
    p = pixels(path)
    return sum(q != p[0] for q in p)
first, last = drawn(sys.argv[1]), drawn(sys.argv[2])
print(first, last)
assert first > 100 and last > 0.5 * first, (first, last)
' "$scratch/turn/frames/0000.png" "$scratch/turn/frames/0003.png"

# Determinism: the same scene twice gives the same frames.
"$plume" simulate "$scratch/swing.json" -o "$scratch/again" >/dev/null 2>&1
check "same scene, same frames" cmp -s "$out/frames/0003.obj" "$scratch/again/frames/0003.obj"

# A positive duration takes at least one step: under 1e-9 of a step it rounded to none, and
# the run wrote frame 0 alone as a completed simulation of 0 steps.
"$plume" simulate "$scratch/swing.json" -o "$scratch/tiny" --duration 1e-12 >/dev/null 2>&1
succeeded "a duration far below the time step runs"
check "a duration far below the time step takes one step" grep -q '"steps": 1,' "$scratch/tiny/summary.json"
check "its stats have that step" test "$(wc -l <"$scratch/tiny/stats.csv")" -eq 2
# seconds_per_cycle divides the wall time by the cycles simulated, the steps' time (docs/scene.md):
# 0.05 s asked in steps of 0.011 s runs 5 steps, 0.055 s, 5 cycles of 0.011 s. It took the
# duration asked instead (4.5 cycles; with --duration 1e-12 one step counted as 1e-12 s).
sed 's/"duration": 0.055,/"cycle_period": 0.011, "duration": 0.055,/' "$scratch/swing.json" >"$scratch/cycle.json"
"$plume" simulate "$scratch/cycle.json" -o "$scratch/cycle" --duration 0.05 >/dev/null 2>&1
check "seconds_per_cycle: the wall time over the cycles of the steps run" /usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["steps"] == 5 and abs(s["time"] - 0.055) < 1e-12, s
assert abs(s["seconds_per_cycle"] - s["wall_seconds"] / 5) <= 1e-6 * s["seconds_per_cycle"], s
' "$scratch/cycle/summary.json"

# The limits on the frames name the option that set them: --duration, not the scene's $.duration.
expect_no_output "--duration past sim.glb's frames" 5 "swing.json: --duration: 90911 frames make a sim.glb" \
	"$scratch/long" "$plume" simulate "$scratch/swing.json" -o "$scratch/long" --duration 1000 --frames-every 1
check "--duration past sim.glb's frames: says to raise --frames-every" grep -qF "(raise --frames-every or \$.time_step" "$scratch/err.txt"

# A failed step names its start and its end; failed_time (as stats.csv's times) is its end. The
# message said "step at t = 0.033 s" for the step summary.json put at 0.044 s.
cat >"$scratch/jerk.json" <<JSON
{"feather": "$source_dir/examples/franco-walter/blue.json", "mesh": {"edge_length": 0.01},
 "handles": [{"group": "rachis_clamp", "keyframes": [{"time": 0.033}, {"time": 0.044, "translation": [0, 0, 2]}]}],
 "duration": 0.066, "solver": {"max_iterations": 5, "max_substep_halvings": 0}}
JSON
expect_failure "a step that fails" 1 "the step from t = 0.033 s to 0.044 s failed with 1 substeps" \
	"$plume" simulate "$scratch/jerk.json" -o "$scratch/jerk"
check "the failed step: summary.json's failed_time is its end" /usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert not s["completed"] and s["failed_step"] == 4 and abs(s["failed_time"] - 0.044) < 1e-12, s
assert "the step from t = 0.033 s to 0.044 s failed" in s["error"], s
' "$scratch/jerk/summary.json"

# A retried step shows in stats.csv (docs/simulation.md, "Failures"): its substeps column. A
# tip pulled by 0.2 N with at most 6 Newton iterations a solve retries its second step.
sed 's/"duration": 0.055,/"duration": 0.033, "forces": [{"group": "rachis_tip", "force": [0, 0, -0.2]}], "solver": {"max_iterations": 6},/' \
	"$scratch/swing.json" >"$scratch/retry.json"
"$plume" simulate "$scratch/retry.json" -o "$scratch/retry" >/dev/null 2>&1
succeeded "a run with a retried step"
check "stats.csv gives each step's substeps, the retried ones as summary.json counts them" /usr/bin/python3 -c '
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
summary = json.load(open(sys.argv[2]))
substeps = [int(r["substeps"]) for r in rows]
assert summary["retried_steps"] == sum(n > 1 for n in substeps) >= 1, (substeps, summary["retried_steps"])
assert all(n in (1, 2, 4, 8, 16) for n in substeps), substeps
' "$scratch/retry/stats.csv" "$scratch/retry/summary.json"

# Rerunning into the same folder replaces the frames and keeps other files.
echo keep >"$scratch/again/notes.txt"
"$plume" simulate "$scratch/swing.json" -o "$scratch/again" >/dev/null 2>&1
check "rerun keeps the user's files" test -s "$scratch/again/notes.txt"
check "rerun leaves no staging" test -z "$(ls -A "$scratch/again" | grep plume-staging)"

# -o . (and ..): the staging folder went beside "." -- inside the folder itself -- and linking the
# folder's own files into it recursed into it until the path was too long (exit 4).
mkdir -p "$scratch/here/inner"
echo mine >"$scratch/here/notes.txt"
(cd "$scratch/here" && "$plume" simulate "$scratch/swing.json" -o . >/dev/null 2>"$scratch/err.txt")
succeeded "simulate -o ."
check "-o .: the run's files" test -s "$scratch/here/summary.json" -a -s "$scratch/here/frames/0003.obj"
check "-o .: the user's files kept" test -s "$scratch/here/notes.txt"
check "-o .: no staging left" test -z "$(ls -A "$scratch" "$scratch/here" | grep plume-staging)"
(cd "$scratch/here/inner" && "$plume" simulate "$scratch/swing.json" -o .. >/dev/null 2>"$scratch/err.txt")
succeeded "simulate -o .. (again, into the earlier run)"
check "-o ..: the user's files kept" test -s "$scratch/here/notes.txt" -a -d "$scratch/here/inner"

# Bad scenes: clear error, exit 3, nothing written.
bad() { # bad NAME FRAGMENT JSON-MEMBERS
	printf '{"feather": "%s/examples/franco-walter/blue.json", "mesh": {"edge_length": 0.01}, %s}\n' "$source_dir" "$3" >"$scratch/bad.json"
	expect_failure "$1" 3 "$2" "$plume" simulate "$scratch/bad.json" -o "$scratch/bad-out"
	check "$1: nothing written" test ! -e "$scratch/bad-out"
}
bad "unknown group" '$.handles[0].group: unknown vertex group "rachis_bse"' '"handles": [{"group": "rachis_bse"}]'
bad "negative modulus" '$.materials.vane.E_ww is -1, allowed > 0' '"materials": {"vane": {"E_ww": -1}}'
bad "negative thickness" '$.materials.rachis.thickness is -0.001, allowed [1e-09, 1] m' '"materials": {"rachis": {"thickness": -0.001}}'
bad "zero time step" '$.time_step is 0, allowed [1e-09, 100] s' '"time_step": 0'
bad "negative time step" '$.time_step is -1, allowed [1e-09, 100] s' '"time_step": -1'
bad "unknown key" 'did you mean "duration"' '"durations": 1'
bad "unknown integrator" '$.integrator: unknown value "bdf3"' '"integrator": "bdf3"'
bad "negative normal drag" '$.air.normal_drag is -1, allowed >= 0' '"air": {"normal_drag": -1}'
bad "NaN wind" '$.air.wind: element 1 is not a number' '"air": {"wind": [0, "NaN", 0]}'
# An inline feather's errors are at the scene's path of it ($.feather.x), not at the scene's
# top ($.x, which names no key of the scene); a feather file that cannot be read names the key.
printf '{"feather": {"model": "franco-walter", "x": 1}, "duration": 0.011}\n' >"$scratch/inline.json"
expect_no_output "an inline feather's unknown key" 3 'inline.json: $.feather.x: unknown key' \
	"$scratch/inline-out" "$plume" simulate "$scratch/inline.json" -o "$scratch/inline-out"
printf '{"feathers": [{"feather": {"model": "franco-walter", "shaft_samples": -1}}], "duration": 0.011}\n' >"$scratch/inline.json"
expect_no_output "an inline feather's bad value in a list" 3 'inline.json: $.feathers[0].feather.shaft_samples is -1' \
	"$scratch/inline-out" "$plume" simulate "$scratch/inline.json" -o "$scratch/inline-out"
printf '{"feathers": [{"feather": "missing.json"}], "duration": 0.011}\n' >"$scratch/inline.json"
expect_no_output "a missing feather file names the key" 4 'inline.json: $.feathers[0].feather: ' \
	"$scratch/inline-out" "$plume" simulate "$scratch/inline.json" -o "$scratch/inline-out"
# A radius without a point to measure it from selected nothing less: the whole group was held.
bad "radius without near" '$.handles[0].radius: given without "near"' '"handles": [{"group": "left_edge", "radius": 0.004}]'
# The static solve leaves the air out: a quasi-static scene in a wind ran as if in still air.
bad "quasi-static in a wind" '$.air: a quasi-static scene leaves the air out of its static solve' '"quasi_static": true, "air": {"wind": [0, 0, 10]}'
# The mesher's refusal names what it meshed, as a list's entry does ($.feathers[2] (feather "f2"): meshing: ...).
printf '{"feather": "%s/examples/franco-walter/blue.json", "mesh": {"edge_length": 10}}\n' "$source_dir" >"$scratch/coarse.json"
expect_no_output "a mesh the mesher refuses" 3 'coarse.json: $.feather: meshing: no vane to mesh at edge_length 10 m' \
	"$scratch/coarse" "$plume" simulate "$scratch/coarse.json" -o "$scratch/coarse"
# A force entry without its force pulled with nothing (a zero force) and said nothing.
bad "force without force" '$.forces[0].force: missing; a force is [x, y, z] in N' '"forces": [{"group": "rachis_tip"}]'
# A handle that pulls a barb away from the clamp holding its other end (the Streit-Heidrich
# bristle's one barb, its vane tip pulled along it): the barb constraint cannot hold, and the
# run used to end "completed" with the barb stretched 264 %.
cat >"$scratch/stretch.json" <<JSON
{
  "feather": "$source_dir/examples/streit-heidrich/bristle.json",
  "mesh": {"edge_length": 0.005},
  "handles": [{"group": "rachis_clamp"},
              {"group": "vane_tip", "keyframes": [{"time": 0, "translation": [0, 0, 0]},
                                                  {"time": 0.1, "translation": [-0.015, 0, 0]}]}],
  "duration": 0.1
}
JSON
expect_no_output "a handle stretching a barb held at both ends" 3 \
	"the handles hold both ends of the barb edge between vertices 3 and 14 and change its length from 0.00341364 m" \
	"$scratch/stretch" "$plume" simulate "$scratch/stretch.json" -o "$scratch/stretch"
check "the stretched barb: the message says what to change" grep -q "hold one end only, or set the vane's barb_constraint to false" "$scratch/err.txt"
expect_failure "missing scene" 4 "missing.json" "$plume" simulate "$scratch/missing.json" -o "$scratch/none"
# A mesh whose every vane face is a junction face has no vane angle to report: null, as
# mesh's report.json (the Streit-Heidrich filoplume at 5 mm: 5 vane faces, all junctions).
cat >"$scratch/filoplume.json" <<JSON
{"feather": "$source_dir/examples/streit-heidrich/filoplume.json", "mesh": {"edge_length": 0.005},
 "handles": [{"group": "rachis_clamp"}], "duration": 0.011}
JSON
"$plume" simulate "$scratch/filoplume.json" -o "$scratch/filoplume" >/dev/null 2>&1
succeeded "the filoplume runs"
# Picture options without the pictures they set were ignored, and the run ended without any.
expect_no_output "--size without --png or --render" 2 "--size sets the pictures of --png and --render; give one of them" \
	"$scratch/view" "$plume" simulate "$scratch/filoplume.json" -o "$scratch/view" --size 200x200
expect_no_output "--view without --png" 2 "--view sets the camera of --png" \
	"$scratch/view" "$plume" simulate "$scratch/filoplume.json" -o "$scratch/view" --render --view 10,10
expect_no_output "--spp without --render" 2 "--spp sets the samples per pixel of --render; give --render" \
	"$scratch/view" "$plume" simulate "$scratch/filoplume.json" -o "$scratch/view" --png --spp 8
# --view: sscanf takes "nan" and "inf", which made a camera of NaN directions (an empty picture).
expect_no_output "--view nan,0" 2 "--view takes AZIMUTH,ELEVATION in degrees (a finite azimuth, |elevation| <= 90), got 'nan,0'" \
	"$scratch/view" "$plume" simulate "$scratch/filoplume.json" -o "$scratch/view" --view nan,0
expect_no_output "--view 0,nan" 2 "got '0,nan'" "$scratch/view" "$plume" simulate "$scratch/filoplume.json" -o "$scratch/view" --view 0,nan
check "no vane angle outside junction faces: null" /usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["mesh_vane_min_angle_deg"] is None and s["mesh_excepted_count"] == 5, s
' "$scratch/filoplume/summary.json"
check "missing scene: nothing written" test ! -e "$scratch/none"
expect_failure "no output" 2 "missing -o DIR" "$plume" simulate "$scratch/swing.json"
# The progress line on a terminal (script(1)): steps, elapsed time and the simulated time.
script -qec "'$plume' simulate '$scratch/swing.json' -o '$scratch/tty' >/dev/null" /dev/null >"$scratch/tty.txt"
check "progress on a terminal" grep -q 'plume simulate: \([0-9]*\)/\1 (100%), [0-9]* s elapsed, t = ' "$scratch/tty.txt"
"$plume" help simulate | grep -q "frames/NNNN.obj"
check "help describes the outputs" test $? -eq 0

# The feather's dump and the OBJ frames are written by a second thread beside the run
# (cli/writer.c): a write it cannot finish still fails the command with the file named
# where it was asked for (not in the staging folder, removed by then), exit 4, and
# nothing kept. A 4 MiB file-size limit (SIGXFSZ ignored, so the write returns EFBIG)
# lets every file but the 10 MB feather.bin through.
expect_no_output "a write the background writer cannot finish" 4 \
	"plume: $scratch/too-large/feather.bin: write failed: File too large" \
	"$scratch/too-large" bash -c "trap '' XFSZ; ulimit -f 4096; exec '$plume' simulate '$scratch/swing.json' -o '$scratch/too-large'"

finish
