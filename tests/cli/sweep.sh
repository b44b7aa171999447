#!/usr/bin/env bash
# Scenario tests of `plume sweep`: a grid x random sweep of lab traction tests gives
# the closed form of thesis eq. 5.2 in every row and the same results.csv bytes with
# -j 1, -j 2 and under mpirun -n 2 and -n 3; failing runs are recorded; a sweep whose
# run or whole job is SIGKILLed resumes to the uninterrupted bytes; random samples are
# reproducible and follow their distributions; bad sweeps write nothing; the output
# keys the sweep accepts are exactly the numbers and booleans a real run writes; files
# of the user's in DIR (DIR/runs included) are never removed or replaced.
# Usage: sweep.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"
py=/usr/bin/python3

# --- a small sweep: 2 grid values x 3 log-normal samples of E_B --------------
cat >"$scratch/grid.json" <<'EOF'
{
  "command": "lab traction",
  "spec": {"sample": {"width": 0.004, "height": 0.0052, "barb_angle_deg": 0, "elements": 200},
           "material": {"model": "mesoscale", "E_B": 2.57e9, "E_b": 3.92e4, "barb_fraction": 0.14, "band_period": 4e-4},
           "traction": {"strain_max": 0.01, "steps": 4}},
  "parameters": [
    {"path": "$.material.barb_fraction", "values": [0.1, 0.2]},
    {"path": "$.material.E_B", "distribution": "lognormal", "mean": 2.57e9, "std": 0.3e9}
  ],
  "samples": 3, "seed": 5,
  "outputs": ["slope_pa", "steps"]
}
EOF
"$plume" sweep "$scratch/grid.json" -o "$scratch/j1" -j 1 >"$scratch/out.txt" 2>"$scratch/err.txt"
succeeded "sweep -j 1 succeeds"
check "sweep: summary line" grep -q '^sweep: 6 runs, 6 ok, 0 failed' "$scratch/out.txt"
for file in results.csv sweep.json stats.json timings.csv plots/slope_pa-vs-material_barb_fraction.png \
	plots/slope_pa-histogram.png; do
	check "sweep: $file written" test -s "$scratch/j1/$file"
done
check "sweep: no run folders kept" test ! -e "$scratch/j1/runs"
check "sweep: header" test "$(head -1 "$scratch/j1/results.csv")" = "index,material.barb_fraction,material.E_B,slope_pa,steps,status,message"
check "sweep: 6 rows" test "$(wc -l <"$scratch/j1/results.csv")" -eq 7
check "sweep: 6 timings" test "$(wc -l <"$scratch/j1/timings.csv")" -eq 6
# Thesis eq. 5.2: the longitudinal slope is Phi_B E_B + (1 - Phi_B) E_b, to 1e-3.
check "sweep: every row follows eq. 5.2" awk -F, 'NR > 1 { e = $2 * $3 + (1 - $2) * 39200; r = $4 / e; if (!(r > 0.999 && r < 1.001) || $6 != "ok") bad = 1 } END { exit bad }' "$scratch/j1/results.csv"
check "sweep: grid value slowest, samples shared across it" \
	test "$(awk -F, 'NR > 1 { print $2 }' "$scratch/j1/results.csv" | tr '\n' ' ')" = "0.1 0.1 0.1 0.2 0.2 0.2 "
check "sweep: the same E_B samples at each grid value" \
	test "$(awk -F, 'NR >= 2 && NR <= 4 { print $3 }' "$scratch/j1/results.csv")" = "$(awk -F, 'NR >= 5 { print $3 }' "$scratch/j1/results.csv")"
check "sweep.json: version and seed" grep -q '"plume_version"' "$scratch/j1/sweep.json"

"$plume" sweep "$scratch/grid.json" -o "$scratch/nested/j2" -j 2 >/dev/null 2>"$scratch/err.txt"
succeeded "sweep -j 2 into a folder whose parents do not exist yet (they are made)"
mv "$scratch/nested/j2" "$scratch/j2"
check "sweep -j 2: same results.csv bytes" cmp -s "$scratch/j1/results.csv" "$scratch/j2/results.csv"
check "sweep -j 2: same stats.json" cmp -s "$scratch/j1/stats.json" "$scratch/j2/stats.json"

# --- MPI ----------------------------------------------------------------------
if "$plume" help sweep | grep -q 'This plume was built with MPI' && command -v mpirun >/dev/null; then
	# Root needs both the flag and these; Open MPI's own allocations at exit are not
	# plume's leaks (the sanitizer build would count them).
	export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
	export ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0
	for n in 2 3; do
		mpirun --allow-run-as-root --oversubscribe -n $n "$plume" sweep "$scratch/grid.json" -o "$scratch/mpi$n" \
			>"$scratch/out.txt" 2>"$scratch/err.txt"
		succeeded "mpirun -n $n succeeds"
		check "mpirun -n $n: same results.csv bytes" cmp -s "$scratch/j1/results.csv" "$scratch/mpi$n/results.csv"
		check "mpirun -n $n: one summary line" test "$(grep -c '^sweep: 6 runs' "$scratch/out.txt")" -eq 1
	done
	"$plume" sweep --dry-run "$scratch/grid.json" -o "$scratch/none" >"$scratch/plan.csv" 2>/dev/null
	mpirun --allow-run-as-root --oversubscribe -n 3 "$plume" sweep --dry-run "$scratch/grid.json" -o "$scratch/none" \
		>"$scratch/mpi-plan.csv" 2>"$scratch/err.txt"
	succeeded "mpirun -n 3 --dry-run succeeds"
	check "mpirun -n 3 --dry-run: the plan printed once" cmp -s "$scratch/plan.csv" "$scratch/mpi-plan.csv"
	check "mpirun -n 3 --dry-run: nothing written" test ! -e "$scratch/none"
	# A usage error and --help are printed by rank 0 alone (every rank printed them).
	mpirun --allow-run-as-root --oversubscribe -n 3 "$plume" sweep --bogus "$scratch/grid.json" -o "$scratch/none" \
		>/dev/null 2>"$scratch/err.txt"
	check "mpirun -n 3: a usage error printed once" test "$(grep -c "unknown option '--bogus'" "$scratch/err.txt")" -eq 1
	mpirun --allow-run-as-root --oversubscribe -n 3 "$plume" sweep --help >"$scratch/out.txt" 2>/dev/null
	check "mpirun -n 3: --help printed once" test "$(grep -c '^Usage' "$scratch/out.txt")" -eq 1
