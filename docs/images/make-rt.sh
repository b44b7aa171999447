#!/usr/bin/env bash
# Re-makes the ray-traced pictures docs/images/rt-*.png with `plume render`. Run from the repository root
# after building (PLUME=path/to/plume to use another binary). Takes about a minute on two cores.
set -euo pipefail
plume=${PLUME:-build/plume}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# A still of each Franco–Walter preset, from the front on a table.
for name in hawk blue peacock figure6a figure6b filoplume; do
	"$plume" render "examples/franco-walter/$name.json" -o "$tmp/$name" -c examples/cameras/front.json --size 400x600
	cp "$tmp/$name/feather.png" "docs/images/rt-$name.png"
done
# The hawk coloured by plume's banded texture (Franco & Walter 4.4 mapping).
"$plume" render examples/franco-walter/hawk.json -o "$tmp/textured" -c examples/cameras/front.json --size 400x600 \
	--texture examples/textures/bands.png
cp "$tmp/textured/feather.png" docs/images/rt-hawk-textured.png
# Light through the vane, a three-quarter view, a close-up of individual barbs.
"$plume" render examples/franco-walter/hawk.json -o "$tmp/backlit" -c examples/cameras/backlit.json --size 400x600 \
	--texture examples/textures/bands.png
cp "$tmp/backlit/feather.png" docs/images/rt-hawk-backlit.png
"$plume" render examples/franco-walter/hawk.json -o "$tmp/quarter" -c examples/cameras/three-quarter.json --size 600x450
cp "$tmp/quarter/feather.png" docs/images/rt-hawk-three-quarter.png
"$plume" render examples/franco-walter/hawk.json -o "$tmp/closeup" -c examples/cameras/closeup.json --size 600x400 \
	--texture examples/textures/bands.png
cp "$tmp/closeup/feather.png" docs/images/rt-hawk-closeup.png
# A turntable of four views.
"$plume" render examples/franco-walter/peacock.json -o "$tmp/turn" -c examples/cameras/turntable.json --size 240x360 \
	--turntable 4
for i in 0 1 2 3; do
	cp "$tmp/turn/turntable/000$i.png" "docs/images/rt-turntable-$i.png"
done
# A coat (Streit & Heidrich 4.4) on a sphere: every feather plus the surface.
"$plume" render examples/coats/sphere.json -o "$tmp/coat" -c examples/cameras/coat.json --size 600x450
cp "$tmp/coat/feather.png" docs/images/rt-coat-sphere.png
# The Figure 1 scenario (Jouve et al. 2024): simulate, then carry the hawk's barbs through the frames and
# render five of them side by side. A simulation that stops early keeps its frames (exit 1), which are
# rendered all the same. About ten minutes, most of it the simulation.
"$plume" simulate examples/scenes/figure1-anisotropic.json -o "$tmp/figure1" || test -d "$tmp/figure1/frames"
"$plume" render "$tmp/figure1" -o "$tmp/figure1-render" -c examples/cameras/front.json --size 200x300 --spp 4 \
	--strip 5 -f png
cp "$tmp/figure1-render/strip.png" docs/images/rt-figure1-strip.png
# Barbules at close range (Zhang & Kanai's Figure 11 feather has them).
"$plume" render examples/zhang-kanai/figure11-expansion.json -o "$tmp/barbules" -c examples/cameras/barbules.json
cp "$tmp/barbules/feather.png" docs/images/rt-barbules.png
