#!/usr/bin/env bash
# Scenario tests of `plume generate`, `plume demo` and the help: what a user
# runs, what they get back, and that bad input changes nothing.
# Usage: generate.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"
presets=$source_dir/examples/franco-walter

no_leftovers() { # nothing but the expected entries in the scratch folder
	! ls -A "$scratch" | grep -q 'plume-staging'
}

# --- every preset renders and exports --------------------------------------
for spec in "$presets"/*.json; do
	name=$(basename "$spec" .json)
	out=$scratch/$name
	"$plume" generate "$spec" -o "$out" 2>"$scratch/err.txt"
	succeeded "$name: generate succeeds"
	for ext in png svg pdf obj usda json; do
		check "$name: feather.$ext written" test -s "$out/feather.$ext"
	done
	check "$name: PNG signature" bash -c "head -c 8 '$out/feather.png' | od -An -tx1 | grep -q '89 50 4e 47 0d 0a 1a 0a'"
	check "$name: PDF signature" bash -c "head -c 5 '$out/feather.pdf' | grep -q '%PDF-'"
	check "$name: SVG root" grep -q '<svg' "$out/feather.svg"
	check "$name: OBJ polylines" grep -q '^l ' "$out/feather.obj"
	check "$name: USD curves" grep -q 'BasisCurves' "$out/feather.usda"
	check "$name: only the six files (and the run manifest)" test "$(ls -A "$out" | grep -Fvx .plume-run | wc -l)" -eq 6
done

# --- determinism -----------------------------------------------------------
"$plume" generate "$presets/hawk.json" -o "$scratch/a" --seed 7 2>/dev/null
"$plume" generate "$presets/hawk.json" -o "$scratch/b" --seed 7 2>/dev/null
"$plume" generate "$presets/hawk.json" -o "$scratch/c" --seed 8 2>/dev/null
for ext in png svg pdf obj usda json; do
	check "same seed, same feather.$ext" cmp -s "$scratch/a/feather.$ext" "$scratch/b/feather.$ext"
done
check "another seed, another OBJ" bash -c "! cmp -s '$scratch/a/feather.obj' '$scratch/c/feather.obj'"

# --- options ----------------------------------------------------------------
"$plume" generate "$presets/blue.json" -o "$scratch/formats" --format obj,json --size 300x400
check "--format writes only those" test "$(ls "$scratch/formats" | tr '\n' ' ')" = "feather.json feather.obj "
"$plume" generate "$presets/blue.json" -o "$scratch/sized" --format png --size 300x400
check "--size sets the PNG size" bash -c "od -An -tu1 -j16 -N8 '$scratch/sized/feather.png' | tr -s ' ' | grep -q '^ 0 0 1 44 0 0 1 144$'"
# Without --size a picture is 1200 tall and as wide as the feather, at most 4096. A flat feather (barbs of
# 100 m across a 1e-6 m rachis) is 4096 wide: its width, 2e11 pixels, was cast to an int (256 wide).
cat >"$scratch/flat.json" <<'EOF'
{"model": "streit-heidrich", "calamus_length": 0, "rachis_length": 1e-6, "rachis_width": 1e-7,
 "rachis_side_curvature": 0, "rachis_front_curvature": 0, "barb_length": 100, "base_angle_deg": 90,
 "tip_angle_deg": 90, "spacing_base": 2e-7, "spacing_tip": 2e-7, "barb_width_base": 1e-9, "barb_width_tip": 1e-9,
 "key_barbs": [{"position": 0, "cvs": [[0, 0, 0], [0.5, 0, 0], [1, 0, 0]]},
               {"position": 1, "cvs": [[0, 0, 0], [0.5, 0, 0], [1, 0, 0]]}]}
EOF
"$plume" generate "$scratch/flat.json" -o "$scratch/flat" --format png 2>"$scratch/err.txt"
succeeded "a flat feather's picture"
check "a flat feather's picture is 4096 x 1200" bash -c "od -An -tu1 -j16 -N8 '$scratch/flat/feather.png' | tr -s ' ' | grep -q '^ 0 0 16 0 0 0 4 176$'"
"$plume" generate "$presets/hawk.json" -o "$scratch/textured" --format png --texture "$source_dir/examples/textures/bands.png"
check "--texture renders" test -s "$scratch/textured/feather.png"
check "textured differs from lines" bash -c "! cmp -s '$scratch/textured/feather.png' '$scratch/a/feather.png'"
"$plume" generate "$presets/hawk.json" -o "$scratch/existing" --format obj >/dev/null
echo keep >"$scratch/existing/notes.txt"
"$plume" generate "$presets/blue.json" -o "$scratch/existing" --format json
check "an existing folder keeps other files" test "$(cat "$scratch/existing/notes.txt")" = keep
check "an existing folder gains the new file" test -s "$scratch/existing/feather.json"

# --- bad input: message, exit code, nothing written ----------------------------
printf '{\n  "model": "franco-walter",\n  "seed": 3\n  "barb_samples": 10\n}\n' >"$scratch/syntax.json"
expect_failure "malformed JSON" 3 "syntax.json:4:" "$plume" generate "$scratch/syntax.json" -o "$scratch/x1"
check "malformed JSON writes nothing" test ! -e "$scratch/x1"
printf '{"model": "franco-walter", "segments": [{}, {"shape_varation": 0.2}]}' >"$scratch/key.json"
expect_failure "unknown key" 3 '$.segments[1].shape_varation: unknown key; did you mean "shape_variation"?' \
	"$plume" generate "$scratch/key.json" -o "$scratch/x2"
check "unknown key writes nothing" test ! -e "$scratch/x2"
printf '{"model": "franco-walter", "segments": [{"barb_count": 9000}, {}]}' >"$scratch/range.json"
expect_failure "out of range" 3 '$.segments[0].barb_count is 9000, allowed [0, 5000]' \
	"$plume" generate "$scratch/range.json" -o "$scratch/x3"
check "out of range writes nothing" test ! -e "$scratch/x3"
expect_failure "missing spec" 4 "no-such.json: cannot read: No such file or directory" \
	"$plume" generate "$scratch/no-such.json" -o "$scratch/x4"
check "missing spec writes nothing" test ! -e "$scratch/x4"
# A folder opens for reading: jansson read it as an empty text (exit 3, "/tmp:1:0: '[' or '{' expected").
mkdir -p "$scratch/a-folder"
expect_no_output "a folder for the spec" 4 "a-folder: cannot read: Is a directory" "$scratch/x4b" \
	"$plume" generate "$scratch/a-folder" -o "$scratch/x4b"
# -o DIR is created if missing, its missing parents too (it failed with exit 4, "No such file
# or directory"), and a run refused before it writes makes none of them.
"$plume" generate "$source_dir/examples/franco-walter/blue.json" -o "$scratch/new/deeper/out" --format obj >/dev/null 2>"$scratch/err.txt"
succeeded "-o in folders that do not exist yet"
check "-o in folders that do not exist yet: written" test -s "$scratch/new/deeper/out/feather.obj"
expect_no_output "-o in new folders, a bad spec" 3 "barb_count is 9000" "$scratch/new2" \
	"$plume" generate "$scratch/range.json" -o "$scratch/new2/deeper/out"
# An empty --format item is refused wherever it is ("png," once passed, "png,,obj" did not).
for list in png, ,png png,,obj; do
	expect_no_output "--format '$list'" 2 "--format '$list' has an empty item" "$scratch/x4c" \
		"$plume" generate "$presets/blue.json" -o "$scratch/x4c" --format "$list"
done
touch "$scratch/a-file"
expect_failure "unwritable output" 4 "cannot write the output folder" \
	"$plume" generate "$presets/blue.json" -o "$scratch/a-file/out"
expect_failure "output is a file" 4 "exists and is not a folder" "$plume" generate "$presets/blue.json" -o "$scratch/a-file"
cp -r "$scratch/a" "$scratch/kept"
expect_failure "bad spec into an existing folder" 3 "allowed [0, 5000]" \
	"$plume" generate "$scratch/range.json" -o "$scratch/kept"
check "an existing folder is untouched by a failure" diff -r "$scratch/a" "$scratch/kept"
expect_failure "missing texture" 4 "nope.png: cannot read" \
	"$plume" generate "$presets/blue.json" -o "$scratch/x5" --texture "$scratch/nope.png"
check "missing texture writes nothing" test ! -e "$scratch/x5"
expect_failure "texture that is not an image" 3 "not an image" \
	"$plume" generate "$presets/blue.json" -o "$scratch/x6" --texture "$scratch/key.json"
check "no staging folders left" no_leftovers

# --- usage --------------------------------------------------------------------
expect_failure "unknown format" 2 "unknown format 'gif'" "$plume" generate "$presets/blue.json" -o "$scratch/x7" --format png,gif
expect_failure "bad size" 2 "--size '12x5000'" "$plume" generate "$presets/blue.json" -o "$scratch/x7" --size 12x5000
expect_failure "bad seed" 2 "--seed 'abc'" "$plume" generate "$presets/blue.json" -o "$scratch/x7" --seed abc
expect_failure "missing -o" 2 "missing -o DIR" "$plume" generate "$presets/blue.json"
expect_failure "missing spec argument" 2 "missing SPEC.json" "$plume" generate -o "$scratch/x7"
expect_failure "unknown command" 2 "unknown command 'generat'" "$plume" generat
check "nothing written by usage errors" test ! -e "$scratch/x7"
check "--version" bash -c "'$plume' --version | grep -q '^plume [0-9]'"
check "--help lists commands" bash -c "'$plume' --help | grep -q generate"
check "help generate" bash -c "'$plume' help generate | grep -q -- '--seed'"
check "help demo" bash -c "'$plume' help demo | grep -q 'plume demo'"

# --- demo ---------------------------------------------------------------------
(cd "$scratch" && "$plume" demo >demo.txt)
check "demo succeeds" test $? -eq 0
for file in feather.png feather.svg feather.pdf feather.obj feather.usda feather.json feather-textured.png figure1-0000.png figure1-0050.png; do
	check "demo writes $file" test -s "$scratch/plume-demo/$file"
done
check "demo writes feather.glb" test -s "$scratch/plume-demo/feather.glb"
"$plume" demo -o "$scratch/demo2" >/dev/null
check "demo is deterministic" cmp -s "$scratch/plume-demo/feather.json" "$scratch/demo2/feather.json"

finish