else
	echo "SKIP: MPI part: this plume was built without MPI (libopenmpi-dev not found at configure time)"
fi

# --- a failing run is recorded and the sweep goes on --------------------------
cat >"$scratch/fail.json" <<'EOF'
{"command": "lab traction",
 "spec": {"sample": {"width": 0.004, "height": 0.0052, "barb_angle_deg": 45, "elements": 300},
          "material": {"model": "mesoscale"},
          "traction": {"strain_max": 0.3, "steps": 3, "max_iterations": 50, "max_substep_halvings": 0}},
 "parameters": [{"path": "$.traction.max_iterations", "values": [1, 50]}],
 "outputs": ["slope_pa"]}
EOF
"$plume" sweep "$scratch/fail.json" -o "$scratch/fail" >"$scratch/out.txt" 2>&1
check "failing run: the sweep completes" test $? -eq 0
check "failing run: recorded with its message" grep -q '^0,1,,failed,exit 1: spec.json: traction step 1 of 3 .*Newton did not converge' "$scratch/fail/results.csv"
check "failing run: the next run is ok" grep -q '^1,50,[0-9.e+]*,ok,$' "$scratch/fail/results.csv"
# Every run failed: the rows are kept, but the sweep measured nothing and exits 1.
sed 's/"values": \[1, 50\]/"values": [1]/' "$scratch/fail.json" >"$scratch/all-fail.json"
expect_failure "every run failed" 1 "every run failed (1 of 1)" "$plume" sweep "$scratch/all-fail.json" -o "$scratch/all-fail"
check "every run failed: the row kept with its message" grep -q '^0,1,,failed,exit 1: ' "$scratch/all-fail/results.csv"
check "every run failed: no run folders left" test ! -e "$scratch/all-fail/runs"

# --- a true/false output counts as 1/0 in stats.json ----------------------------
cat >"$scratch/bool.json" <<EOF
{"command": "simulate",
 "spec": {"feather": "$source_dir/examples/franco-walter/blue.json", "mesh": {"edge_length": 0.012},
          "handles": [{"group": "rachis_clamp"}], "gravity": [0, 0, -9.81], "duration": 0.011},
 "parameters": [{"path": "\$.duration", "values": [0.011, 0.022]}],
 "outputs": ["completed", "steps"]}
EOF
"$plume" sweep "$scratch/bool.json" -o "$scratch/bool" >"$scratch/out.txt" 2>"$scratch/err.txt"
succeeded "boolean output: the sweep succeeds"
check "boolean output: completed counted as 1 in stats.json" /usr/bin/python3 -c \
	'import json, sys; c = json.load(open(sys.argv[1]))["outputs"]["completed"]; sys.exit(not (c["count"] == 2 and c["mean"] == 1))' \
	"$scratch/bool/stats.json"

# --- kill and resume ----------------------------------------------------------
cat >"$scratch/slow.json" <<'EOF'
{"command": "lab traction",
 "spec": {"sample": {"width": 0.004, "height": 0.0052, "barb_angle_deg": 45, "elements": 450},
          "material": {"model": "mesoscale", "E_b": 3.92e4, "band_phase": 0}, "traction": {"strain_max": 0.2, "steps": 6}},
 "parameters": [{"path": "$.material.band_phase", "grid": {"from": 0, "to": 0.75, "count": 4}},
                {"path": "$.material.E_b", "values": [3.5e4, 4.5e4]}],
 "outputs": ["slope_pa", "newton_iterations"]}
EOF
"$plume" sweep "$scratch/slow.json" -o "$scratch/whole" -j 2 >/dev/null 2>&1
check "slow sweep: 8 ok rows" test "$(grep -c ',ok,$' "$scratch/whole/results.csv")" -eq 8

rows() { test -f "$1/results.csv" && echo $(($(wc -l <"$1/results.csv") - 1)) || echo 0; }
wait_rows() { # wait_rows DIR N: until DIR/results.csv has N rows (at most 60 s, while $job lives)
	for _ in $(seq 600); do
		test "$(rows "$1")" -ge "$2" && return 0
		kill -0 "$job" 2>/dev/null || return 1
		sleep 0.1
	done
	return 1
}
# SIGKILL to one run: recorded as killed by a signal, then run again on resume.
"$plume" sweep "$scratch/slow.json" -o "$scratch/worker" -j 1 >/dev/null 2>&1 &
job=$!
wait_rows "$scratch/worker" 2
# Kill the current run until one kill lands on a live run (not one just exiting).
while kill -0 $job 2>/dev/null && ! grep -q ',signal,' "$scratch/worker/results.csv"; do
	child=$(pgrep -P $job | head -1)
	test -n "$child" && kill -KILL "$child" 2>/dev/null
	sleep 0.2
