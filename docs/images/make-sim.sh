#!/usr/bin/env bash
# Regenerates the simulation pictures of docs/simulation.md with the built plume.
# Usage: docs/images/make-sim.sh [PLUME] (default build/plume)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
plume=${1:-$root/build/plume}
work=$(mktemp -d /tmp/plume-sim-images-XXXXXX)
trap 'rm -rf "$work"' EXIT

# Figure 1: anisotropic and isotropic, seen face on (the motion is in the vane's plane).
for model in anisotropic isotropic; do
	"$plume" simulate "$root/examples/scenes/figure1-$model.json" -o "$work/$model" --png --size 360x560 --view 0,0 >/dev/null
	for frame in 0000 0050 0100; do
		cp "$work/$model/frames/$frame.png" "$here/sim-figure1-$model-$frame.png"
	done
done
# Thesis Figure 6.5: the rachis tip pulled out of the vane's plane, seen from three-quarters.
"$plume" simulate "$root/examples/scenes/figure6.5-pull.json" -o "$work/pull" --png --size 480x480 --view 60,15 >/dev/null
for frame in 0000 0050 0100; do
	cp "$work/pull/frames/$frame.png" "$here/sim-figure6.5-$frame.png"
done
# A falling feather, followed by the camera.
"$plume" simulate "$root/examples/scenes/falling.json" -o "$work/falling" --png --size 400x400 --view 30,35 >/dev/null
for frame in 0000 0023 0045; do
	cp "$work/falling/frames/$frame.png" "$here/sim-falling-$frame.png"
done
