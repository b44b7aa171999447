#!/usr/bin/env bash
# Scenario tests of `plume coat`: a coat whose surface is seen from behind
# still writes its (empty) picture, and says why it is empty.
# Usage: coat.sh PLUME_BINARY SOURCE_DIR
# (Each status is saved before `check`: a $(...) in the check's name would reset $?.)
source "$(dirname "$0")/../cli_support.sh" "$@"
examples="$source_dir/examples"
cp "$examples"/coats/key-*.json "$scratch/"
# Every run is capped: a regression must fail here, not take the machine's memory.
capped() { (ulimit -v 6000000 && timeout 120 "$@"); }

# --- a surface seen from behind: no follicle faces +z ----------------------------------------------
printf 'v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nf 1 3 2\n' >"$scratch/flipped.obj"
printf '{"model": "coat", "surface": {"type": "mesh", "obj": "flipped.obj"}, "follicles": {"layout": "poisson", "spacing": 0.01}, "key_feathers": [{"at": [0, 0, 0], "feather": "key-contour.json"}]}' >"$scratch/flipped.json"
capped "$plume" coat "$scratch/flipped.json" -o "$scratch/o8" >/dev/null 2>"$scratch/err.txt"
succeeded "coat of a surface seen from behind"
check "its picture, obj and usda written" test -s "$scratch/o8/coat.png" -a -s "$scratch/o8/coat.obj" -a -s "$scratch/o8/coat.usda"
check "a warning says why the picture is empty ($(cat "$scratch/err.txt"))" \
	grep -qF 'warning: no follicle faces +z' "$scratch/err.txt"
capped "$plume" coat "$scratch/flipped.json" -o "$scratch/o9" --format obj,glb >/dev/null 2>"$scratch/err.txt"
succeeded "the same without a picture"
check "no warning without a picture" test ! -s "$scratch/err.txt"
finish
