#!/usr/bin/env bash
# Regression tests of issue 17 (hardening): each input that crashed, hung,
# grew without bound or gave a silently wrong result now fails with a message
# naming the file and the JSON path, a documented exit code, nothing written
# and no staging folder left. Every command runs under `timeout` so that a
# hang is a failure, not a stuck suite.
# Usage: hardening.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"
examples=$source_dir/examples
bad=$scratch/bad
mkdir -p "$bad"
T="timeout 60"

# edit IN OUT PYTHON: OUT is IN (JSON) with the Python statement applied to d.
edit() {
	/usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1])); $3; json.dump(d, open(sys.argv[2], 'w'))" "$1" "$2"
}

# --- Franco-Walter shaft point [1e308, 1e308]: hung in the arc-length recursion -------
edit "$examples/franco-walter/hawk.json" "$bad/fw-shaft.json" "d['shaft'][3] = [1e308, 1e308]"
expect_no_output "FW shaft 1e308" 3 'fw-shaft.json: $.shaft[3][0]: 1e+308 is outside the range' "$scratch/o1" \
	$T "$plume" generate "$bad/fw-shaft.json" -o "$scratch/o1"

# --- rachis (shaft) width 1e308: wrote inf into feather.usda -------------------------------
edit "$examples/franco-walter/hawk.json" "$bad/fw-width.json" "d['shaft_width_base'] = 1e308"
expect_no_output "FW shaft width 1e308" 3 'fw-width.json: $.shaft_width_base: 1e+308' "$scratch/o2" \
	$T "$plume" generate "$bad/fw-width.json" -o "$scratch/o2" --format usda
edit "$examples/scenes/falling.json" "$bad/scene-width.json" \
	"d['feather'] = '$examples/franco-walter/hawk.json'; d['mesh']['rachis_width_base'] = 1e308"
expect_no_output "scene rachis width 1e308" 3 'scene-width.json: $.mesh.rachis_width_base: 1e+308' "$scratch/o3" \
	$T "$plume" simulate "$bad/scene-width.json" -o "$scratch/o3"

# --- Zhang-Kanai ridge_width 1e308: 0 barbs and exit 0 -----------------------------------
edit "$examples/zhang-kanai/figure8-contour.json" "$bad/zk-huge.json" "d['ridge_width'] = 1e308"
expect_no_output "ZK ridge_width 1e308" 3 'zk-huge.json: $.ridge_width: 1e+308' "$scratch/o4" \
	$T "$plume" generate "$bad/zk-huge.json" -o "$scratch/o4"
edit "$examples/zhang-kanai/figure8-contour.json" "$bad/zk-wide.json" "d['ridge_width'] = 0.5"
expect_no_output "ZK ridge_width past the collar" 3 \
	"zk-wide.json: \$.ridge_width is 0.5 m, longer than the left emitter's path" "$scratch/o5" \
	$T "$plume" generate "$bad/zk-wide.json" -o "$scratch/o5"

# --- coats without bound: spacing 1e-6 m, a sphere of radius 1000 m ----------------------------
cp "$examples"/coats/key-*.json "$bad/"
edit "$examples/coats/sphere.json" "$bad/coat-fine.json" "d['follicles']['spacing'] = 1e-6"
expect_no_output "coat spacing 1e-6" 5 '$.follicles.spacing: 1e-06 m on' "$scratch/o6" \
	$T "$plume" coat "$bad/coat-fine.json" -o "$scratch/o6"
check "coat limit names --max-memory" grep -qF 'raise it with --max-memory' "$scratch/err.txt"
edit "$examples/coats/sphere.json" "$bad/coat-big.json" "d['surface']['radius'] = 1000"
expect_no_output "coat sphere radius 1000 m" 5 'about 1.92e+11 follicles' "$scratch/o7" \
	$T "$plume" coat "$bad/coat-big.json" -o "$scratch/o7"
