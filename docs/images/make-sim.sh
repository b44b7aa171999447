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
# Figure 1 (b) and (c) ray-traced: both runs at the same five frames (t = 0, 0.275, ... 1.1 s) through
# one fixed camera, barbs and all.
for model in anisotropic isotropic; do
	"$plume" render "$work/$model" -o "$work/$model-render" -c "$here/figure1-camera.json" --strip 5 -f png >/dev/null
	cp "$work/$model-render/strip.png" "$here/rt-figure1-$model-strip.png"
done
# Figure 1's wrinkles under refinement: the anisotropic run on finer meshes (about 4 minutes on
# one core at 1.25 mm), the out-of-plane displacement of the last frame over the rest shell.
for e in 0.0025 0.00175 0.00125; do
	sed -e "s#\"../franco-walter/hawk.json\"#\"$root/examples/franco-walter/hawk.json\"#" \
	    -e "s#\"edge_length\": 0.005#\"edge_length\": $e#" \
	    "$root/examples/scenes/figure1-anisotropic.json" >"$work/figure1-$e.json"
	"$plume" simulate "$work/figure1-$e.json" -o "$work/anisotropic-$e" --frames-every 1000 >/dev/null
done
/usr/bin/python3 "$here/plot_wrinkles.py" "$here/figure1-wrinkles.png" "$work/anisotropic" "e = 5 mm" \
	"$work/anisotropic-0.0025" "e = 2.5 mm" "$work/anisotropic-0.00175" "e = 1.75 mm" "$work/anisotropic-0.00125" "e = 1.25 mm"
# Thesis Figure 6.5: the rachis tip pulled out of the vane's plane, seen from three-quarters.
"$plume" simulate "$root/examples/scenes/figure6.5-pull.json" -o "$work/pull" --png --size 480x480 --view 60,15 >/dev/null
for frame in 0000 0050 0100; do
	cp "$work/pull/frames/$frame.png" "$here/sim-figure6.5-$frame.png"
done
# A falling feather in air, followed by the camera: every 0.44 s (frames are every 2 steps).
"$plume" simulate "$root/examples/scenes/falling.json" -o "$work/falling" --png --size 320x320 --view 30,35 >/dev/null
for frame in 0000 0020 0040 0060 0080; do
	cp "$work/falling/frames/$frame.png" "$here/sim-falling-$frame.png"
done
# The swing (BDF2), ray-traced from the side by plume render: every 0.22 s (frames are every
# 5 steps), a quarter of its 0.86 s period, gathered into a folder of their own for --strip.
"$plume" simulate "$root/examples/scenes/swing.json" -o "$work/swing" >/dev/null
mkdir -p "$work/swing-strip/frames"
cp "$work/swing/mesh.obj" "$work/swing/feather.json" "$work/swing/feather.bin" "$work/swing-strip/"
k=0
for frame in 0000 0004 0008 0012 0016; do
	cp "$work/swing/frames/$frame.obj" "$work/swing-strip/frames/$(printf %04d $k).obj"
	k=$((k + 1))
done
"$plume" render "$work/swing-strip" -o "$work/swing-render" -c "$here/sim-side-camera.json" --strip 5 -f png >/dev/null
cp "$work/swing-render/strip.png" "$here/sim-swing-strip.png"
