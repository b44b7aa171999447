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

# An existing output folder keeps what it had when a render fails.
mkdir -p "$scratch/keep"
echo keep >"$scratch/keep/note.txt"
"$plume" render "$presets/figure6a.json" -o "$scratch/keep" -c "$scratch/away.json" 2>/dev/null
check "failed render keeps the folder as it was" test "$(ls -A "$scratch/keep")" = "note.txt"

finish