done
wait $job
check "killed run: recorded as a signal" grep -q ',signal,killed by signal 9' "$scratch/worker/results.csv"
check "killed run: the sweep went on to the end" test "$(rows "$scratch/worker")" -eq 8
"$plume" sweep "$scratch/slow.json" -o "$scratch/worker" -j 2 >/dev/null 2>&1
check "killed run: resumed to the uninterrupted bytes" cmp -s "$scratch/whole/results.csv" "$scratch/worker/results.csv"

# SIGKILL to the whole sweep: its runs die with it; resume runs only what is missing.
"$plume" sweep "$scratch/slow.json" -o "$scratch/job" -j 2 >/dev/null 2>&1 &
job=$!
wait_rows "$scratch/job" 3
expect_failure "a second sweep in a busy DIR" 4 "another plume sweep is running in this folder" \
	"$plume" sweep "$scratch/slow.json" -o "$scratch/job"
kill -KILL $job
wait $job 2>/dev/null
done_before=$(rows "$scratch/job")
check "killed sweep: part done ($done_before rows)" test "$done_before" -lt 8
check "killed sweep: results.csv whole (every row ends in a status)" \
	awk -F, 'NR > 1 && $(NF - 1) != "ok" { bad = 1 } END { exit bad }' "$scratch/job/results.csv"
sleep 0.3
check "killed sweep: no run outlives it" test -z "$(pgrep -P $job)"
"$plume" sweep "$scratch/slow.json" -o "$scratch/job" -j 1 >/dev/null 2>&1
check "killed sweep: resumed to the uninterrupted bytes" cmp -s "$scratch/whole/results.csv" "$scratch/job/results.csv"
check "killed sweep: only the missing runs ran again" \
	test "$(wc -l <"$scratch/job/timings.csv")" -le $((8 + 2))
check "killed sweep: what its runs left is removed on resume ($(ls -A "$scratch/job/runs" 2>&1 | head -3))" \
	test ! -e "$scratch/job/runs"
expect_failure "resume with another sweep" 3 "holds another sweep" "$plume" sweep "$scratch/grid.json" -o "$scratch/job"

# --- files of the user's in DIR are neither removed nor replaced ---------------------
# A run folder the sweep did not make (no marker) is refused before anything is written.
mkdir -p "$scratch/own/runs/000000"
echo mine >"$scratch/own/runs/mine.txt"
echo keep >"$scratch/own/runs/000000/keep.txt"
expect_failure "a run folder the user made" 4 "own/runs/000000: not a run folder of this sweep (it lacks .plume-sweep-run)" \
	"$plume" sweep "$scratch/grid.json" -o "$scratch/own"
check "a run folder the user made: its file kept" grep -qx keep "$scratch/own/runs/000000/keep.txt"
check "a run folder the user made: nothing written" test ! -e "$scratch/own/sweep.json" -a ! -e "$scratch/own/results.csv"
# Other files in DIR/runs stay, and so does DIR/runs with them.
mv "$scratch/own/runs/000000" "$scratch/own-000000"
"$plume" sweep "$scratch/grid.json" -o "$scratch/own" -j 2 >/dev/null 2>"$scratch/err.txt"
succeeded "the user's file in DIR/runs: the sweep runs"
check "the user's file in DIR/runs: kept" grep -qx mine "$scratch/own/runs/mine.txt"
check "the user's file in DIR/runs: the sweep's run folders removed" test "$(ls -A "$scratch/own/runs")" = "mine.txt"
check "the user's file in DIR/runs: same results" cmp -s "$scratch/j1/results.csv" "$scratch/own/results.csv"
# A file the user put in a run folder of the sweep (kept with keep_runs) keeps that folder.
sed 's/"outputs"/"keep_runs": true, "outputs"/' "$scratch/grid.json" >"$scratch/keep.json"
"$plume" sweep "$scratch/keep.json" -o "$scratch/keep" >/dev/null 2>&1
check "keep_runs: run folders kept" test -f "$scratch/keep/runs/000005/spec.json" -a -f "$scratch/keep/runs/000005/out/traction.json"
echo note >"$scratch/keep/runs/000002/note.txt"
sed -i '/^2,/d' "$scratch/keep/results.csv" # run 2 again, into its folder
"$plume" sweep "$scratch/keep.json" -o "$scratch/keep" >/dev/null 2>&1
check "a run again in its folder: the user's note kept" grep -qx note "$scratch/keep/runs/000002/note.txt"
check "a run again in its folder: its row back" cmp -s "$scratch/j1/results.csv" "$scratch/keep/results.csv"
# A new sweep does not replace a results.csv (or timings.csv, stats.json, plots/) it did not write.
mkdir -p "$scratch/theirs" && echo theirs >"$scratch/theirs/results.csv"
expect_failure "a results.csv not a sweep's" 4 "theirs/results.csv exists, but" "$plume" sweep "$scratch/grid.json" -o "$scratch/theirs"
check "a results.csv not a sweep's: kept" grep -qx theirs "$scratch/theirs/results.csv"
check "a results.csv not a sweep's: nothing written" test ! -e "$scratch/theirs/sweep.json"
# -o naming a file, or a folder plume may not write: the real reason, not a held lock.
echo x >"$scratch/afile"
expect_failure "-o names a file" 4 "afile: not a folder" "$plume" sweep "$scratch/grid.json" -o "$scratch/afile"
check "-o names a file: the file kept" grep -qx x "$scratch/afile"
if [ "$(id -u)" -ne 0 ]; then
	mkdir "$scratch/readonly" && chmod 555 "$scratch/readonly"
	expect_failure "an unwritable DIR" 4 "readonly/.sweep.lock: cannot create the sweep's lock: Permission denied" \
		"$plume" sweep "$scratch/grid.json" -o "$scratch/readonly"
	chmod 755 "$scratch/readonly"
