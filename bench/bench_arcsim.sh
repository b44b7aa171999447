#!/usr/bin/env bash
# Issue 15's per-step target against ARCSim's linearised implicit Euler step
# (docs/simulation.md, "Against issue 15's targets"). ARCSim is not a dependency of
# plume: build it yourself (we used the CMake port Wajov/arcsim-0.3.1, commit 0961778,
# Eigen's SimplicialLLT, its matrix filled from triplets instead of coeffRef, which
# otherwise took about 60 % of its run) and pass its source folder and binary.
#
# Writes two flat 20 x 5 cm sheets (376 and 1340 vertices, regular grids with
# alternating diagonals), runs ARCSim on each for 100 steps of 11 ms (two corners held,
# gravity, gray-interlock, remeshing, proximity and collision off, no frames written),
# interleaved with `bench_simulate` (Figure 1 at e = 5 and 2.5 mm, 374 and 1352
# vertices, to Table 6.1's tolerance), three rounds, one thread, and prints the CPU
# seconds of each and their ratio.
#
# Usage, from the repository root after building:
#   bench/bench_arcsim.sh ARCSIM_SOURCE_DIR [ARCSIM_BINARY] [PLUME_BUILD_DIR]
set -euo pipefail
source_dir=${1:?usage: bench_arcsim.sh ARCSIM_SOURCE_DIR [ARCSIM_BINARY] [PLUME_BUILD_DIR]}
arcsim=${2:-$source_dir/build/arcsim}
build=${3:-build}
material=$source_dir/materials/gray-interlock.json
for f in "$arcsim" "$material" "$build/bench/bench_simulate"; do
	[[ -e $f ]] || { echo "bench_arcsim: $f not found" >&2; exit 2; }
done
work=$(mktemp -d /tmp/plume-bench-arcsim-XXXXXX)
trap 'rm -rf "$work"' EXIT
cores=$(getconf _NPROCESSORS_ONLN)
export OMP_NUM_THREADS=1

# sheet NX NY: an OBJ of NX x NY vertices over 0.20 x 0.05 m, texture coordinates = (x, y)
# (ARCSim's material space), and its configuration holding vertices 0 and (NY - 1) NX.
sheet() {
	local nx=$1 ny=$2
	local name=$((nx * ny))
	awk -v nx="$nx" -v ny="$ny" 'BEGIN {
		for (j = 0; j < ny; ++j) for (i = 0; i < nx; ++i) printf "v %.9g %.9g 0\n", 0.2 * i / (nx - 1), 0.05 * j / (ny - 1)
		for (j = 0; j < ny; ++j) for (i = 0; i < nx; ++i) printf "vt %.9g %.9g\n", 0.2 * i / (nx - 1), 0.05 * j / (ny - 1)
		for (j = 0; j < ny - 1; ++j) for (i = 0; i < nx - 1; ++i) {
			a = j * nx + i + 1; b = a + 1; c = a + nx; d = c + 1
			if ((i + j) % 2 == 0) printf "f %d/%d %d/%d %d/%d\nf %d/%d %d/%d %d/%d\n", a, a, b, b, d, d, a, a, d, d, c, c
			else printf "f %d/%d %d/%d %d/%d\nf %d/%d %d/%d %d/%d\n", a, a, b, b, c, c, b, b, d, d, c, c
		}
	}' >"$work/sheet-$name.obj"
	# The port needs "motions" and "obstacles" present, and a remeshing size even with
	# remeshing off (without it the reference shapes are clamped to zero stiffness).
	cat >"$work/sheet-$name.json" <<JSON
{"frame_time": 0.011, "frame_steps": 1, "end_frame": 100,
 "cloths": [{"mesh": "$work/sheet-$name.obj", "materials": [{"data": "$material"}],
             "remeshing": {"size": [10e-3, 200e-3]}}],
 "motions": [], "obstacles": [], "handles": [{"nodes": [0, $(((ny - 1) * nx))]}],
 "gravity": [0, 0, -9.8], "disable": ["remeshing", "proximity", "collision"]}
JSON
}
sheet 47 8
sheet 67 20

cpu() { # CPU seconds (user + system) of a command
	/usr/bin/time -o "$work/time" -f "%U %S" "$@" >/dev/null 2>&1
	awk '{ printf "%.2f", $1 + $2 }' "$work/time"
}

echo "bench_arcsim: load before $(cut -d' ' -f1-3 /proc/loadavg); $cores cores; one thread; CPU seconds for 100 steps"
for round in 1 2 3; do
	small=$(cpu "$arcsim" simulateoffline "$work/sheet-376.json")
	large=$(cpu "$arcsim" simulateoffline "$work/sheet-1340.json")
	lines=$("$build/bench/bench_simulate" | grep '^figure1-anisotropic' | head -2)
	plume_small=$(sed -n 1p <<<"$lines" | grep -o '[0-9.]* s CPU' | cut -d' ' -f1)
	plume_large=$(sed -n 2p <<<"$lines" | grep -o '[0-9.]* s CPU' | cut -d' ' -f1)
	awk -v r="$round" -v a="$small" -v b="$large" -v p="$plume_small" -v q="$plume_large" 'BEGIN {
		printf "round %d: 376 vertices ARCSim %5.2f, plume %5.2f, ratio %.2f (target 0.5) | 1340 vertices ARCSim %5.2f, plume %5.2f, ratio %.2f (target 1.0)\n", r, a, p, p / a, b, q, q / b
	}'
done
