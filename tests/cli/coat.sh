#!/usr/bin/env bash
# Scenario tests of `plume coat` and `plume generate` against --max-memory: the
# coat's estimate is a bound (the follicles laid out, each feather bounded by the
# key feathers), checked before any feather is built; the outputs' memory is
# checked before anything is written; a run that passes the checks stays within
# them (peak RSS, the program's own ~20 MB aside). And a coat whose surface is
# seen from behind still writes its (empty) picture.
# Usage: coat.sh PLUME_BINARY SOURCE_DIR
# (Each status is saved before `check`: a $(...) in the check's name would reset $?.)
source "$(dirname "$0")/../cli_support.sh" "$@"
examples="$source_dir/examples"
cp "$examples"/coats/key-*.json "$scratch/"
# Every run is capped: a regression must fail here, not take the machine's memory.
# Under AddressSanitizer (the CI's sanitizer build) the cap cannot be set: its shadow memory
# reserves terabytes of address space; nor does peak RSS measure plume's own memory. There the
# runs go uncapped and the RSS bounds are not checked (the estimates' refusals still are).
if ldd "$plume" 2>/dev/null | grep -q 'libasan'; then sanitized=1; else sanitized=0; fi
vm_cap() { if [ "$sanitized" -eq 0 ]; then ulimit -v 6000000; fi; }
within() { [ "$sanitized" -eq 1 ] || test "$1" -le "$2"; } # within PEAK_KB BOUND_KB
capped() { (vm_cap && timeout 120 "$@"); }
# rss COMMAND...: "EXIT PEAK_RSS_KB" of the command (its output discarded).
rss() {
	/usr/bin/python3 -c '
import resource, subprocess, sys
r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)' bash -c "$(declare -f vm_cap); sanitized=$sanitized; vm_cap && exec \"\$@\"" bash "$@"
}
# gb MESSAGE_FILE PATTERN: the number before " GB" that PATTERN's match ends with, in kilobytes.
kb_of() { grep -oE "$2" "$1" | head -1 | grep -oE '[0-9.e+]+ GB' | /usr/bin/python3 -c 'import sys; print(int(float(sys.stdin.read().split()[0]) * 1e6 + 1))'; }
program_kb=32768 # the program itself (code, libraries, stacks), which the estimates leave out

# --- a coat of 289,289 follicles: refused at once, its follicles counted, each feather bounded -------
printf '{"model": "coat", "surface": {"type": "plane", "size": [0.05, 0.05]}, "follicles": {"spacing": 1e-4}, "key_feathers": [{"at": [0, 0, 0], "feather": "key-contour.json"}]}' >"$scratch/big.json"
expect_no_output "coat of 289,289 follicles" 5 'makes 289289 follicles; with feathers of at most' "$scratch/o1" \
	capped "$plume" coat "$scratch/big.json" -o "$scratch/o1"
check "the estimate and the limit ($(cat "$scratch/err.txt"))" \
	grep -qE 'the coat takes up to [0-9.]+ GB; the limit is 4.29 GB \(raise it with --max-memory' "$scratch/err.txt"
# The example of 64 feathers takes more than 1M (and its estimate says so before any is built).
expect_no_output "figure 15 under --max-memory 1M" 5 'makes 64 follicles' "$scratch/o2" \
	capped "$plume" coat "$examples/coats/figure15-hexagonal.json" -o "$scratch/o2" --max-memory 1M

# An empty --format item is a typo, refused as generate and grow refuse it (cli_parse_formats).
expect_no_output "coat: an empty --format item" 2 "--format 'png,' has an empty item" "$scratch/o3" \
	"$plume" coat "$examples/coats/figure15-hexagonal.json" -o "$scratch/o3" --format png,