else
	echo "SKIP: unwritable DIR: root writes any folder"
fi

# --- random samples: reproducible, distributed as asked -----------------------
cat >"$scratch/random.json" <<'EOF'
{"command": "lab traction",
 "spec": {"material": {"model": "mesoscale", "E_B": 2.57e9, "E_b": 3.92e4, "barb_fraction": 0.14}},
 "parameters": [
   {"path": "$.material.barb_fraction", "distribution": "normal", "mean": 0.14, "std": 0.02, "min": 0.1, "max": 0.2},
   {"path": "$.material.E_b", "distribution": "lognormal", "mean": 3.92e4, "std": 0.98e4},
   {"path": "$.material.E_B", "distribution": "uniform", "min": 2e9, "max": 3e9}
 ],
 "samples": 4000, "seed": 11}
EOF
"$plume" sweep --dry-run "$scratch/random.json" -o "$scratch/none" >"$scratch/plan1.csv" 2>"$scratch/err.txt"
succeeded "dry run succeeds"
check "dry run: nothing written" test ! -e "$scratch/none"
"$plume" sweep --dry-run "$scratch/random.json" -o "$scratch/none" >"$scratch/plan2.csv" 2>/dev/null
check "same seed, same samples" cmp -s "$scratch/plan1.csv" "$scratch/plan2.csv"
sed 's/"seed": 11/"seed": 12/' "$scratch/random.json" >"$scratch/random12.json"
"$plume" sweep --dry-run "$scratch/random12.json" -o "$scratch/none" >"$scratch/plan3.csv" 2>/dev/null
check "another seed, other samples" test "$(sed -n 2p "$scratch/plan1.csv")" != "$(sed -n 2p "$scratch/plan3.csv")"
# Moments against closed forms: the truncated normal on [0.1, 0.2] (mean 0.14, std 0.02,
# i.e. [-2, 3] std) has mean 0.14 + 0.02 (phi(-2) - phi(3)) / (Phi(3) - Phi(-2)) = 0.14101;
# the log-normal's mean and std are the given ones; the uniform's mean 2.5e9, std 2.89e8.
check "samples follow their distributions" "$py" - "$scratch/plan1.csv" <<'EOF'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 4000
phi = [float(r["material.barb_fraction"]) for r in rows]
eb = [float(r["material.E_b"]) for r in rows]
EB = [float(r["material.E_B"]) for r in rows]
def mean(x): return sum(x) / len(x)
def std(x):
    m = mean(x); return math.sqrt(sum((v - m) ** 2 for v in x) / (len(x) - 1))
pdf = lambda z: math.exp(-z * z / 2) / math.sqrt(2 * math.pi)
cdf = lambda z: 0.5 * math.erfc(-z / math.sqrt(2))
expected = 0.14 + 0.02 * (pdf(-2) - pdf(3)) / (cdf(3) - cdf(-2))
assert min(phi) >= 0.1 and max(phi) <= 0.2, (min(phi), max(phi))
assert abs(mean(phi) - expected) < 4 * 0.02 / math.sqrt(4000), (mean(phi), expected)
assert abs(mean(eb) / 3.92e4 - 1) < 0.01, mean(eb)
assert abs(std(eb) / 0.98e4 - 1) < 0.06, std(eb)
assert min(eb) > 0
assert abs(mean(EB) / 2.5e9 - 1) < 0.005 and abs(std(EB) / (1e9 / math.sqrt(12)) - 1) < 0.03
EOF

