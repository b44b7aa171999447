#!/usr/bin/env bash
# Scenario tests of `plume render`: a feather spec, a turntable, a simulation folder (made here: a feather,
# a two-triangle shell and a turned copy of it as frames), same bytes on a second run, and bad inputs that
# leave nothing behind.
# Usage: render.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"
presets=$source_dir/examples/franco-walter
differs() { ! cmp -s "$1" "$2"; }

# --- a feather spec
"$plume" render "$presets/figure6a.json" -o "$scratch/spec" --spp 2 --size 64x96 2>"$scratch/err.txt"
check "spec: exit 0" test $? -eq 0
check "spec: feather.png" test -s "$scratch/spec/feather.png"
"$plume" render "$presets/figure6a.json" -o "$scratch/spec2" --spp 2 --size 64x96 --threads 1
check "spec: same bytes with another thread count" cmp -s "$scratch/spec/feather.png" "$scratch/spec2/feather.png"
"$plume" render "$presets/figure6a.json" -o "$scratch/spec3" --spp 2 --size 64x96 --seed 9
check "spec: another seed, other bytes" differs "$scratch/spec/feather.png" "$scratch/spec3/feather.png"

"$plume" render "$presets/figure6a.json" -o "$scratch/turn" --spp 1 --size 32x32 --turntable 3 \
	-t "$source_dir/examples/textures/bands.png"
check "turntable: exit 0" test $? -eq 0
check "turntable: three images" test "$(ls "$scratch/turn/turntable" | wc -l)" -eq 3

# Every ready camera file is valid.
for camera in "$source_dir"/examples/cameras/*.json; do
	"$plume" render "$presets/hawk.json" -o "$scratch/cam-$(basename "$camera" .json)" -c "$camera" --spp 1 \
		--size 32x32 2>"$scratch/err.txt"
	succeeded "camera ${camera##*/}: exit 0"
done

# --- a coat spec: the coat's feathers over its surface
"$plume" render "$source_dir/examples/coats/sphere.json" -o "$scratch/coat" --spp 1 --size 32x32 2>"$scratch/err.txt"
succeeded "coat: exit 0"
check "coat: feather.png" test -s "$scratch/coat/feather.png"

# --- a simulation folder: feather.json, a flat two-triangle shell around it, frames 0000 (rest) and
# 0001 (turned a quarter about the shaft axis y: (x, y, z) -> (z, y, -x)).
"$plume" generate "$presets/figure6a.json" -o "$scratch/gen" -f json
sim=$scratch/sim
mkdir -p "$sim/frames"
cp "$scratch/gen/feather.json" "$sim/feather.json"
shell() { # shell TURNED
	if [ "$1" = 0 ]; then
		printf 'v -0.03 -0.01 0\nv 0.03 -0.01 0\nv 0.03 0.09 0\nv -0.03 0.09 0\n'
	else
		printf 'v 0 -0.01 0.03\nv 0 -0.01 -0.03\nv 0 0.09 -0.03\nv 0 0.09 0.03\n'
	fi
	printf 'f 1 2 3\nf 1 3 4\n'
}
shell 0 >"$sim/mesh.obj"
shell 0 >"$sim/frames/0000.obj"
shell 1 >"$sim/frames/0001.obj"
"$plume" render "$sim" -o "$scratch/simout" --spp 1 --size 48x48 2>"$scratch/err.txt"
succeeded "sim: exit 0"
for f in 0000.png 0001.png 0000.obj 0001.obj 0000.usda 0001.usda; do
	check "sim: frames/$f" test -s "$scratch/simout/frames/$f"
done
check "sim: frames differ" differs "$scratch/simout/frames/0000.obj" "$scratch/simout/frames/0001.obj"
"$plume" render "$sim" -o "$scratch/simshell" --spp 1 --size 48x48 --shell -f png
check "sim --shell: png only" test "$(ls "$scratch/simshell/frames")" = "$(printf '0000.png\n0001.png')"

png_width() { od -An -tu1 -j16 -N4 "$1" | awk '{print $1 * 16777216 + $2 * 65536 + $3 * 256 + $4}'; }
"$plume" render "$sim" -o "$scratch/strip" --spp 1 --size 48x32 --strip 2 -f png
check "sim --strip: strip.png two frames wide" test "$(png_width "$scratch/strip/strip.png")" -eq 96