expect_no_output "coat --max-memory 2T is still too little" 5 'the limit is 2.2e+03 GB' "$scratch/o8" \
	$T "$plume" coat "$bad/coat-big.json" -o "$scratch/o8" --max-memory 2T
expect_no_output "coat --max-memory garbage" 2 "--max-memory 'lots'" "$scratch/o9" \
	$T "$plume" coat "$examples/coats/sphere.json" -o "$scratch/o9" --max-memory lots
# The limit is real: the example sphere (about 400 follicles) fits in 1G, not in 1M.
expect_no_output "coat --max-memory 1M refuses the example" 5 'the limit is 0.00105 GB' "$scratch/o10" \
	$T "$plume" coat "$examples/coats/sphere.json" -o "$scratch/o10" --max-memory 1M
$T "$plume" coat "$examples/coats/sphere.json" -o "$scratch/sphere" --max-memory 1G --format obj 2>"$scratch/err.txt"
check "coat --max-memory 1G builds the example ($(cat "$scratch/err.txt"))" test -s "$scratch/sphere/coat.obj"

# --- a coat on an OBJ with a nan vertex: looped forever choosing follicles -----------------------
printf 'v 0 0 0\nv 0.1 0 0\nv nan 0.1 0\nv 0 0.1 0\nf 1 2 3\nf 1 3 4\n' >"$bad/nan.obj"
printf '{"model": "coat", "surface": {"type": "mesh", "obj": "nan.obj"}, "follicles": {"layout": "poisson", "spacing": 0.01}, "key_feathers": [{"at": [0, 0, 0], "feather": "key-plume.json"}]}' >"$bad/coat-nan.json"
expect_no_output "coat on a nan vertex" 3 'nan.obj:3: vertex 3: coordinate 1 is nan; allowed finite' "$scratch/o11" \
	$T "$plume" coat "$bad/coat-nan.json" -o "$scratch/o11"
printf 'v 0 0 0\nv 0.1 0 0\nv 1e300 0.1 0\nf 1 2 3\n' >"$bad/huge.obj"
sed 's/nan.obj/huge.obj/' "$bad/coat-nan.json" >"$bad/coat-huge.json"
expect_no_output "coat on a 1e300 vertex" 3 'huge.obj:3: vertex 3: coordinate 1 is 1e+300; allowed finite, within 1e12 m' \
	"$scratch/o12" $T "$plume" coat "$bad/coat-huge.json" -o "$scratch/o12"

# --- time_step 1e-9 over duration 1e9: overflowed the step count, exit 0 with 0 steps -----------
edit "$examples/scenes/falling.json" "$bad/scene-steps.json" \
	"d['feather'] = '$examples/franco-walter/hawk.json'; d['time_step'] = 1e-9; d['duration'] = 1e9"
expect_no_output "step count overflow" 3 'scene-steps.json: $.duration: 1e+09 s in steps of 1e-09 s' "$scratch/o13" \
	$T "$plume" simulate "$bad/scene-steps.json" -o "$scratch/o13"

# --- the first simulation step fails: frame 0 and a summary that says where and why --------
edit "$examples/scenes/falling.json" "$bad/scene-fail.json" \
	"d['feather'] = '$examples/franco-walter/hawk.json'; d['mesh']['edge_length'] = 0.02; d['duration'] = 0.05; d['solver'] = {'max_iterations': 1, 'max_substep_halvings': 0}"
expect_failure "first step fails" 1 'Newton did not converge in 1 iterations (the forces do not balance: largest force residual' \
	$T "$plume" simulate "$bad/scene-fail.json" -o "$scratch/fail"
check "first step fails: frame 0 kept" test -s "$scratch/fail/frames/0000.obj"
check "first step fails: only frame 0" test "$(ls "$scratch/fail/frames" | wc -l)" -eq 1
check "first step fails: summary says not completed" grep -q '"completed": false' "$scratch/fail/summary.json"
check "first step fails: summary names the step" grep -q '"failed_step": 1,' "$scratch/fail/summary.json"
check "first step fails: summary has the reason" grep -q '"error": "simulation: the step from t = 0 s to' "$scratch/fail/summary.json"
check "first step fails: no staging left" test -z "$(ls -A "$scratch" | grep plume-staging)"