# --- bad sweeps: a clear message before any run, nothing written --------------
base='"command": "lab traction", "spec": {"material": {"model": "mesoscale", "barb_fraction": 0.14}}'
echo "{$base, \"parameters\": [{\"path\": \"\$.material.barb_fractoin\", \"values\": [0.1]}]}" >"$scratch/bad-path.json"
expect_no_output "bad key" 3 'bad-path.json: the first run'"'"'s spec is refused: $.material.barb_fractoin: unknown key; did you mean "barb_fraction"?' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-path.json" -o "$scratch/bad"
echo "{$base, \"parameters\": [{\"path\": \"\$.materal.barb_fraction\", \"values\": [0.1]}]}" >"$scratch/bad-path2.json"
expect_no_output "bad path" 3 'bad-path2.json: $.parameters[0].path: $.materal.barb_fraction is not in the base spec; the nearest path there is $.material.barb_fraction' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-path2.json" -o "$scratch/bad"
echo '{"command": "lab calibrate", "spec": {"phi": 0.14, "Eb": 3.92e4, "EB": 2.57e9}, "parameters": [{"path": "$.phase", "values": [1]}]}' >"$scratch/bad-cal.json"
expect_no_output "bad calibration key" 3 '$.phase: not a calibration option; did you mean "phases"?' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-cal.json" -o "$scratch/bad"
# The calibration's option ranges are checked before any run, as `plume lab calibrate` checks them.
echo '{"command": "lab calibrate", "spec": {"phi": 0.14, "Eb": 3.92e4, "EB": 2.57e9}, "parameters": [{"path": "$.EB", "values": [2e9, 2e12]}]}' >"$scratch/bad-cal-range.json"
expect_no_output "calibration value out of range" 3 'the value 2000000000000 is refused: $.EB is 2e+12, allowed a number in (0, 1e+12]' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-cal-range.json" -o "$scratch/bad"
echo '{"command": "lab calibrate", "spec": {"phi": 0.14, "Eb": 3.92e4, "EB": 2.57e9}, "parameters": [{"path": "$.phases", "values": [2, 65]}]}' >"$scratch/bad-cal-phases.json"
expect_no_output "calibration count out of range" 3 '$.phases is 65, allowed a whole number in [1, 64]' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-cal-phases.json" -o "$scratch/bad"
# Every option of the command is a key, checked against the same table (cli_calibrate_options).
echo '{"command": "lab calibrate", "spec": {"phi": 0.14, "Eb": 3.92e4, "EB": 2.57e9}, "parameters": [{"path": "$.compression", "values": [0, -1]}]}' >"$scratch/bad-cal-compression.json"
expect_no_output "calibration compression out of range" 3 '$.compression is -1, allowed a number in [0, 1e+12]' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-cal-compression.json" -o "$scratch/bad"
echo '{"command": "lab calibrate", "spec": {"phi": 0.14, "Eb": 3.92e4, "EB": 2.57e9}, "parameters": [{"path": "$.macro_elements", "values": [200, 4000001]}]}' >"$scratch/bad-cal-macro.json"
expect_no_output "calibration macro elements out of range" 3 '$.macro_elements is 4000001, allowed a whole number in [2, 4000000]' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-cal-macro.json" -o "$scratch/bad"
echo "{$base, \"parameters\": [{\"path\": \"\$.material.barb_fraction\", \"distribution\": \"normal\", \"mean\": 0.14, \"std\": 0.02}], \"samples\": 3}" >"$scratch/bad-range.json"
expect_no_output "distribution outside the range" 3 '$.material.barb_fraction is -0.06, allowed in (0, 1); bound it with "min"/"max"' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-range.json" -o "$scratch/bad"
# An integer parameter's values lie in [-2^53, 2^53]: they were rounded with llround and cast to a JSON
# integer past a long (the value -9223372036854775808 was refused, or the cast trapped the sanitizer).
steps_base='"command": "lab traction", "spec": {"material": {"model": "mesoscale", "barb_fraction": 0.14}, "traction": {"steps": 4}}'
echo "{$steps_base, \"parameters\": [{\"path\": \"\$.traction.steps\", \"grid\": {\"from\": 4, \"to\": 1e19, \"count\": 2}, \"integer\": true}]}" >"$scratch/big-grid.json"
expect_no_output "an integer grid past 2^53" 3 '$.parameters[0].grid.to is 1e+19; an integer parameter takes values in [-2^53, 2^53]' \
	"$scratch/bad" "$plume" sweep "$scratch/big-grid.json" -o "$scratch/bad"
echo "{$steps_base, \"parameters\": [{\"path\": \"\$.traction.steps\", \"distribution\": \"lognormal\", \"log_mean\": 2, \"log_std\": 5, \"integer\": true}], \"samples\": 2}" >"$scratch/big-lognormal.json"
expect_no_output "an unbounded integer distribution" 3 'the distribution reaches 9007199254740992, which is refused' \
	"$scratch/bad" "$plume" sweep "$scratch/big-lognormal.json" -o "$scratch/bad"
printf 'index,x,status\n0,4,ok\n1,1e300,ok\n' >"$scratch/big.csv"
echo "{$steps_base, \"parameters\": [{\"path\": \"\$.traction.steps\", \"from_csv\": \"big.csv\", \"column\": \"x\", \"integer\": true}]}" >"$scratch/big-csv.json"
expect_no_output "an integer column past 2^53" 3 "big.csv line 3: column x is '1e300'; an integer parameter takes values in [-2^53, 2^53]" \
	"$scratch/bad" "$plume" sweep "$scratch/big-csv.json" -o "$scratch/bad"
echo "{$base, \"parameters\": [{\"path\": \"\$.material.barb_fraction\", \"values\": [0.1, 1.5]}]}" >"$scratch/bad-value.json"
expect_no_output "grid value outside the range" 3 'the value 1.5 is refused: $.material.barb_fraction is 1.5, allowed in (0, 1)' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-value.json" -o "$scratch/bad"
echo "{$base, \"parameters\": [{\"path\": \"\$.material.barb_fraction\", \"values\": [0.1]}], \"outputs\": [\"slope\"]}" >"$scratch/bad-output.json"
expect_no_output "unknown output" 3 '$.outputs[0]: no lab traction run produces "slope"; lab traction writes: slope_pa,' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-output.json" -o "$scratch/bad"
echo "{$base, \"parameters\": [{\"path\": \"\$.material.barb_fraction\", \"values\": [0.1]}], \"sample\": 3}" >"$scratch/bad-key.json"
expect_no_output "unknown sweep key" 3 '$.sample is not a sweep key; did you mean "samples"?' \
	"$scratch/bad" "$plume" sweep "$scratch/bad-key.json" -o "$scratch/bad"
