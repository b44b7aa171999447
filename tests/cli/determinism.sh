#!/usr/bin/env bash
# Determinism pinned (issue 17): the same input and seed give the same bytes
# under OMP_NUM_THREADS=1, 2 and 4, in separate processes, for generate (each
# model), coat, a short simulation and a small ray-traced render; generate and
# coat are also pinned to golden SHA-256 hashes, so a change of their output
# shows up as a failing test (update the hash with the commit that means it).
# The simulation and the render are compared across thread counts only: their
# bits may legitimately differ between CPUs (Embree picks its kernels by ISA).
# Usage: determinism.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"
examples=$source_dir/examples

/usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1])); d['feather'] = sys.argv[2]; d['mesh']['edge_length'] = 0.02; d['duration'] = 0.033; json.dump(d, open(sys.argv[3], 'w'))" \
	"$examples/scenes/falling.json" "$examples/franco-walter/filoplume.json" "$scratch/scene.json"

for n in 1 2 4; do
	out=$scratch/t$n
	mkdir -p "$out"
	export OMP_NUM_THREADS=$n
	"$plume" generate "$examples/franco-walter/hawk.json" -o "$out/fw" --format json,obj >/dev/null 2>&1
	"$plume" generate "$examples/streit-heidrich/contour.json" -o "$out/sh" --format json >/dev/null 2>&1
	"$plume" generate "$examples/zhang-kanai/figure8-contour.json" -o "$out/zk" --format json >/dev/null 2>&1
	"$plume" coat "$examples/coats/figure15-hexagonal.json" -o "$out/coat" --format obj >/dev/null 2>&1
	"$plume" simulate "$scratch/scene.json" -o "$out/sim" >/dev/null 2>&1
	"$plume" render "$examples/franco-walter/filoplume.json" -o "$out/rt" --spp 2 --size 48x64 >/dev/null 2>&1
	unset OMP_NUM_THREADS
done

hash_of() { sha256sum "$1" 2>/dev/null | cut -d' ' -f1; }
golden() { # golden NAME FILE HASH
	for n in 1 2 4; do
		local got
		got=$(hash_of "$scratch/t$n/$2")
		check "$1 under $n threads: golden hash (got ${got:-nothing})" test "$got" = "$3"
	done
}
golden "franco-walter hawk JSON" fw/feather.json c2b283408fac4e0106498eeb161be52a7b404dc91df3c56438fe6c42ca7b3879
golden "franco-walter hawk OBJ" fw/feather.obj af6c0263b9606144522b9c4ed4492f86a5f05ba5f2f24de0fc490ed99cbd9f66
golden "streit-heidrich contour" sh/feather.json 47d44f0f1b197bf36bd8349ed2a449c95ca8af107fd29b996f4dfdb64845b3ed
golden "zhang-kanai figure 8" zk/feather.json 28a3894c55f224b3205b38616b61fe020852c119ea2de1230d70ddda81472e5f
golden "coat figure 15" coat/coat.obj 9cbab708ee7bf2f503c2aa348907b90c3b1769f71d80df5ad831156adb4e5ddb

for file in sim/mesh.obj sim/feather.json sim/frames/0000.obj sim/frames/0001.obj sim/frames/0002.obj \
	sim/stats.csv rt/feather.png; do
	check "$file written" test -s "$scratch/t1/$file"
	for n in 2 4; do
		if [ "$file" = sim/stats.csv ]; then # every column but the sixth, wall time
			check "$file: same as 1 thread under $n" \
				cmp -s <(cut -d, -f1-5,7- "$scratch/t1/$file") <(cut -d, -f1-5,7- "$scratch/t$n/$file")
		else
			check "$file: same bytes under 1 and $n threads" cmp -s "$scratch/t1/$file" "$scratch/t$n/$file"
		fi
	done
done

finish
