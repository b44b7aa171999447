#!/usr/bin/env bash
# Builds plume's browser viewer (viewer/, three.js bundled by esbuild) into
# BUILD/viewer, where `plume view` finds it beside the binary; `make install`
# copies it to <prefix>/share/plume/viewer. Needs node (>= 18) and npm; the
# packages come from npm once (viewer/package-lock.json pins them), after
# which building and viewing work offline.
#   scripts/viewer.sh BUILD [--optional]
# --optional (used by `make build`): a missing node/npm or a failed download
# prints a note and succeeds, since everything but `plume view` works without.
set -uo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
optional=false
[[ "${2:-}" == "--optional" ]] && optional=true

give_up() {
	if $optional; then
		echo "plume: note: browser viewer not built ($1); \`plume view\` needs it: see README (make viewer)" >&2
		exit 0
	fi
	echo "plume: viewer: $1" >&2
	exit 1
}

command -v node >/dev/null && command -v npm >/dev/null ||
	give_up "node and npm are missing: as root, apt-get install -y nodejs npm"
major=$(node -p 'process.versions.node.split(".")[0]')
((major >= 18)) || give_up "node $(node --version) is too old (18 or newer)"

# npm ci only when the installed packages are not those of the lock file.
if [[ ! -f viewer/node_modules/.package-lock.json || viewer/package-lock.json -nt viewer/node_modules/.package-lock.json ]]; then
	echo "plume: viewer: npm ci (three.js, esbuild, playwright-core)" >&2
	(cd viewer && npm ci --prefer-offline --no-audit --no-fund --loglevel=error >/dev/null) || give_up "npm ci failed in viewer/ (no network?)"
fi

# Bundle only when a source is newer than the bundle.
out="$build/viewer/plume-viewer.js"
if [[ -f "$out" && -z $(find viewer/src viewer/build.mjs viewer/node_modules/.package-lock.json -newer "$out" 2>/dev/null) ]]; then
	exit 0
fi
node viewer/build.mjs --outdir "$build/viewer" >/dev/null || give_up "esbuild failed"