expect_no_output "bad -j" 2 "-j expects a whole number" "$scratch/bad" "$plume" sweep "$scratch/grid.json" -o "$scratch/bad" -j 0
echo "{$base, \"parameters\": [{\"path\": \"\$.material.barb_fraction\", \"values\": [0.1]}], \"outputs\": [\"slope_pa\", \"steps\", \"slope_pa\"]}" >"$scratch/dup-output.json"
expect_no_output "an output twice" 3 '$.outputs[2]: "slope_pa" is already collected by $.outputs[0]' \
	"$scratch/bad" "$plume" sweep "$scratch/dup-output.json" -o "$scratch/bad"
expect_no_output "a sweep file that is not there" 4 "nonexist.json: cannot read: No such file or directory" \
	"$scratch/bad" "$plume" sweep "$scratch/nonexist.json" -o "$scratch/bad"
echo '{"command": "lab traction", "spec": "nospec.json", "parameters": [{"path": "$.x", "values": [1]}]}' >"$scratch/no-spec.json"
expect_no_output "a base spec that is not there" 4 "\$.spec: $scratch/nospec.json: cannot read: No such file or directory" \
	"$scratch/bad" "$plume" sweep "$scratch/no-spec.json" -o "$scratch/bad"
echo "{$base, \"parameters\": [{\"path\": \"\$.material.barb_fraction\", \"grid\": {\"from\": 0.1, \"to\": 0.2, \"count\": 11}}, {\"path\": \"\$.material.E_b\", \"distribution\": \"uniform\", \"min\": 3e4, \"max\": 4e4}], \"samples\": 100000}" >"$scratch/huge.json"
expect_no_output "more runs than any sweep may have" 5 'make 1100000 runs; a sweep may have at most 1000000' \
	"$scratch/bad" "$plume" sweep "$scratch/huge.json" -o "$scratch/bad"
# $.arguments: options the sweep sets, options the command does not take, values
# missing, words that would be second specs; all before any run.
arguments_refused() { # arguments_refused NAME ARGUMENTS_JSON MESSAGE
	echo "{$base, \"parameters\": [{\"path\": \"\$.material.barb_fraction\", \"values\": [0.1, 0.2]}], \"arguments\": $2}" >"$scratch/args.json"
	expect_no_output "$1" 3 "$3" "$scratch/bad" "$plume" sweep "$scratch/args.json" -o "$scratch/bad"
}
arguments_refused "an unknown option" '["--bogus"]' "\$.arguments: plume lab traction refuses them: unknown option '--bogus'"
arguments_refused "-o in the arguments" '["-o", "/x"]' "\$.arguments[0]: '-o' (--output) is refused in a sweep: the sweep gives each run its own output folder"
arguments_refused "--output abbreviated" '["--out=/x"]' "'--out=/x' (--output) is refused in a sweep"
arguments_refused "--help in the arguments" '["--help"]' "'--help' (--help) is refused in a sweep"
arguments_refused "a value missing" '["--max-memory"]' "\$.arguments[0]: '--max-memory' needs a value after it"
arguments_refused "a bad value" '["--max-memory", "lots"]' "\$.arguments: plume lab traction refuses them:"
arguments_refused "a second spec" '["--max-memory", "1G", "other.json"]' "\$.arguments[2]: 'other.json' is neither an option of plume lab traction nor an option's value"
echo '{"command": "lab calibrate", "spec": {"phi": 0.14, "Eb": 3.92e4, "EB": 2.57e9}, "parameters": [{"path": "$.phi", "values": [0.1, 0.2]}], "arguments": ["--phi", "0.3"]}' >"$scratch/args-cal.json"
expect_no_output "a calibration option in the arguments" 3 "'--phi' (--phi) is refused in a sweep: set \$.spec.phi instead" \
	"$scratch/bad" "$plume" sweep "$scratch/args-cal.json" -o "$scratch/bad"
echo "{$base, \"parameters\": [{\"path\": \"\$.material.barb_fraction\", \"values\": [0.1]}], \"arguments\": [\"--max-memory\", \"1G\"], \"outputs\": [\"slope_pa\"]}" >"$scratch/args-ok.json"
"$plume" sweep "$scratch/args-ok.json" -o "$scratch/args-ok" >/dev/null 2>"$scratch/err.txt"
succeeded "arguments the command takes: the sweep runs"
check "arguments the command takes: the run ok" grep -q '^0,0.1,[0-9.e+]*,ok,$' "$scratch/args-ok/results.csv"

# --- frames: ranges rendered apart (render --frames, a sweep) equal one render -----
sed 's/"duration": 1.1/"duration": 0.033/' "$source_dir/examples/scenes/figure1-anisotropic.json" |
	sed "s|\"../franco-walter/hawk.json\"|\"$source_dir/examples/franco-walter/hawk.json\"|" >"$scratch/short.json"