# --- bad inputs
expect_no_output "missing input" 4 "cannot read" "$scratch/o1" "$plume" render "$scratch/nothing.json" -o "$scratch/o1"
mkdir -p "$scratch/nosim"
cp "$sim/feather.json" "$sim/mesh.obj" "$scratch/nosim/"
touch "$scratch/nosim/frames" # a file, not a folder
expect_no_output "unreadable frames folder" 4 "cannot read the frames folder" "$scratch/o2" \
	"$plume" render "$scratch/nosim" -o "$scratch/o2"
mkdir -p "$scratch/badframe/frames"
cp "$sim/feather.json" "$sim/mesh.obj" "$scratch/badframe/"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$scratch/badframe/frames/0000.obj"
expect_no_output "frame with other vertices" 3 "frames must keep the shell's vertices" "$scratch/o3" \
	"$plume" render "$scratch/badframe" -o "$scratch/o3"
printf '{"camera": {"eye": [0, 0.04, 0], "target": [0, 0.04, -1]}}' >"$scratch/inside.json"
expect_no_output "camera inside" 3 "inside the scene's bounds" "$scratch/o4" \
	"$plume" render "$presets/figure6a.json" -o "$scratch/o4" -c "$scratch/inside.json" --size 32x32
printf '{"camera": {"eye": [0, 0.04, 0.5], "target": [0, 0.04, 1]}}' >"$scratch/away.json"
expect_no_output "camera looking at nothing" 3 "sees none of the scene" "$scratch/o5" \
	"$plume" render "$presets/figure6a.json" -o "$scratch/o5" -c "$scratch/away.json" --size 32x32
expect_no_output "camera looking at nothing (sim)" 3 "sees none of the scene" "$scratch/o5b" \
	"$plume" render "$sim" -o "$scratch/o5b" -c "$scratch/away.json" --size 32x32
printf 'not an image' >"$scratch/bad.png"
expect_no_output "unreadable texture" 3 "bad.png" "$scratch/o6" \
	"$plume" render "$presets/figure6a.json" -o "$scratch/o6" -t "$scratch/bad.png"
expect_no_output "missing texture" 4 "missing.png" "$scratch/o7" \
	"$plume" render "$presets/figure6a.json" -o "$scratch/o7" -t "$scratch/missing.png"
printf '{"camera": {"fov": 30}}' >"$scratch/typo.json"
expect_no_output "camera key typo" 3 'typo.json: $.camera.fov: unknown key' "$scratch/o8" \
	"$plume" render "$presets/figure6a.json" -o "$scratch/o8" -c "$scratch/typo.json"
expect_no_output "bad spp" 2 "--spp" "$scratch/o9" "$plume" render "$presets/figure6a.json" -o "$scratch/o9" --spp 0
expect_no_output "strip of a spec" 2 "--strip needs a simulation folder" "$scratch/o11" \
	"$plume" render "$presets/figure6a.json" -o "$scratch/o11" --strip 3
expect_no_output "turntable of a sim" 2 "--turntable needs a feather spec" "$scratch/o10" \
	"$plume" render "$sim" -o "$scratch/o10" --turntable 3

# --- rendering into the simulation folder itself: refused (its frames/NNNN.obj are the shell's),
# however the folder is named, with or without --frames; the simulation is left as it was.
cp -r "$sim" "$scratch/sim-before"
expect_failure "into the simulation folder" 2 "is the simulation folder" \
	"$plume" render "$sim" -o "$sim" --spp 1 --size 32x32
expect_failure "into the simulation folder, --frames" 2 "is the simulation folder" \
	"$plume" render "$sim" -o "$sim/." --frames 0:1 --spp 1 --size 32x32
ln -s "$sim" "$scratch/sim-link"
expect_failure "into the simulation folder through a link" 2 "is the simulation folder" \
	"$plume" render "$scratch/sim-link" -o "$sim/" --frames 0:1 -f obj --spp 1 --size 32x32
cp -r "$sim" "$scratch/other-sim"
expect_failure "into another simulation's folder" 2 "holds a simulation" \
	"$plume" render "$sim" -o "$scratch/other-sim" --frames 0:1 --spp 1 --size 32x32