# --- render of a simulation folder whose feather.json holds 1e308: segfaulted -------------
sim=$scratch/sim
edit "$examples/scenes/falling.json" "$bad/scene-short.json" \
	"d['feather'] = '$examples/franco-walter/filoplume.json'; d['mesh']['edge_length'] = 0.02; d['duration'] = 0.011"
$T "$plume" simulate "$bad/scene-short.json" -o "$sim" >/dev/null 2>"$scratch/err.txt"
check "short simulation for render ($(cat "$scratch/err.txt"))" test -s "$sim/feather.bin"
# Version 1 (numbers inline, as earlier plume wrote it) in a copy of the folder:
# the views of version 2 become arrays again, the shaft's first coordinate 1e308.
cp -r "$sim" "$sim-v1"
/usr/bin/python3 - "$sim-v1" <<'EOF'
import json, struct, sys
folder = sys.argv[1]
doc = json.load(open(folder + '/feather.json'))
data = open(folder + '/feather.bin', 'rb').read()
def inline(value):
    if isinstance(value, dict) and set(value) == {'offset', 'count'}:
        return list(struct.unpack_from('<%dd' % value['count'], data, value['offset']))
    if isinstance(value, dict):
        return {k: inline(v) for k, v in value.items() if k != 'buffer'}
    if isinstance(value, list):
        return [inline(v) for v in value]
    return value
doc = inline(doc)
doc['version'] = 1
doc['shaft']['position'][0] = 1e308
open(folder + '/feather.json', 'w').write(json.dumps(doc))
EOF
check "feather.json edited" grep -q '1e+308' "$sim-v1/feather.json"
expect_no_output "render feather.json 1e308" 3 'feather.json: $.' "$scratch/o14" \
	$T "$plume" render "$sim-v1" -o "$scratch/o14" --spp 1 --size 32x32
check "render 1e308: names the range" grep -qF 'is outside the range of any value plume reads' "$scratch/err.txt"
# Version 2: the first number of the sidecar becomes 1e308.
/usr/bin/python3 -c 'import struct, sys; f = open(sys.argv[1], "r+b"); f.write(struct.pack("<d", 1e308))' "$sim/feather.bin"
expect_no_output "render feather.bin 1e308" 3 'feather.json: $.' "$scratch/o14b" \
	$T "$plume" render "$sim" -o "$scratch/o14b" --spp 1 --size 32x32
check "render feather.bin 1e308: names the sidecar and the range" \
	grep -qF 'in the sidecar is 1e+308, outside the range of any value plume reads' "$scratch/err.txt"

# --- a simulation whose frames would pass --max-memory: refused before the run -----------
edit "$bad/scene-short.json" "$bad/scene-long.json" "d['duration'] = 1e4; d['time_step'] = 0.001; d['frame_every'] = 1"
expect_no_output "frames past the limit" 5 'frames of up to' "$scratch/o15" \
	$T "$plume" simulate "$bad/scene-long.json" -o "$scratch/o15"
check "frames limit names --max-memory" grep -qF 'raise it with --max-memory' "$scratch/err.txt"
expect_no_output "PNG frames past a 1M limit" 5 'the limit is 0.00105 GB' "$scratch/o16" \
	$T "$plume" simulate "$bad/scene-short.json" -o "$scratch/o16" --png --max-memory 1M
$T "$plume" simulate "$bad/scene-short.json" -o "$scratch/o17" --max-memory 64M >/dev/null 2>&1
check "a short run fits in 64M" test -s "$scratch/o17/summary.json"

# --- meshes past the limit: refused before the guide vertices are placed (src/mesh/aligned.c) ---
expect_no_output "mesh edge length 10 um" 5 \
	'guides.json: edge_length 1e-05 m on a 0.12 m rachis with guides up to' "$scratch/m1" \
	$T "$plume" mesh "$examples/meshes/guides.json" -o "$scratch/m1" -e 1e-5