"$plume" simulate "$scratch/short.json" -o "$scratch/sim" >/dev/null 2>&1
check "frames: a 4-frame simulation" test -f "$scratch/sim/frames/0003.obj"
"$plume" render "$scratch/sim" -o "$scratch/render-all" --spp 1 --size 40x40 -f png >/dev/null 2>&1
"$plume" render "$scratch/sim" -o "$scratch/render-parts" --spp 1 --size 40x40 -f png --frames 0:3:2 >/dev/null 2>&1
check "render --frames 0:3:2: frames 0 and 2 only" test "$(ls "$scratch/render-parts/frames" | tr '\n' ' ')" = "0000.png 0002.png "
"$plume" render "$scratch/sim" -o "$scratch/render-parts" --spp 1 --size 40x40 -f png --frames 1:3:2 >/dev/null 2>&1
check "render --frames: a second range joins the folder" test "$(ls -A "$scratch/render-parts/frames" | wc -l)" -eq 4
check "render --frames: nothing else left in DIR" test "$(ls -A "$scratch/render-parts" | tr '\n' ' ')" = "frames "
for f in 0000 0001 0002 0003; do
	check "render --frames: frame $f equals the whole render's" cmp -s "$scratch/render-all/frames/$f.png" "$scratch/render-parts/frames/$f.png"
done
expect_failure "render --frames: bad range" 2 "--frames '5:1': expected A:B or A:B:S" \
	"$plume" render "$scratch/sim" -o "$scratch/o" --frames 5:1
expect_failure "render --frames: no frame selected" 3 "no frame in --frames 7:9:1 (the frames are 0000 to 0003)" \
	"$plume" render "$scratch/sim" -o "$scratch/o" --frames 7:9
echo '{"command": "render frames",
 "spec": {"simulation": "sim", "output": "render-sweep", "first": 0, "count": 2, "spp": 1, "size": "40x40", "format": "png"},
 "parameters": [{"path": "$.first", "grid": {"from": 0, "to": 2, "count": 2}}]}' >"$scratch/frames.json"
"$plume" sweep "$scratch/frames.json" -o "$scratch/frames-sweep" -j 2 >/dev/null 2>"$scratch/err.txt"
check "frames sweep: 2 ranges ok ($(cat "$scratch/err.txt"))" test "$(grep -c ',ok,$' "$scratch/frames-sweep/results.csv")" -eq 2
for f in 0000 0001 0002 0003; do
	check "frames sweep: frame $f equals the whole render's" cmp -s "$scratch/render-all/frames/$f.png" "$scratch/render-sweep/frames/$f.png"
done
# Rendering into the simulation's own folder would replace its frames: refused.
sed 's/"output": "render-sweep"/"output": "sim"/' "$scratch/frames.json" >"$scratch/frames-into-sim.json"
ls -l "$scratch/sim" "$scratch/sim/frames" >"$scratch/sim-before.txt"
expect_no_output "frames sweep into the simulation's folder" 3 \
	"\$.output ($scratch/sim) is the same folder as \$.simulation ($scratch/sim): the rendered frames would replace the simulation's frames" \
	"$scratch/frames-bad" "$plume" sweep "$scratch/frames-into-sim.json" -o "$scratch/frames-bad"
sed 's/"output": "render-sweep"/"output": "sim\/frames"/' "$scratch/frames.json" >"$scratch/frames-into-sim.json"
expect_no_output "frames sweep into the simulation's frames" 3 "is the frames folder of \$.simulation" \
	"$scratch/frames-bad" "$plume" sweep "$scratch/frames-into-sim.json" -o "$scratch/frames-bad"
check "frames sweep into the simulation: its files untouched" test "$(ls -l "$scratch/sim" "$scratch/sim/frames")" = "$(cat "$scratch/sim-before.txt")"

