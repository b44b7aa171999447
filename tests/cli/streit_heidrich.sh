#!/usr/bin/env bash
# Scenario tests of the streit-heidrich presets with `plume generate`, of
# `plume grow` and of `plume coat`: what a user runs, what they get back, and
# that bad input changes nothing.
# Usage: streit_heidrich.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"
presets=$source_dir/examples/streit-heidrich
coats=$source_dir/examples/coats

# --- every preset generates ---------------------------------------------------
for spec in "$presets"/*.json; do
	name=$(basename "$spec" .json)
	out=$scratch/$name
	"$plume" generate "$spec" -o "$out" --format png,obj,usda --size 200x300 2>"$scratch/err.txt"
	succeeded "$name: generate succeeds"
	for ext in png obj usda; do
		check "$name: feather.$ext written" test -s "$out/feather.$ext"
	done
	check "$name: OBJ polylines" grep -q '^l ' "$out/feather.obj"
done
check "semiplume: afterfeather exported" grep -q 'afterfeather' "$scratch/semiplume/feather.obj"

# --- determinism and seeds ----------------------------------------------------
"$plume" generate "$presets/down.json" -o "$scratch/a" --format obj --seed 7 2>/dev/null
"$plume" generate "$presets/down.json" -o "$scratch/b" --format obj --seed 7 2>/dev/null
"$plume" generate "$presets/down.json" -o "$scratch/c" --format obj --seed 8 2>/dev/null
check "same seed, same OBJ" cmp -s "$scratch/a/feather.obj" "$scratch/b/feather.obj"
check "another seed, another down feather" bash -c "! cmp -s '$scratch/a/feather.obj' '$scratch/c/feather.obj'"

# --- grow -------------------------------------------------------------------------
"$plume" grow "$presets/contour.json" -o "$scratch/grow" --frames 5 --size 160x240 2>"$scratch/err.txt"
succeeded "grow succeeds"
check "grow: 5 frames x png, obj, usda" test "$(ls "$scratch/grow" | wc -l)" -eq 15
for i in 0000 0004; do
	for ext in png obj usda; do
		check "grow: frame-$i.$ext" test -s "$scratch/grow/frame-$i.$ext"
	done
done
"$plume" generate "$presets/contour.json" -o "$scratch/full" --format obj 2>/dev/null
check "grow: the last frame is the finished feather" cmp -s "$scratch/grow/frame-0004.obj" "$scratch/full/feather.obj"
check "grow: the first frame differs" bash -c "! cmp -s '$scratch/grow/frame-0000.obj' '$scratch/full/feather.obj'"
"$plume" grow "$presets/contour.json" -o "$scratch/grow1" --frames 1 --format obj 2>/dev/null
check "grow: one frame is the finished feather" cmp -s "$scratch/grow1/frame-0000.obj" "$scratch/full/feather.obj"
"$plume" grow "$presets/semiplume.json" -o "$scratch/grow-strips" --frames 2 --format png --style strips --size 100x100
check "grow --style strips" test -s "$scratch/grow-strips/frame-0001.png"
check "help grow" bash -c "'$plume' help grow | grep -q -- '--frames'"
# The frames are written by a background writer while the next frame grows: a file it
# cannot write (a 300 KiB file-size limit lets every file through but the last frame's
# 416 KB USD) fails the command, names the file in DIR, and keeps nothing.
expect_no_output "grow: a write the background writer cannot finish" 4 \
	"plume: $scratch/too-large/frame-0004.usda: write failed: File too large" "$scratch/too-large" \
	bash -c "trap '' XFSZ; ulimit -f 300; exec '$plume' grow '$presets/contour.json' -o '$scratch/too-large' --frames 5 --size 160x240"

# A model without the stages asked for is the command line's mistake (it read exit 1, a failed computation).
expect_no_output "grow: --unfurl on streit-heidrich" 2 "plume: grow: $presets/contour.json: the streit-heidrich model has growth stages but no unfurling" "$scratch/g1" \
	"$plume" grow "$presets/contour.json" -o "$scratch/g1" --frames 3 --unfurl
expect_no_output "grow: franco-walter" 2 "the franco-walter model has no growth or unfurling stages" "$scratch/g1b" \
	"$plume" grow "$source_dir/examples/franco-walter/hawk.json" -o "$scratch/g1b" --frames 3
expect_no_output "grow: an empty --format item" 2 "--format 'obj,' has an empty item" "$scratch/g1c" \
	"$plume" grow "$presets/contour.json" -o "$scratch/g1c" --frames 3 --format obj,
# glb frames, as generate writes them, and the help says so.
"$plume" grow "$presets/contour.json" -o "$scratch/g-glb" --frames 2 --format glb 2>/dev/null
check "grow --format glb" test -s "$scratch/g-glb/frame-0001.glb"
check "help grow lists glb" bash -c "'$plume' help grow | grep -q 'png,svg,pdf,obj,usda,json,glb'"
expect_no_output "grow: frames missing" 2 "missing --frames" "$scratch/g2" \
	"$plume" grow "$presets/contour.json" -o "$scratch/g2"
expect_no_output "grow: frames 0" 2 "--frames '0'" "$scratch/g3" \
	"$plume" grow "$presets/contour.json" -o "$scratch/g3" --frames 0
expect_no_output "grow: unknown style" 2 "--style 'paint'" "$scratch/g4" \
	"$plume" grow "$presets/contour.json" -o "$scratch/g4" --frames 2 --style paint

mkdir -p "$scratch/existing"
echo keep >"$scratch/existing/notes.txt"
"$plume" grow "$presets/contour.json" -o "$scratch/existing" --frames 11 >/dev/null 2>"$scratch/err.txt"
check "grow: 11 frames into an existing folder" test $? -eq 0
check "grow: every frame and the user's file are there" test "$(ls "$scratch/existing" | wc -l)" -eq 34
check "grow: the user's file is kept" test -s "$scratch/existing/notes.txt"
rm -rf "$scratch/existing" && mkdir -p "$scratch/existing" && echo keep >"$scratch/existing/notes.txt"
"$plume" grow "$presets/contour.json" -o "$scratch/existing" --frames 2 --format obj 2>/dev/null
check "grow: adds frames to an existing folder" test "$(ls "$scratch/existing" | wc -l)" -eq 3

# --- coat -------------------------------------------------------------------------
for spec in "$coats"/figure15-hexagonal.json "$coats"/figure16-poisson.json; do
	name=$(basename "$spec" .json)
	"$plume" coat "$spec" -o "$scratch/$name" --size 300x300 2>"$scratch/err.txt"
	succeeded "$name: coat succeeds"
	for file in coat.png coat.obj coat.usda; do
		check "$name: $file written" test -s "$scratch/$name/$file"
	done
done
check "figure 15: 64 feather objects" test "$(grep -c '^o feather_' "$scratch/figure15-hexagonal/coat.obj")" -eq 64
check "figure 15: USD curves" grep -q 'def BasisCurves "feather_00063"' "$scratch/figure15-hexagonal/coat.usda"
"$plume" coat "$coats/figure15-hexagonal.json" -o "$scratch/f15b" --size 300x300 2>/dev/null
check "coat: deterministic" cmp -s "$scratch/figure15-hexagonal/coat.obj" "$scratch/f15b/coat.obj"
# Progress only on a terminal: nothing in a file, a line with the count on a pseudo-terminal (script(1)).
check "coat: no progress when stderr is a file" test ! -s "$scratch/err.txt"
script -qec "'$plume' coat '$coats/figure15-hexagonal.json' -o '$scratch/f15t' --format obj >/dev/null" /dev/null >"$scratch/tty.txt"
check "coat: progress on a terminal" grep -q 'plume coat: 64/64 (100%), [0-9]* s elapsed' "$scratch/tty.txt"
"$plume" coat "$coats/figure15-hexagonal.json" -o "$scratch/f15s" --format png --style strips --size 200x200
check "coat --style strips" test -s "$scratch/f15s/coat.png"
check "help coat" bash -c "'$plume' help coat | grep -q 'COAT.json'"

# --- bad input: a clear message naming the file and key, nothing written -----------
bad=$scratch/bad
mkdir -p "$bad"
printf '{"model": "streit-heidrich", "key_barbs": [{"position": 0.7, "cvs": [[0,0,0],[1,0,0]]}, {"position": 0.3, "cvs": [[0,0,0],[1,0,0]]}]}' >"$bad/order.json"
expect_no_output "key barbs out of order" 3 'order.json: $.key_barbs[1].position is 0.3, below the key barb before it' \
	"$scratch/o1" "$plume" generate "$bad/order.json" -o "$scratch/o1"
printf '{"model": "streit-heidrich", "key_barbs": [{"position": 1.5, "cvs": [[0,0,0],[1,0,0]]}]}' >"$bad/outside.json"
expect_no_output "key barb outside [0, 1]" 3 '$.key_barbs[0].position is 1.5, allowed [0, 1]' "$scratch/o2" \
	"$plume" generate "$bad/outside.json" -o "$scratch/o2"
printf '{"model": "streit-heidrich", "key_barbs": [{"position": 0.5, "cvs": [[0,0,0]]}]}' >"$bad/one.json"
expect_no_output "one control vertex" 3 '$.key_barbs[0].cvs: a key barb needs 2 to 32 control vertices' "$scratch/o3" \
	"$plume" generate "$bad/one.json" -o "$scratch/o3"
printf '{"model": "streit-heidrich", "rachis_length": -0.1}' >"$bad/negative.json"
expect_no_output "negative length" 3 '$.rachis_length is -0.1, must be a positive length' "$scratch/o4" \
	"$plume" generate "$bad/negative.json" -o "$scratch/o4"
printf '{"model": "streit-heidrich", "barb_length_scan": {"image": "nothing.png", "base_px": [1, 50], "tip_px": [1, 2]}}' >"$bad/scan.json"
expect_no_output "unreadable scan" 4 'nothing.png: cannot read' "$scratch/o5" \
	"$plume" generate "$bad/scan.json" -o "$scratch/o5"
printf 'not a png' >"$bad/empty.png"
printf '{"model": "streit-heidrich", "barb_length_scan": {"image": "empty.png", "base_px": [1, 50], "tip_px": [1, 2]}}' >"$bad/scan2.json"
expect_no_output "undecodable scan" 3 'empty.png: not an image' "$scratch/o6" \
	"$plume" generate "$bad/scan2.json" -o "$scratch/o6"
expect_no_output "grow a bad spec" 3 '$.rachis_length is -0.1' "$scratch/o7" \
	"$plume" grow "$bad/negative.json" -o "$scratch/o7" --frames 3
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2\n' >"$bad/short.obj"
printf '{"model": "coat", "surface": {"type": "mesh", "obj": "short.obj"}, "follicles": {"layout": "poisson", "spacing": 0.1}, "key_feathers": [{"at": [0, 0, 0], "feather": "%s/key-plume.json"}]}' "$coats" >"$bad/coat-short.json"
expect_no_output "coat on an OBJ face of 2 corners" 3 'short.obj:6: face 2 has 2 corners; a face needs at least 3' \
	"$scratch/o8" "$plume" coat "$bad/coat-short.json" -o "$scratch/o8"
printf '{"model": "coat", "surface": {"type": "plane", "size": [0.05, 0.05]}, "follicles": {"spacing": 0}, "key_feathers": [{"at": [0, 0], "feather": "%s/key-plume.json"}]}' "$coats" >"$bad/coat-zero.json"
expect_no_output "coat with zero spacing" 3 '$.follicles.spacing: is 0' "$scratch/o9" \
	"$plume" coat "$bad/coat-zero.json" -o "$scratch/o9"
expect_no_output "coat given a feather spec" 3 'plume coat reads "model": "coat"' "$scratch/o10" \
	"$plume" coat "$presets/down.json" -o "$scratch/o10"
expect_no_output "coat: missing -o" 2 "missing -o DIR" "$scratch/o11" "$plume" coat "$coats/sphere.json"

finish