check "mesh limit names the estimate, the limit and --max-memory" \
	grep -qE 'about [0-9.e+]+ vertices, [0-9.e+]+ faces: [0-9.]+ GB while meshing; the limit is 4.29 GB \(raise it with --max-memory' "$scratch/err.txt"
expect_no_output "tall feather past --max-memory 32M" 5 'the limit is 0.0336 GB' "$scratch/m2" \
	$T "$plume" mesh "$source_dir/fuzz/corpus/mesh_spec/tall-feather-2.json" -o "$scratch/m2" --max-memory 32M
expect_no_output "mesh at 0.5 mm past --max-memory 1M" 5 'the limit is 0.00105 GB' "$scratch/m3" \
	$T "$plume" mesh "$examples/meshes/guides.json" -o "$scratch/m3" -e 5e-4 --max-memory 1M
$T "$plume" mesh "$examples/meshes/guides.json" -o "$scratch/m4" --max-memory 2M -f obj 2>"$scratch/err.txt"
check "mesh --max-memory 2M meshes the example ($(cat "$scratch/err.txt"))" test -s "$scratch/m4/mesh.obj"
edit "$bad/scene-short.json" "$bad/scene-fine.json" "d['mesh']['edge_length'] = 1e-6"
expect_no_output "scene mesh past the limit" 5 'scene-fine.json: $.feather: meshing: edge_length 1e-06 m on a' "$scratch/m5" \
	$T "$plume" simulate "$bad/scene-fine.json" -o "$scratch/m5"

# --- a Franco-Walter feather past the limit: barbs x samples (plume_fw_estimate_bytes) -------
edit "$examples/franco-walter/hawk.json" "$bad/fw-dense.json" \
	"d['barb_samples'] = 1000; d['segments'][0]['barb_count'] = 5000; d['segments'][1]['barb_count'] = 5000"
expect_no_output "FW 20000 barbs x 1000 samples past --max-memory 64M" 5 \
	'fw-dense.json: $.segments[*].barb_count (5000 and 5000 barbs a vane) x $.barb_samples (1000)' "$scratch/g1" \
	$T "$plume" generate "$bad/fw-dense.json" -o "$scratch/g1" --max-memory 64M
check "FW limit names the estimate and --max-memory" \
	grep -qF 'make a feather of about 1.6 GB; the limit is 0.0671 GB (raise it with --max-memory' "$scratch/err.txt"
edit "$bad/fw-dense.json" "$bad/fw-range.json" "d['segments'][0]['barb_count'] = 6000"
expect_no_output "FW out of range wins over the limit" 3 '$.segments[0].barb_count' "$scratch/g2" \
	$T "$plume" generate "$bad/fw-range.json" -o "$scratch/g2" --max-memory 64M

# --- Streit-Heidrich and Zhang-Kanai feathers past the limit, within the keys' ranges -------
# (plume_sh_estimate_bytes, plume_zk_estimate_bytes)
edit "$examples/streit-heidrich/contour.json" "$bad/sh-dense.json" \
	"d['spacing_base'] = d['spacing_tip'] = 1e-6; d['lod'] = {'barb_elevations': 60}"
expect_no_output "SH 4000 barbs a vane x 64 points past --max-memory 16M" 5 \
	'sh-dense.json: $.rachis_length / $.spacing_base, $.spacing_tip (at most 4000 barbs a vane)' "$scratch/g3" \
	$T "$plume" generate "$bad/sh-dense.json" -o "$scratch/g3" --max-memory 16M
check "SH limit names the estimate and --max-memory" \
	grep -qF 'the limit is 0.0168 GB (raise it with --max-memory' "$scratch/err.txt"
$T "$plume" generate "$examples/streit-heidrich/contour.json" -o "$scratch/g4" -f json --max-memory 1M \
	2>"$scratch/err.txt"
