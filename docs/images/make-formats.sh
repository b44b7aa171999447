#!/usr/bin/env bash
# Regenerates the pictures of docs/formats.md with the built plume: the hawk,
# a coat and a simulation frame as Blender 3.4 renders the imported .glb
# (blender_render.py: Blender's glTF importer, Cycles on the CPU), and the
# browser viewer (`plume view`) in headless Chromium (tests/browser/view.mjs,
# which checks the page while it takes the screenshot).
# Usage: docs/images/make-formats.sh [PLUME] (default build/plume)
# Needs blender, chromium and the built viewer (make viewer).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
plume=${1:-$root/build/plume}
work=$(mktemp -d /tmp/plume-formats-images-XXXXXX)
trap 'rm -rf "$work"' EXIT

"$plume" generate "$root/examples/franco-walter/hawk.json" -o "$work/hawk" --format glb
"$plume" coat "$root/examples/coats/figure15-hexagonal.json" -o "$work/coat" --format glb >/dev/null
"$plume" simulate "$root/examples/scenes/figure6.5-pull.json" -o "$work/pull" >/dev/null

render() { # render IN.glb OUT.png OPTIONS...
	local in=$1 out=$2
	shift 2
	blender -b --factory-startup --python "$here/blender_render.py" -- "$in" "$out" "$@" >"$work/blender.log" 2>&1 ||
		{ tail -20 "$work/blender.log" >&2; exit 1; }
}
render "$work/hawk/feather.glb" "$here/formats-blender-hawk.png" --size 320x480 --samples 32
render "$work/coat/coat.glb" "$here/formats-blender-coat.png" --size 480x480 --view 20,50 --samples 32
render "$work/pull/sim.glb" "$here/formats-blender-sim.png" --size 480x480 --view 60,15 --frame last --samples 32

# The viewer: the simulation paused on its last frame (view.mjs moves the slider there).
"$plume" view "$work/pull" >/dev/null
node "$root/tests/browser/view.mjs" --screenshot "$here/formats-viewer-sim.png" "$work/pull/view/index.html:animated"
"$plume" view "$work/hawk" >/dev/null
node "$root/tests/browser/view.mjs" --screenshot "$here/formats-viewer-hawk.png" "$work/hawk/view/index.html"
