#!/usr/bin/env bash
# Sweep scheduling: 16 short Figure 1 simulations (3 steps each) run directly one
# after the other, then as `plume sweep` with -j 1 and -j 2, and under mpirun -n 2
# and -n 3 (rank 0 schedules, so -n 2 has one worker and -n 3 two). Prints the wall
# time of each, the speed-up over -j 1 and the overhead per run of the sweep over the
# direct loop. CMake copies this script to build/bench/ (so `make bench` runs it).
# Usage: bench_sweep.sh [PLUME_BINARY] [SOURCE_DIR]
set -u
here=$(cd "$(dirname "$0")" && pwd)
plume=${1:-$here/../plume}
source_dir=${2:-@PROJECT_SOURCE_DIR@}
work=$(mktemp -d /tmp/plume-bench-sweep-XXXXXX)
trap 'rm -rf "$work"' EXIT
runs=16
sed 's/"duration": 1.1/"duration": 0.033/' "$source_dir/examples/scenes/figure1-anisotropic.json" |
	sed "s|\"../franco-walter/hawk.json\"|\"$source_dir/examples/franco-walter/hawk.json\"|" >"$work/scene.json"
cat >"$work/sweep.json" <<JSON
{"command": "simulate", "spec": "scene.json",
 "parameters": [{"path": "\$.gravity[0]", "grid": {"from": -9.661, "to": -4.0, "count": $runs}}],
 "outputs": ["rachis_tip_deflection", "newton_iterations"]}
JSON
now() { date +%s.%N; }
calc() { awk "BEGIN { print $1 }"; }
echo "bench_sweep: $runs runs of a 3-step Figure 1 simulation; load before: $(cut -d' ' -f1-3 /proc/loadavg); $(nproc) cores"
start=$(now)
for i in $(seq $runs); do
	OMP_NUM_THREADS=1 "$plume" simulate "$work/scene.json" -o "$work/direct-$i" >/dev/null 2>&1
done
direct=$(calc "$(now) - $start")
printf '  %-22s %7.2f s\n' "direct loop" "$direct"
run_case() { # run_case NAME COMMAND...
	local name=$1
	shift
	local t0
	t0=$(now)
	"$@" >/dev/null 2>&1 || echo "  $name failed"
	local wall
	wall=$(calc "$(now) - $t0")
	eval "wall_$(echo "$name" | tr -c 'a-z0-9\n' '_')=$wall"
	printf '  %-22s %7.2f s   speed-up %.2f   overhead per run %+.3f s\n' "$name" "$wall" \
		"$(calc "${wall_sweep__j_1:-$wall} / $wall")" "$(calc "($wall - $direct) / $runs")"
}
run_case "sweep -j 1" "$plume" sweep "$work/sweep.json" -o "$work/j1" -j 1
run_case "sweep -j 2" "$plume" sweep "$work/sweep.json" -o "$work/j2" -j 2
cmp -s "$work/j1/results.csv" "$work/j2/results.csv" || echo "  results.csv differs between -j 1 and -j 2"
if "$plume" help sweep | grep -q 'This plume was built with MPI' && command -v mpirun >/dev/null; then
	export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
	for n in 2 3; do
		run_case "mpirun -n $n" mpirun --allow-run-as-root --oversubscribe -n $n "$plume" sweep "$work/sweep.json" -o "$work/mpi$n"
		cmp -s "$work/j1/results.csv" "$work/mpi$n/results.csv" || echo "  results.csv differs under mpirun -n $n"
	done
else
	echo "  (MPI: this plume was built without MPI)"
fi
echo "  load after: $(cut -d' ' -f1-3 /proc/loadavg)"