check "SH contour under --max-memory 1M ($(cat "$scratch/err.txt"))" test -s "$scratch/g4/feather.json"
edit "$examples/zhang-kanai/figure11-expansion.json" "$bad/zk-dense.json" \
	"d['barb_count'] = 5000; d['step'] = 1e-5; d['downsample'] = 1"
expect_no_output "ZK 5000 barbs traced at 10 us with barbules" 5 \
	'zk-dense.json: $.barb_count (5000) and the barbs still growing' "$scratch/g5" \
	$T "$plume" generate "$bad/zk-dense.json" -o "$scratch/g5"
check "ZK limit names the step, the barbules and --max-memory" \
	grep -qF '($.step 1e-05, $.downsample 1, barbules kept) make a feather of about' "$scratch/err.txt"

# --- lab runs past the limit: the largest mesh's elements x 16 KiB (plume_sample_estimate_bytes) -----
edit "$examples/lab/tilted-mesoscale.json" "$bad/lab-dense.json" "d['sample']['elements'] = 4000000"
expect_no_output "lab traction of 4e6 elements" 5 \
	'lab-dense.json: $.sample.elements (4000000) make meshes of about 65.6 GB (16 KiB an element); the limit is 4.29 GB (raise it with --max-memory' \
	"$scratch/l1" $T "$plume" lab traction "$bad/lab-dense.json" -o "$scratch/l1"
expect_no_output "lab calibrate --elements 100000 past --max-memory 1G" 5 \
	'--elements 100000 and --macro-elements 2000 (twice the larger for the spreads) make meshes of about 3.31 GB' \
	"$scratch/l2" $T "$plume" lab calibrate --phi 0.14 --Eb 3.92e4 --EB 2.57e9 --elements 100000 --max-memory 1G \
	-o "$scratch/l2"
expect_no_output "lab study --scale 16 past --max-memory 1G" 5 '--scale 16 (16000 x 16 elements) make meshes' \
	"$scratch/l3" $T "$plume" lab study locking --scale 16 --max-memory 1G -o "$scratch/l3"

# --- a sweep of 1e6 runs (the spec's own cap) past the default --max-runs 100000 --------------------
cat >"$bad/sweep-big.json" <<EOF
{"command": "generate", "spec": "$examples/franco-walter/hawk.json", "outputs": [],
 "parameters": [{"path": "\$.barb_width_base", "grid": {"from": 1e-4, "to": 2e-4, "count": 1000}},
                {"path": "\$.barb_width_tip", "grid": {"from": 1e-5, "to": 2e-5, "count": 1000}}]}
EOF
expect_no_output "sweep of 1e6 runs" 5 \
	"sweep-big.json: \$.samples (1) x the grids' and lists' values (1000000) make 1000000 runs; the limit is 100000 (raise it with --max-runs" \
	"$scratch/s1" $T "$plume" sweep "$bad/sweep-big.json" -o "$scratch/s1"
expect_no_output "sweep --max-runs 0" 2 "--max-runs expects a whole number in [1, 1000000], got '0'" "$scratch/s2" \
	$T "$plume" sweep "$bad/sweep-big.json" -o "$scratch/s2" --max-runs 0

# --- renders past the limit: pixels x images (cli/render.c, plume_raytrace_estimate_bytes) ---
expect_no_output "render turntable of 100 16384^2 images" 5 \
	'filoplume.json: 100 image(s) of 16384x16384 pixels' "$scratch/r1" \
	$T "$plume" render "$examples/franco-walter/filoplume.json" -o "$scratch/r1" --size 16384x16384 --turntable 100
check "render limit names the estimate and --max-memory" \
	grep -qF 'take about 110 GB; the limit is 4.29 GB (raise it with --max-memory' "$scratch/err.txt"
expect_no_output "render 4096^2 past --max-memory 64M" 5 'take about 0.201 GB; the limit is 0.0671 GB' "$scratch/r2" \
	$T "$plume" render "$examples/franco-walter/filoplume.json" -o "$scratch/r2" --size 4096x4096 --max-memory 64M