check "the other simulation folder is untouched" diff -r "$scratch/sim-before" "$scratch/other-sim"
check "the simulation folder is untouched" diff -r "$scratch/sim-before" "$sim"

# --- a render into a folder it wrote before replaces that run: the earlier frames go (here
# the .obj and .usda a png-only run does not write), the user's files stay, in frames/ too.
"$plume" render "$sim" -o "$scratch/again" --spp 1 --size 32x32 2>"$scratch/err.txt"
succeeded "render: first run"
echo mine >"$scratch/again/notes.txt"
echo mine >"$scratch/again/frames/0001-notes.txt"
"$plume" render "$sim" -o "$scratch/again" --spp 1 --size 32x32 -f png 2>"$scratch/err.txt"
succeeded "render again into the same folder"
check "render again: the new run's frames, the user's files" test "$(ls "$scratch/again/frames" | tr '\n' ' ')" = \
	"0000.png 0001-notes.txt 0001.png "
check "render again: the user's file beside frames/" test -s "$scratch/again/notes.txt"
"$plume" render "$presets/figure6a.json" -o "$scratch/turn" --spp 1 --size 32x32 --turntable 2 2>"$scratch/err.txt"
succeeded "turntable again into the same folder"
check "turntable again: the new run's two images" test "$(ls "$scratch/turn/turntable" | tr '\n' ' ')" = "0000.png 0001.png "

# --- --frames: ranges join DIR/frames; bad input makes no folder (DIR and DIR/frames are
# made only once the range is rendered).
"$plume" render "$sim" -o "$scratch/ranges" --frames 0:0 -f obj --spp 1 --size 32x32 2>"$scratch/err.txt"
succeeded "--frames 0:0"
"$plume" render "$sim" -o "$scratch/ranges" --frames 1:1 -f obj --spp 1 --size 32x32 2>"$scratch/err.txt"
succeeded "--frames 1:1 into the same folder"
check "--frames: both ranges" test "$(ls -A "$scratch/ranges/frames" | tr '\n' ' ')" = "0000.obj 0001.obj "
expect_no_output "--frames past the last frame" 3 "no frame in --frames" "$scratch/r-none" \
	"$plume" render "$sim" -o "$scratch/r-none" --frames 50:60
expect_no_output "--frames with a bad camera" 3 'inside.json: $.camera.eye' "$scratch/r-cam" \
	"$plume" render "$sim" -o "$scratch/r-cam" --frames 0:1 -c "$scratch/inside.json" --size 32x32

# --- frames are taken in the order of their numbers: simulate writes %04d, so 10000.obj
# follows 9999.obj. The same with numbers of one and two digits, 0.obj to 11.obj (10.obj sorts
# before 2.obj as text): the strip's one slot is the last frame, 11.
mkdir -p "$scratch/numbers/frames"
cp "$sim/feather.json" "$sim/mesh.obj" "$scratch/numbers/"
for k in $(seq 0 11); do
	printf 'v -0.03 -0.01 0\nv 0.03 -0.01 0.00%d\nv 0.03 0.09 0\nv -0.03 0.09 -0.00%d\nf 1 2 3\nf 1 3 4\n' "$k" "$k" \
		>"$scratch/numbers/frames/$k.obj"
done
"$plume" render "$scratch/numbers" -o "$scratch/numbers-out" -f png --strip 1 --spp 1 --size 32x32 2>"$scratch/err.txt"
succeeded "frames by number"
check "strip of one: the last frame by number (11)" cmp -s "$scratch/numbers-out/strip.png" \
	"$scratch/numbers-out/frames/11.png"
check "strip of one: not frame 9" differs "$scratch/numbers-out/strip.png" "$scratch/numbers-out/frames/9.png"
# A frame missing from the sequence (or from what summary.json counts) is named; nothing written.
rm "$scratch/numbers/frames/5.obj"
expect_no_output "a missing frame" 4 "numbers/frames/0005.obj: missing" "$scratch/r-gap" \
	"$plume" render "$scratch/numbers" -o "$scratch/r-gap"
