#!/usr/bin/env bash
# Re-makes the mesh pictures in docs/images (docs/meshing.md) with `plume mesh`.
# Run from the repository root after building.
set -euo pipefail
plume=${PLUME:-build/plume}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for name in hawk peacock; do
	"$plume" mesh "examples/franco-walter/$name.json" -o "$tmp/$name" --size 300x900
	cp "$tmp/$name/mesh.png" "docs/images/mesh-$name.png"
done
"$plume" mesh examples/franco-walter/hawk.json -o "$tmp/fine" --edge-length 0.0025 --size 300x900
cp "$tmp/fine/mesh.png" docs/images/mesh-hawk-fine.png
"$plume" mesh examples/meshes/guides.json -o "$tmp/guides" --size 400x900
cp "$tmp/guides/mesh.png" docs/images/mesh-guides.png
