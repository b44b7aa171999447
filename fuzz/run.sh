#!/usr/bin/env bash
# Runs every libFuzzer harness for SECONDS each (default 60) from a copy of its
# corpus in fuzz/corpus/<reader>/ (new inputs stay in the copy; add findings to
# the repository's corpus by hand: libFuzzer runs every corpus input first, so
# each past finding is a regression test). Fails on the first crash, sanitizer
# report, leak (LeakSanitizer), memory past 2 GiB or input slower than 30 s
# (a hang: the readers refuse work past their size limits before doing it, and
# the mesher's work is near-linear in its output); the reproducer lands in
# BUILD/fuzz-findings/.
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
		if grep -q '^SUMMARY: libFuzzer: timeout' "$findings/$reader.log"; then
			echo "FAIL: fuzz_$reader: an input took over 30 s (a hang): $(ls -t "$findings/$reader"-timeout-* | head -1)"
			grep -E '^ +#[0-9]+ .* in [a-z_]+ .*/src/' "$findings/$reader.log" | head -6 || true
		else
			echo "FAIL: fuzz_$reader (log: $findings/$reader.log)"
			tail -40 "$findings/$reader.log"
		fi
		status=1
	else
		grep -E 'stat::number_of_executed_units|stat::peak_rss_mb' "$findings/$reader.log" || true
	fi
	rm -rf "$corpus"
done
exit $status