mkdir -p "$scratch/short/frames"
cp "$sim/feather.json" "$sim/mesh.obj" "$scratch/short/"
cp "$sim/frames/0000.obj" "$sim/frames/0001.obj" "$scratch/short/frames/"
echo '{"completed": true, "frames": 3}' >"$scratch/short/summary.json"
expect_no_output "a last frame missing" 4 "short/frames/0002.obj: missing; $scratch/short/summary.json says the run wrote 3 frames" \
	"$scratch/r-short" "$plume" render "$scratch/short" -o "$scratch/r-short"
echo '{"completed": true, "frames": 1}' >"$scratch/short/summary.json"
expect_no_output "a frame too many" 3 "short/frames/0001.obj: not of this run" "$scratch/r-long" \
	"$plume" render "$scratch/short" -o "$scratch/r-long"
cp "$sim/frames/0001.obj" "$scratch/short/frames/1.obj"
rm "$scratch/short/summary.json"
expect_no_output "a frame twice" 3 "0001.obj and 1.obj: both are frame 1" "$scratch/r-twice" \
	"$plume" render "$scratch/short" -o "$scratch/r-twice"

# --- camera files: errors name the file and the key, not an image of the run.
printf '{"camera": {"eye": [0, 0.04, 1], "target": [0, 0.04, 0], "up": [0, 0, 1]}}' >"$scratch/upcam.json"
expect_no_output "camera up along the view" 3 'upcam.json: $.camera.up: (0, 0, 1) is parallel' "$scratch/c1" \
	"$plume" render "$presets/figure6a.json" -o "$scratch/c1" -c "$scratch/upcam.json" --size 32x32
printf '{"camera": {"margin": 0.45}}' >"$scratch/margin.json"
expect_no_output "camera margin 0.45" 3 'margin.json: $.camera.margin: is 0.45, allowed [0, 0.45)' "$scratch/c2" \
	"$plume" render "$sim" -o "$scratch/c2" -c "$scratch/margin.json" --size 32x32
printf '{"camera": {"eye": [0, 0.04, 1], "target": [0, 0.04, 0], "orthographic": true}}' >"$scratch/ortho.json"
expect_no_output "orthographic camera without ortho_height" 3 'ortho.json: $.camera.ortho_height: missing' \
	"$scratch/c3" "$plume" render "$presets/figure6a.json" -o "$scratch/c3" -c "$scratch/ortho.json" --size 32x32
expect_no_output "camera inside names the key" 3 'inside.json: $.camera.eye: the camera at' "$scratch/c4" \
	"$plume" render "$presets/figure6a.json" -o "$scratch/c4" -c "$scratch/inside.json" --size 32x32
expect_no_output "camera looking away names the key" 3 'away.json: $.camera.target: the camera at' "$scratch/c5" \
	"$plume" render "$sim" -o "$scratch/c5" -c "$scratch/away.json" --size 32x32
expect_no_output "camera a folder" 4 ".: is a folder; --camera takes a camera file" "$scratch/c6" \
	"$plume" render "$presets/figure6a.json" -o "$scratch/c6" -c .

# --- what render does not take: a scene (simulate it first), a spec without a model, --format for a spec.
printf '{"feather": "%s", "handles": [{"group": "rachis_clamp"}]}' "$presets/figure6a.json" >"$scratch/scene.json"
expect_no_output "a scene" 3 "scene.json: a scene (docs/scene.md), which plume render does not take" "$scratch/s1" \
	"$plume" render "$scratch/scene.json" -o "$scratch/s1"
printf '{"rachis_length": 0.2}' >"$scratch/nomodel.json"
expect_no_output "no model" 3 'a coat spec ("model": "coat") or a simulation folder' "$scratch/s2" \
	"$plume" render "$scratch/nomodel.json" -o "$scratch/s2"
expect_no_output "--format for a spec" 2 "--format needs a simulation folder" "$scratch/s3" \
	"$plume" render "$presets/figure6a.json" -o "$scratch/s3" -f obj

# An existing output folder keeps what it had when a render fails.
mkdir -p "$scratch/keep"
echo keep >"$scratch/keep/note.txt"
"$plume" render "$presets/figure6a.json" -o "$scratch/keep" -c "$scratch/away.json" 2>/dev/null
check "failed render keeps the folder as it was" test "$(ls -A "$scratch/keep")" = "note.txt"

finish