# --- the output keys the sweep accepts are the ones a real run writes ------------
# The sweep checks output keys against its lists (cli/sweep_commands.c) before any run.
# Here the list is compared with a real run's result file both ways: every number and
# boolean in the file is a listed key (so a key added to a writer fails here until it is
# listed), every listed key not marked "(when ...)" is in the file; then a few keys,
# nested, indexed and named ones among them, come back through results.csv.
listed_keys() { # listed_keys SWEEP_WITHOUT_OUTPUTS: the keys the unknown-output message lists, one a line
	sed 's/}$/, "outputs": ["?"]}/' "$1" >"$scratch/keys.json"
	"$plume" sweep "$scratch/keys.json" -o "$scratch/bad" 2>&1 | sed -n 's/.* writes: //p' | sed 's/, /\n/g'
}
keys_match_writer() { # keys_match_writer NAME SWEEP_WITHOUT_OUTPUTS RESULT_FILE OUTPUTS_JSON
	listed_keys "$2" >"$scratch/listed.txt"
	check "$1: keys listed" test -s "$scratch/listed.txt"
	sed "s/}\$/, \"keep_runs\": true, \"outputs\": $4}/" "$2" >"$scratch/all.json"
	rm -rf "$scratch/all"
	"$plume" sweep "$scratch/all.json" -o "$scratch/all" >/dev/null 2>"$scratch/err.txt"
	succeeded "$1: the sweep succeeds"
	check "$1: the listed keys are the result file's numbers and booleans" "$py" - "$scratch/listed.txt" \
		"$scratch/all/runs/000000/$3" <<'EOF'
import json, re, sys
listed = [line.rstrip("\n") for line in open(sys.argv[1]) if line.strip()]
text = open(sys.argv[2]).read()
written = {}
def walk(node, path):
    if isinstance(node, dict):
        for k, v in node.items(): walk(v, f"{path}.{k}" if path else k)
    elif isinstance(node, list):
        for i, v in enumerate(node): walk(v, f"{path}[{i}]")
    elif not isinstance(node, str):  # numbers, booleans, null (a measure never defined)
        written[path] = node
walk(json.loads(text), "")
# A Zhang-Kanai summary's list of unsnapped barbs varies in length: not an output.
written = {k: v for k, v in written.items() if not k.startswith("snapping.unsnapped_barbs")}
def pattern(key):
    return re.compile(re.escape(key).replace(re.escape("<group>"), "[A-Za-z0-9_-]+")
                      .replace(re.escape("<handle>"), "[0-9]+").replace(re.escape("<feather>"), "[0-9]+") + "$")
keys = [(line.split(" (")[0], " (" in line) for line in listed]
bad = [k for k in written if not any(pattern(key).match(k) for key, _ in keys)]
missing = [key for key, conditional in keys if not conditional and not any(pattern(key).match(k) for k in written)]
if bad or missing:
    sys.exit(f"written, not listed: {bad}; listed, not written: {missing}")
EOF
	check "$1: the outputs asked have values ($(tail -1 "$scratch/all/results.csv" 2>/dev/null))" \
		awk -F, -v n="$(echo "$4" | tr ',' '\n' | wc -l)" 'NR == 2 { for (i = 3; i < 3 + n; ++i) if ($i == "") bad = 1; if ($(3 + n) != "ok") bad = 1 } END { exit bad || NR != 2 }' "$scratch/all/results.csv"
}
echo "{\"command\": \"simulate\", \"spec\": \"$source_dir/examples/scenes/figure1-anisotropic.json\", \"parameters\": [{\"path\": \"\$.duration\", \"values\": [0.011]}]}" >"$scratch/k-simulate.json"
keys_match_writer simulate "$scratch/k-simulate.json" out/summary.json \
	'["mesh_vane_min_angle_deg", "mesh_excepted_count", "vane_min_principal_stretch", "seconds_contact", "duration", "handle_max_reaction[1]", "feathers[0].face_count"]'
echo "{\"command\": \"mesh\", \"spec\": \"$source_dir/examples/meshes/guides.json\", \"parameters\": [{\"path\": \"\$.mesh.edge_length\", \"values\": [0.004]}]}" >"$scratch/k-mesh.json"
keys_match_writer mesh "$scratch/k-mesh.json" out/report.json \
	'["vane_min_angle_deg", "excepted_count", "guide_count[1]", "groups.rachis_clamp"]'
echo "{$base, \"parameters\": [{\"path\": \"\$.material.barb_fraction\", \"values\": [0.14]}]}" >"$scratch/k-traction.json"
keys_match_writer "lab traction" "$scratch/k-traction.json" out/traction.json '["slope_pa", "compression"]'
echo '{"command": "lab calibrate", "spec": {"phi": 0.14, "Eb": 3.92e4, "EB": 2.57e9, "phases": 1, "elements": 300, "macro_elements": 200}, "parameters": [{"path": "$.phi", "values": [0.14]}]}' >"$scratch/k-calibrate.json"
keys_match_writer "lab calibrate" "$scratch/k-calibrate.json" stdout.txt \
	'["slopes.longitudinal", "spread.E_vw.total", "protocol.barb_constraint", "E_vw"]'
echo "{\"command\": \"generate\", \"spec\": \"$source_dir/examples/zhang-kanai/figure11-expansion.json\", \"arguments\": [\"-f\", \"json\"], \"parameters\": [{\"path\": \"\$.seed\", \"values\": [1]}]}" >"$scratch/k-generate.json"
keys_match_writer generate "$scratch/k-generate.json" out/summary.json '["barbs.left", "snapping.partial", "expansion"]'
# What the first run has: a group of its mesh, a handle of its scene; a summary at all.
sed 's/}$/, "outputs": ["groups.rachis_clamps"]}/' "$scratch/k-mesh.json" >"$scratch/k-bad.json"
expect_no_output "an output naming a group the mesh lacks" 3 \
	'$.outputs[0]: the first run'"'"'s mesh has no group "rachis_clamps"; its groups: rachis,' \
	"$scratch/bad" "$plume" sweep "$scratch/k-bad.json" -o "$scratch/bad"
sed 's/}$/, "outputs": ["handle_max_reaction[2]"]}/' "$scratch/k-simulate.json" >"$scratch/k-bad.json"
expect_no_output "an output naming a handle the scene lacks" 3 \
	"\$.outputs[0]: handle_max_reaction[2]: the first run's scene has 2 handles" \
	"$scratch/bad" "$plume" sweep "$scratch/k-bad.json" -o "$scratch/bad"
echo "{\"command\": \"generate\", \"spec\": \"$source_dir/examples/franco-walter/blue.json\", \"parameters\": [{\"path\": \"\$.seed\", \"values\": [1]}], \"outputs\": [\"barbs.left\"]}" >"$scratch/k-bad.json"
expect_no_output "generate outputs of a feather with no summary" 3 "generate writes its outputs (summary.json) for Zhang-Kanai feathers only" \
	"$scratch/bad" "$plume" sweep "$scratch/k-bad.json" -o "$scratch/bad"

finish
