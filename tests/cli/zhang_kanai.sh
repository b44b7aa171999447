#!/usr/bin/env bash
# Scenario tests of the zhang-kanai model through `plume generate` and
# `plume grow`: every example renders and exports, the summary reports
# snapping, growth and unfurling sequences, determinism, and bad specs fail
# with a clear message and write nothing.
# Usage: zhang_kanai.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"
examples=$source_dir/examples/zhang-kanai

# --- every example generates, with a summary --------------------------------
for spec in "$examples"/*.json; do
	name=$(basename "$spec" .json)
	out=$scratch/$name
	"$plume" generate "$spec" -o "$out" --format png,obj,usda,json --size 200x400 >"$scratch/stdout.txt" 2>"$scratch/err.txt"
	succeeded "$name: generate succeeds"
	for ext in png obj usda json; do
		check "$name: feather.$ext written" test -s "$out/feather.$ext"
	done
	check "$name: summary.json written" grep -q '"model": "zhang-kanai"' "$out/summary.json"
	check "$name: summary printed" grep -q '^summary: {"model": "zhang-kanai"' "$scratch/stdout.txt"
	check "$name: OBJ polylines" grep -q '^l ' "$out/feather.obj"
done
check "expansion snaps every barb of figure 11" grep -q '"unsnapped": 0,' "$scratch/figure11-expansion/summary.json"
check "expansion keeps barbules in the USD" grep -q 'barbules' "$scratch/figure11-expansion/feather.usda"
check "the crest stops before the BGZ" grep -q '"emitter_clamp_time": {"left": null, "right": null}' \
	"$scratch/figure13-crest/summary.json"

# --- barbs that cannot snap are reported, never silently -------------------
printf '{"model": "zhang-kanai", "barb_count": 110, "expansion": true, "ridge_height": 0.00001}\n' >"$scratch/flaw.json"
"$plume" generate "$scratch/flaw.json" -o "$scratch/flaw" --format json >"$scratch/stdout.txt" 2>&1
check "flaw: generate succeeds" test $? -eq 0
check "flaw: unsnapped barbs counted" grep -q '"unsnapped": 21[0-9]' "$scratch/flaw/summary.json"
check "flaw: unsnapped barbs listed" grep -q '"unsnapped_barbs": \[{"barb": ' "$scratch/flaw/summary.json"
check "flaw: printed" grep -q '"unsnapped": 21[0-9]' "$scratch/stdout.txt"

# --- determinism -------------------------------------------------------------
"$plume" generate "$examples/figure11-expansion.json" -o "$scratch/a" --format obj,json >/dev/null 2>&1
"$plume" generate "$examples/figure11-expansion.json" -o "$scratch/b" --format obj,json >/dev/null 2>&1
for name in feather.obj feather.json summary.json; do
	check "same spec, same $name" cmp -s "$scratch/a/$name" "$scratch/b/$name"
done

# --- growth and unfurling sequences through plume grow -----------------------
"$plume" grow "$examples/figure8-contour.json" -o "$scratch/grow" --frames 4 --format png,obj --size 200x400 \
	>/dev/null 2>"$scratch/err.txt"
succeeded "grow: succeeds"
check "grow: four PNG frames" test "$(ls "$scratch/grow"/frame-*.png 2>/dev/null | wc -l)" -eq 4
barbs() { grep -c '^l ' "$1"; }
if [ -s "$scratch/grow/frame-0003.obj" ]; then
	check "grow: the feather grows frame by frame" test "$(barbs "$scratch/grow/frame-0001.obj")" -lt \
		"$(barbs "$scratch/grow/frame-0002.obj")"
	"$plume" generate "$examples/figure8-contour.json" -o "$scratch/final" --format obj >/dev/null 2>&1
	check "grow: the last frame is the finished feather" cmp -s "$scratch/grow/frame-0003.obj" "$scratch/final/feather.obj"
fi
"$plume" grow "$examples/figure8-contour.json" -o "$scratch/unfurl" --frames 3 --unfurl --format obj >/dev/null 2>"$scratch/err.txt"
succeeded "grow --unfurl: succeeds"
if [ -s "$scratch/unfurl/frame-0000.obj" ] && [ -s "$scratch/unfurl/frame-0002.obj" ]; then
	check "grow --unfurl: frames differ" bash -c "! cmp -s '$scratch/unfurl/frame-0000.obj' '$scratch/unfurl/frame-0002.obj'"
	check "grow --unfurl: same barbs in every frame" test "$(barbs "$scratch/unfurl/frame-0000.obj")" -eq \
		"$(barbs "$scratch/unfurl/frame-0002.obj")"
fi

# --- bad input: a clear message, exit 3, nothing written ---------------------
bad() { # bad NAME FRAGMENT JSON-FRAGMENT
	local name=$1 fragment=$2 body=$3
	printf '{"model": "zhang-kanai", %s}\n' "$body" >"$scratch/$name.json"
	"$plume" generate "$scratch/$name.json" -o "$scratch/out-$name" >"$scratch/out.txt" 2>"$scratch/err.txt"
	local code=$?
	check "$name: exit 3 (got $code)" test "$code" -eq 3
	if grep -qF -- "$fragment" "$scratch/err.txt" && grep -qF -- "$scratch/$name.json" "$scratch/err.txt"; then
		passed=$((passed + 1))
	else
		failed=$((failed + 1))
		echo "FAIL: $name: stderr lacks the file and '$fragment': $(cat "$scratch/err.txt")" >&2
	fi
	check "$name: nothing written" test ! -e "$scratch/out-$name"
}
bad overlap '$.posterior <0.99, 0.49> and $.anterior <0.98, 0.02> overlap' '"posterior": [0.99, 0.49]'
bad crossed 'overlap or are out of order' '"posterior": [0.4, 0.6]'
bad zero-speed '$.emitter_speed[1]: speed 0 must be positive' '"emitter_speed": [[0, 0.01], [0.5, 0], [1, 0.01]]'
bad negative-speed '$.barb_speed: speed -0.002 must be positive' '"barb_speed": -0.002'
bad zero-growth '$.growth_speed is 0, must be a positive speed' '"growth_speed": 0'
bad downsample '$.downsample is 0, allowed [1, 1000]' '"downsample": 0'
bad barb-count '$.barb_count is 0, allowed [1, 5000]' '"barb_count": 0'
bad collar '$.collar.points: has 3 control points' '"collar": {"points": [[0, -0.01], [0.01, 0], [0, 0.01]]}'
bad unknown-key 'did you mean "barb_speed"' '"barb_sped": 0.01'
bad angle '$.theta_distal_deg is 0, allowed (0, 180)' '"theta_distal_deg": 0'
# Splits that bend nothing were ignored: the feather came out as without them.
bad split-no-barb '$.splits[0].barb is 500, allowed [0, 99]' '"expansion": true, "splits": [{"side": "right", "barb": 500}]'
bad split-no-expansion '$.splits: a split bends a barb before snapping' '"splits": [{"side": "right", "barb": 60}]'
bad split-barb-missing '$.splits[0].barb: missing; a split names its barb' '"expansion": true, "splits": [{"at": 0.3}]'
# An emitter too slow for the step once wrote "v 0 inf 0" and "v 0 -nan 0" with exit 0 (1e-9: no barbs).
bad slow-emitter '$.emitter_speed: the growth does not end: the left emitter needs more than' '"emitter_speed": 1e-8'
bad slower-emitter '$.emitter_speed: the growth does not end' '"emitter_speed": 1e-9'
bad fast-emitter 'the left vane emits more than 200000 barbs' '"emitter_speed": 100'
printf '{"model": "zhang-kanai", "emitter_speed": 1e-8}\n' >"$scratch/slow.json"
"$plume" generate "$scratch/slow.json" -o "$scratch/out-slow" --format obj,usda,glb,json >/dev/null 2>&1
code=$?
check "slow emitter, every format: exit 3 (got $code)" test "$code" -eq 3
check "slow emitter, every format: nothing written" test ! -e "$scratch/out-slow"

finish