expect_no_output "render a strip past --max-memory 256M" 5 'held at once' "$scratch/r3" \
	$T "$plume" render "$scratch/o17" -o "$scratch/r3" --strip 3 --size 8192x8192 --max-memory 256M

# --- all or nothing over an earlier run (cli/output.c) -----------------------------------
edit "$bad/scene-short.json" "$bad/scene-three.json" "d['duration'] = 0.033"
run=$scratch/run
$T "$plume" simulate "$bad/scene-three.json" -o "$run" >/dev/null 2>&1
check "earlier run: three frames" test "$(ls "$run/frames" | wc -l)" -eq 3
echo mine >"$run/notes.txt"
echo mine >"$run/frames/my-notes.txt"
cp "$run/summary.json" "$scratch/summary-before.json"
# A failing run changes nothing, not even a frame.
expect_failure "failing run over an earlier one" 3 '$.duration' \
	$T "$plume" simulate "$bad/scene-steps.json" -o "$run"
check "failed run: summary intact" cmp -s "$run/summary.json" "$scratch/summary-before.json"
check "failed run: three frames kept" test "$(ls "$run/frames" | grep -c obj)" -eq 3
# A shorter run replaces the earlier run whole: its frames go, the user's files stay.
$T "$plume" simulate "$bad/scene-short.json" -o "$run" >/dev/null 2>&1
check "new run: only its two frames" test "$(ls "$run/frames" | grep -c obj)" -eq 2
check "new run: summary replaced" bash -c "! cmp -s '$run/summary.json' '$scratch/summary-before.json'"
check "new run: the user's file in DIR kept" test "$(cat "$run/notes.txt")" = mine
check "new run: the user's file in frames/ kept" test "$(cat "$run/frames/my-notes.txt")" = mine
check "new run: no staging beside or inside" test -z "$(ls -A "$scratch" "$run" | grep plume-staging)"
# Staging folders of a dead run are removed, found by their name and the marker plume writes
# in each (its PID and start time); those of a live process (this shell), those without a
# valid marker and anything else are not.
true &
dead=$!
wait "$dead"
marker() { # marker FOLDER PID: a staging folder as plume makes it
	mkdir -p "$1"
	printf 'plume staging folder\npid %s\nstart 0\n' "$2" >"$1/.plume-staging-marker"
	echo partial >"$1/stats.csv"
}
marker "$scratch/.run.plume-staging-$dead-abcdef" "$dead"
marker "$run/.plume-staging-$dead-abcdeg" "$dead"
marker "$scratch/.run.plume-staging-$$-abcdef" $$
marker "$scratch/.run.plume-staging-$dead-other" "$((dead + 1))"
mkdir "$scratch/.run.plume-staging-keep" "$scratch/.run.plume-staging-$dead-nomark"
echo mine >"$scratch/.run.plume-staging-$dead-nomark/notes.txt"
printf 'not plume\n' >"$scratch/.run.plume-staging-$dead-other/.plume-staging-marker"
$T "$plume" simulate "$bad/scene-short.json" -o "$run" >/dev/null 2>&1
check "stale staging beside DIR removed" test ! -e "$scratch/.run.plume-staging-$dead-abcdef"
check "stale staging inside DIR removed" test ! -e "$run/.plume-staging-$dead-abcdeg"
check "a live process's staging kept" test -d "$scratch/.run.plume-staging-$$-abcdef"
check "a folder not of the pattern kept" test -d "$scratch/.run.plume-staging-keep"
check "a look-alike without a marker kept" test "$(cat "$scratch/.run.plume-staging-$dead-nomark/notes.txt")" = mine
check "a look-alike with another marker kept" test -d "$scratch/.run.plume-staging-$dead-other"
check "stale clean-up: the user's file in frames/ kept" test "$(cat "$run/frames/my-notes.txt")" = mine
rm -r "$scratch/.run.plume-staging-$$-abcdef" "$scratch/.run.plume-staging-keep" \
	"$scratch/.run.plume-staging-$dead-nomark" "$scratch/.run.plume-staging-$dead-other"

