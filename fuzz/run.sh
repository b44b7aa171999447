#!/usr/bin/env bash
# Runs every libFuzzer harness for SECONDS each (default 60) from a copy of its
# corpus in fuzz/corpus/<reader>/ (new inputs stay in the copy; add findings to
# the repository's corpus by hand). Fails on the first crash, sanitizer report,
# leak (LeakSanitizer), hang past 30 s or memory past 2 GiB; the reproducer
# lands in BUILD/fuzz-findings/. 30 s, not libFuzzer's usual 10: fuzz/slow/ holds
# an input that is slow but finite (a 10 m feather meshed at 4 mm: 3 s in a
# release build, over 10 s instrumented; the strip walk of src/mesh/aligned.c is
# quadratic in guide length), kept out of the corpus until the mesher bounds it.
# Usage: fuzz/run.sh BUILD_DIR [SECONDS] [READER...]
set -euo pipefail
build=${1:?usage: fuzz/run.sh BUILD_DIR [SECONDS] [READER...]}
seconds=${2:-60}
shift $(($# >= 2 ? 2 : 1))
source_dir=$(cd "$(dirname "$0")/.." && pwd)
readers=("$@")
if [ ${#readers[@]} -eq 0 ]; then
	readers=(feather_spec coat scene lab camera mesh_spec obj feather_json)
fi
findings=$build/fuzz-findings
mkdir -p "$findings"
status=0
for reader in "${readers[@]}"; do
	corpus=$(mktemp -d /tmp/plume-corpus-XXXXXX)
	cp "$source_dir/fuzz/corpus/$reader"/* "$corpus/"
	echo "== fuzz_$reader for ${seconds} s"
	if ! OMP_NUM_THREADS=1 "$build/fuzz/fuzz_$reader" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=2048 \
		-max_len=65536 -artifact_prefix="$findings/$reader-" -print_final_stats=1 "$corpus" \
		>"$findings/$reader.log" 2>&1; then
		echo "FAIL: fuzz_$reader (log: $findings/$reader.log)"
		tail -40 "$findings/$reader.log"
		status=1
	else
		grep -E 'stat::number_of_executed_units|stat::peak_rss_mb' "$findings/$reader.log" || true
	fi
	rm -rf "$corpus"
done
exit $status
