#!/usr/bin/env bash
# Browser test of `plume view`: plume writes a feather's and a simulation's
# .glb, `plume view` writes their pages (embedded, opened as file://) and serves
# one (--serve), and headless Chromium driven by playwright-core (view.mjs)
# loads each page, checks the canvas is not empty, plays the simulation and
# checks the frame counter advances. Run by .ci/run (which installs chromium and
# nodejs/npm); skips itself with a message where they are missing.
#   tests/browser/run.sh [BUILD]        (default build; plume is BUILD/plume)
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
plume=$build/plume

skip() {
	echo "browser test skipped: $1"
	exit 0
}
command -v node >/dev/null && command -v npm >/dev/null || skip "node and npm are not installed (apt-get install nodejs npm)"
chromium=${CHROMIUM:-/usr/bin/chromium}
[[ -x "$chromium" ]] || skip "no Chromium at $chromium (apt-get install chromium, or set CHROMIUM)"
[[ -x "$plume" ]] || { echo "browser test: $plume is not built (make build)" >&2; exit 1; }
scripts/viewer.sh "$build" # the viewer and playwright-core (viewer/node_modules)
if ! "$plume" generate --help | grep -q glb; then
	echo "browser test: this plume writes no .glb (plume generate --format glb)" >&2
	exit 1
fi

scratch=$(mktemp -d /tmp/plume-browser-XXXXXX)
server=
cleanup() {
	[[ -n "$server" ]] && kill -INT "$server" 2>/dev/null && wait "$server" 2>/dev/null
	rm -rf "$scratch"
}
trap cleanup EXIT

"$plume" generate examples/franco-walter/hawk.json -o "$scratch/feather" --format glb
"$plume" simulate examples/scenes/figure1-anisotropic.json -o "$scratch/sim" >/dev/null
"$plume" view "$scratch/feather"
"$plume" view "$scratch/sim"

port=$((30000 + $$ % 20000))
"$plume" view "$scratch/sim" -o "$scratch/served" --serve "$port" >"$scratch/serve.txt" 2>&1 &
server=$!
for _ in $(seq 50); do grep -q Serving "$scratch/serve.txt" && break || sleep 0.1; done
grep -q Serving "$scratch/serve.txt" || { echo "browser test: plume view --serve: $(cat "$scratch/serve.txt")" >&2; exit 1; }

CHROMIUM=$chromium node tests/browser/view.mjs \
	"$scratch/feather/view/index.html" \
	"$scratch/sim/view/index.html:animated" \
	"http://127.0.0.1:$port/:animated"
echo "browser test passed"