# Ctrl-C (SIGINT) and SIGTERM during a run: its staging folder goes, plume ends by the
# signal, and DIR keeps the earlier run. (set -m: a background job of a script would
# otherwise start with SIGINT ignored, and plume keeps an ignored signal ignored.)
edit "$bad/scene-short.json" "$bad/scene-slow.json" "d['duration'] = 30"
cp "$run/summary.json" "$scratch/summary-before.json"
for sig in INT TERM; do
	set -m
	"$plume" simulate "$bad/scene-slow.json" -o "$run" >/dev/null 2>&1 &
	pid=$!
	set +m
	# Wait until the run has written a frame into its staging folder.
	for _ in $(seq 300); do
		ls "$scratch"/.run.plume-staging-*/frames/0001.obj >/dev/null 2>&1 && break
		sleep 0.1
	done
	check "SIG$sig: the run was staging" bash -c "ls '$scratch'/.run.plume-staging-*/frames/0001.obj >/dev/null 2>&1"
	kill -"$sig" "$pid"
	wait "$pid"
	status=$?
	check "SIG$sig: plume ended by the signal (status $status)" test "$status" -eq $((128 + $(kill -l "$sig")))
	check "SIG$sig: nothing left beside DIR" test -z "$(ls -A "$scratch" "$run" | grep plume-staging)"
	check "SIG$sig: the earlier run intact" cmp -s "$run/summary.json" "$scratch/summary-before.json"
	check "SIG$sig: the user's file in frames/ kept" test "$(cat "$run/frames/my-notes.txt")" = mine
done

# A folder of DIR with the name of a file of the run is not deleted: the run fails instead.
gen=$scratch/gen
mkdir -p "$gen/feather.obj"
echo mine >"$gen/feather.obj/inside.txt"
expect_failure "a folder named like an output" 4 'feather.obj: the run writes a file or folder of that name' \
	$T "$plume" generate "$examples/franco-walter/blue.json" -o "$gen" --format obj
check "that folder is intact" test "$(cat "$gen/feather.obj/inside.txt")" = mine
check "no staging left after the conflict" test -z "$(ls -A "$scratch" | grep plume-staging)"

# DIR a symbolic link to a folder: the folder gets the run, the link stays a link.
mkdir -p "$scratch/real"
echo mine >"$scratch/real/notes.txt"
ln -s real "$scratch/link"
$T "$plume" generate "$examples/franco-walter/blue.json" -o "$scratch/link" --format json >/dev/null 2>&1
check "a linked DIR: still a link" test -L "$scratch/link"
check "a linked DIR: the run is in the folder" test -s "$scratch/real/feather.json"
check "a linked DIR: the user's file kept" test "$(cat "$scratch/real/notes.txt")" = mine
check "a linked DIR: no staging left" test -z "$(ls -A "$scratch" "$scratch/real" | grep plume-staging)"

# --- the run manifest (DIR/.plume-run): a new run replaces exactly the earlier run's files,
# whatever their names, and keeps everything else.
grew=$scratch/grew
$T "$plume" grow "$examples/streit-heidrich/contour.json" -o "$grew" --frames 6 --format json >/dev/null 2>&1
echo mine >"$grew/frame-notes.txt"
$T "$plume" grow "$examples/streit-heidrich/contour.json" -o "$grew" --frames 2 --format json >/dev/null 2>&1
check "grow again: the new run's two frames and the user's file" \
	test "$(ls "$grew" | tr '\n' ' ')" = "frame-0000.json frame-0001.json frame-notes.txt "
