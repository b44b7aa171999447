#!/usr/bin/env bash
# Re-makes the Streit–Heidrich and coat pictures in docs/images with plume itself (docs/spec-streit-heidrich.md,
# docs/coats.md). Run from the repository root after `make`; PLUME names another binary.
set -euo pipefail
plume=${PLUME:-build/plume}
root=$(pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# Each preset (line style).
for name in down semiplume contour flight filoplume bristle peacock; do
	"$plume" generate "examples/streit-heidrich/$name.json" -o "$tmp/$name" --format png --size 300x600
	cp "$tmp/$name/feather.png" "docs/images/sh-$name.png"
done

# The semiplume and its afterfeather as triangle strips (4.3.1, Figure 11).
"$plume" grow examples/streit-heidrich/semiplume.json -o "$tmp/strips" --frames 1 --format png --size 300x600 \
	--style strips
cp "$tmp/strips/frame-0000.png" docs/images/sh-semiplume-strips.png

# A type continuum down -> semiplume -> contour (4.2.3, Figure 5): five blends along the three feathers.
for i in 0 1 2 3 4; do
	t=$(awk "BEGIN { print $i / 4 }")
	printf '{"model": "streit-heidrich", "seed": 1, "blend": {"feathers": ["%s", "%s", "%s"], "t": %s}}\n' \
		"$root/examples/streit-heidrich/down.json" "$root/examples/streit-heidrich/semiplume.json" \
		"$root/examples/streit-heidrich/contour.json" "$t" >"$tmp/continuum-$i.json"
	"$plume" generate "$tmp/continuum-$i.json" -o "$tmp/continuum-$i" --format png --size 200x400
	cp "$tmp/continuum-$i/feather.png" "docs/images/sh-continuum-$i.png"
done

# A growth sequence (4.2.4, Figures 6 and 7): stages 0.25, 0.5, 0.75, 0.9 and 1 of the contour feather, in one
# framing. grow writes evenly spaced stages, so 21 frames give stage i / 20.
"$plume" grow examples/streit-heidrich/contour.json -o "$tmp/growth" --frames 21 --format png --size 200x400
for frame in 05 10 15 18 20; do
	cp "$tmp/growth/frame-00$frame.png" "docs/images/sh-growth-$frame.png"
done

# Coats (4.4, Figures 15 and 16) and a coat on a sphere.
"$plume" coat examples/coats/figure15-hexagonal.json -o "$tmp/figure15" --format png --size 600x600 --style strips
cp "$tmp/figure15/coat.png" docs/images/coat-figure15.png
"$plume" coat examples/coats/figure16-poisson.json -o "$tmp/figure16" --format png --size 600x500 --style strips
cp "$tmp/figure16/coat.png" docs/images/coat-figure16.png
"$plume" coat examples/coats/sphere.json -o "$tmp/sphere" --format png --size 600x600 --style strips
cp "$tmp/sphere/coat.png" docs/images/coat-sphere.png
