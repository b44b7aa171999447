#!/usr/bin/env bash
# Re-makes the pictures in docs/images with plume itself. Run from the repository root after `make`.
set -euo pipefail
plume=${PLUME:-build/plume}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for name in hawk blue peacock figure6a figure6b filoplume; do
	"$plume" generate "examples/franco-walter/$name.json" -o "$tmp/$name" --format png --size 300x600
	cp "$tmp/$name/feather.png" "docs/images/fw-$name.png"
done
"$plume" generate examples/franco-walter/hawk.json -o "$tmp/textured" --format png --size 300x600 \
	--texture examples/textures/bands.png
cp "$tmp/textured/feather.png" docs/images/fw-hawk-textured.png