gen2=$scratch/gen2
$T "$plume" generate "$examples/zhang-kanai/figure8-contour.json" -o "$gen2" --format json >/dev/null 2>&1
check "zhang-kanai writes summary.json" test -s "$gen2/summary.json"
$T "$plume" generate "$examples/franco-walter/blue.json" -o "$gen2" --format json >/dev/null 2>&1
check "franco-walter after it: the earlier run's summary.json gone" test "$(ls "$gen2")" = "feather.json"
# A user's file named like a frame, in a folder the run writes, is the user's: kept.
echo mine >"$run/frames/0007-notes.txt"
$T "$plume" simulate "$bad/scene-short.json" -o "$run" >/dev/null 2>&1
check "a user's file named like a frame kept" test "$(cat "$run/frames/0007-notes.txt")" = mine
check "the manifest lists the run's files" grep -qx "frames/0001.obj" "$run/.plume-run"
check "the manifest does not list the user's" bash -c "! grep -q notes '$run/.plume-run'"
# An earlier run of another command is not this run's to replace: its files stay, and a run
# that would overwrite one of them fails, naming it.
mixed=$scratch/mixed
$T "$plume" generate "$examples/franco-walter/blue.json" -o "$mixed" --format png,json >/dev/null 2>&1
cp -r "$mixed" "$scratch/mixed-before"
expect_failure "render over generate's feather.png" 4 "mixed/feather.png: written by plume generate, which this plume render would replace" \
	$T "$plume" render "$examples/franco-walter/blue.json" -o "$mixed" --size 32x32 --spp 1
check "that folder as it was" diff -r "$scratch/mixed-before" "$mixed"
$T "$plume" render "$examples/franco-walter/blue.json" -o "$mixed" --size 32x32 --spp 1 --turntable 2 >/dev/null 2>&1
check "a turntable beside generate's files" test "$(ls "$mixed" | tr '\n' ' ')" = "feather.json feather.png turntable "
# A folder written before manifests (none in it): the earlier rule, names starting with a digit
# in the run's folders are the earlier run's.
rm "$run/.plume-run"
$T "$plume" simulate "$bad/scene-short.json" -o "$run" >/dev/null 2>&1
check "no manifest: frames named with a digit first replaced" test ! -e "$run/frames/0007-notes.txt"
check "no manifest: other user files kept" test "$(cat "$run/frames/my-notes.txt")" = mine

# As another user (root runs the suite in CI; skipped otherwise): a DIR whose parent plume may
# not write is committed entry by entry, which keeps the user's files in the run's folders and
# drops the earlier run's other files; a file of another user that the kernel will not let
# plume hard-link (fs.protected_hardlinks) is named as such, and nothing changes.
if [ "$(id -u)" -eq 0 ] && command -v setpriv >/dev/null; then
	as_nobody() { setpriv --reuid=65534 --regid=65534 --clear-groups "$@"; }
	locked=$scratch/locked
	mkdir -p "$locked/out"
	chmod 755 "$scratch" "$locked"
	chmod 777 "$locked/out"
	cp -r "$grew/." "$locked/out/"
	chown -R 65534:65534 "$locked/out"
	as_nobody $T "$plume" grow "$examples/streit-heidrich/contour.json" -o "$locked/out" --frames 1 --format json \
		>/dev/null 2>"$scratch/err.txt"
	succeeded "commit by moves (parent not writable)"
	check "commit by moves: the new run and the user's file" \
		test "$(ls -A "$locked/out" | tr '\n' ' ')" = ".plume-run frame-0000.json frame-notes.txt "
	shared=$scratch/shared
	mkdir -p "$shared/out"
	chmod 777 "$shared" "$shared/out"
	echo root >"$shared/out/user.txt"
	expect_failure "another user's file" 4 "out/user.txt: owned by another user (uid 0)" \
		as_nobody $T "$plume" generate "$examples/franco-walter/blue.json" -o "$shared/out" --format json
	check "another user's file: the folder as it was" test "$(ls -A "$shared/out")" = "user.txt"
	check "another user's file: no staging left" test -z "$(ls -A "$shared" | grep plume-staging)"
fi

finish
