#!/usr/bin/env bash
# Re-makes the Zhang–Kanai pictures in docs/images (zk-*.png) with plume itself.
# Run from the repository root after `make`; PLUME=path/to/plume to use another build.
set -euo pipefail
plume=${PLUME:-build/plume}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for spec in examples/zhang-kanai/*.json; do
	name=$(basename "$spec" .json)
	"$plume" generate "$spec" -o "$tmp/$name" --format png --size 300x600 >/dev/null
	cp "$tmp/$name/feather.png" "docs/images/zk-$name.png"
done
# Figure 8: the growth sequence, four frames over t_curr, and the unfurling over w.
"$plume" grow examples/zhang-kanai/figure8-contour.json -o "$tmp/grow" --frames 4 --format png --size 200x400
for i in 0 1 2 3; do
	cp "$tmp/grow/frame-000$i.png" "docs/images/zk-figure8-growth-$i.png"
done
"$plume" grow examples/zhang-kanai/figure8-contour.json -o "$tmp/unfurl" --frames 3 --unfurl --format png \
	--size 200x400
for i in 0 1 2; do
	cp "$tmp/unfurl/frame-000$i.png" "docs/images/zk-figure8-unfurl-$i.png"
done
