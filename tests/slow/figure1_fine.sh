#!/usr/bin/env bash
# Slow solver regression (.ci/run, not `make test`: one to two minutes on 2 cores).
# Figure 1 anisotropic (examples/scenes/figure1-anisotropic.json) on the e = 1.25 mm
# mesh (5,072 vertices) through its hardest step: at t = 0.638 s the vane buckles and a
# first try fails, and the step is retried in substeps. There the exact Hessian is nearly
# singular along a soft mode; its steps run off along that mode and the line search cuts
# them to nothing, one after another. The rule that takes the projected Hessian after a
# step cut below 1e-3 of its length (RETRY_MIN_STEP_FRACTION, src/sim/newton.c) is what
# gets through it cheaply, and no smaller scene exercises it. Measured (GCC, Release):
# 783 Newton iterations in the 60 steps to t = 0.66 s with the rule, 1000 without it
# (the rest the same to the printed digits: rachis tip 2.95837 cm, barb strain 9.75e-11);
# the bound below sits between. Also checked: the run completes, the barbs
# hold (strain under Table 6.1's 1e-8), the retried steps are counted.
# Usage: figure1_fine.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"

iteration_bound=900

/usr/bin/python3 - "$source_dir" "$scratch/scene.json" <<'PY'
import json, sys
source, out = sys.argv[1:]
scene = json.load(open(source + "/examples/scenes/figure1-anisotropic.json"))
scene["feather"] = source + "/examples/franco-walter/hawk.json"
scene["mesh"]["edge_length"] = 0.00125
json.dump(scene, open(out, "w"))
PY

"$plume" simulate "$scratch/scene.json" -o "$scratch/run" --duration 0.65 >"$scratch/out.txt" 2>"$scratch/err.txt"
succeeded "Figure 1 at e = 1.25 mm runs to t = 0.66 s"
cat "$scratch/out.txt"

summary_holds() {
	/usr/bin/python3 - "$scratch/run/summary.json" "$iteration_bound" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
bound = int(sys.argv[2])
problems = []
if not s["completed"]:
    problems.append("did not complete")
if s["vertices"] != 5072:
    problems.append(f"{s['vertices']} vertices, the 1.25 mm mesh has 5072")
if s["newton_iterations"] > bound:
    problems.append(f"{s['newton_iterations']} Newton iterations, more than {bound} (783 measured)")
if not s["max_barb_strain"] <= 1e-8:
    problems.append(f"barb strain {s['max_barb_strain']:g} over 1e-8")
if s["retried_steps"] < 1:
    problems.append("no step retried: the run no longer passes through the hard step")
for p in problems:
    print(p, file=sys.stderr)
sys.exit(1 if problems else 0)
PY
}
check "the hard step's retries stay within $iteration_bound Newton iterations, the barbs hold" summary_holds

finish