# --- the outputs: a coat that fits, whose SVG does not ---------------------------------------------
printf '{"model": "coat", "surface": {"type": "plane", "size": [0.03, 0.03]}, "follicles": {"spacing": 2e-3}, "key_feathers": [{"at": [0, 0, 0], "feather": "key-contour.json"}]}' >"$scratch/mid.json"
capped "$plume" coat "$scratch/mid.json" -o "$scratch/o3" --max-memory 1M 2>"$scratch/err.txt"
coat_kb=$(kb_of "$scratch/err.txt" 'the coat takes up to [0-9.e+]+ GB')
check "the coat's estimate ($(cat "$scratch/err.txt"))" test "${coat_kb:-0}" -gt 1000
expect_no_output "its svg past the limit" 5 'writing svg (--format, --size 1200x1200) takes up to' "$scratch/o4" \
	capped "$plume" coat "$scratch/mid.json" -o "$scratch/o4" --format svg --max-memory $((coat_kb * 1024 / 1000 + 1024))K
check "the outputs' estimate and the limit ($(cat "$scratch/err.txt"))" \
	grep -qE "besides the coat's [0-9.e+]+ GB: [0-9.e+]+ GB in all; the limit is" "$scratch/err.txt"
total_kb=$(kb_of "$scratch/err.txt" ': [0-9.e+]+ GB in all')
# Given that much, it runs, and within it.
read -r status peak_kb <<<"$(rss "$plume" coat "$scratch/mid.json" -o "$scratch/o5" --format svg,glb,png --max-memory $((total_kb * 1024 / 1000 + 1024))K)"
check "svg, glb, png within the estimate: exit $status" test "$status" -eq 0
check "peak RSS ${peak_kb} KB within the estimate ${total_kb} KB + the program's ${program_kb} KB" \
	within "$peak_kb" $((total_kb + program_kb))
check "coat.svg, coat.glb and coat.png written" test -s "$scratch/o5/coat.svg" -a -s "$scratch/o5/coat.glb" -a -s "$scratch/o5/coat.png"

# --- generate: a GLB streams to its file (it held two copies of the ribbons in doubles) -------------
printf '{"model": "franco-walter", "barb_samples": 100, "segments": [{"barb_count": 500}, {"barb_count": 500}]}' >"$scratch/dense.json"
read -r status peak_kb <<<"$(rss "$plume" generate "$scratch/dense.json" -o "$scratch/o6" --format glb --max-memory 64M)"
check "generate --format glb of 200,000 barb points: exit $status" test "$status" -eq 0
check "its peak RSS ${peak_kb} KB within --max-memory 64M + the program's ${program_kb} KB" \
	within "$peak_kb" $((65536 + program_kb))
check "feather.glb written" test -s "$scratch/o6/feather.glb"
check "no spooled chunk left" test -z "$(ls -A "$scratch/o6" | grep -v '^feather.glb$' | grep -v '^.plume-run$')"
expect_no_output "generate: its svg past a limit that the feather fits" 5 'writing svg (--format) takes up to' "$scratch/o7" \
	capped "$plume" generate "$scratch/dense.json" -o "$scratch/o7" --format svg --max-memory 24M

# --- a surface seen from behind: no follicle faces +z ----------------------------------------------
printf 'v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nf 1 3 2\n' >"$scratch/flipped.obj"
printf '{"model": "coat", "surface": {"type": "mesh", "obj": "flipped.obj"}, "follicles": {"layout": "poisson", "spacing": 0.01}, "key_feathers": [{"at": [0, 0, 0], "feather": "key-contour.json"}]}' >"$scratch/flipped.json"
capped "$plume" coat "$scratch/flipped.json" -o "$scratch/o8" >/dev/null 2>"$scratch/err.txt"
succeeded "coat of a surface seen from behind"
check "its picture, obj and usda written" test -s "$scratch/o8/coat.png" -a -s "$scratch/o8/coat.obj" -a -s "$scratch/o8/coat.usda"
check "a warning says why the picture is empty ($(cat "$scratch/err.txt"))" \
	grep -qF 'warning: no follicle faces +z' "$scratch/err.txt"
capped "$plume" coat "$scratch/flipped.json" -o "$scratch/o9" --format obj,glb >/dev/null 2>"$scratch/err.txt"
succeeded "the same without a picture"
check "no warning without a picture" test ! -s "$scratch/err.txt"
finish
