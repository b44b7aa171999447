#!/usr/bin/env bash
# Re-makes the lab's pictures in docs/images (docs/lab.md) with plume itself.
# Run from the repository root after `make`. The studies take minutes (the
# angle sweep the longest); pass study names to re-make only those:
#   docs/images/make-lab.sh traction size conditioning locking angles bending
set -euo pipefail
plume=${PLUME:-build/plume}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
what=${*:-traction size conditioning locking angles bending}
for item in $what; do
	case $item in
	traction)
		for name in transverse-mesoscale longitudinal-mesoscale tilted-mesoscale tilted-macroscale; do
			"$plume" lab traction "examples/lab/$name.json" -o "$tmp/$name"
			cp "$tmp/$name/traction.png" "docs/images/lab-traction-$name.png"
		done
		;;
	*)
		"$plume" lab study "$item" -o "$tmp/$item"
		cp "$tmp/$item/$item.png" "docs/images/lab-study-$item.png"
		;;
	esac
done
