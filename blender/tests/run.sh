#!/usr/bin/env bash
# The add-on tested headless in Blender: builds the zip, installs it into a scratch user folder,
# runs blender/tests/test_addon.py. Skips with a message when blender is absent.
# Usage: blender/tests/run.sh BUILD_DIR [RENDER.png]   (run by .ci/run; RENDER.png: a Cycles
# picture of the groomed sphere, as in docs/blender.md)
set -euo pipefail
build=$(cd "$1" && pwd)
render=${2:-}
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
if ! command -v blender >/dev/null; then
	echo "SKIP: blender is not installed (apt-get install blender); the add-on was not tested"
	exit 0
fi
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
/usr/bin/python3 "$source_dir/blender/make_zip.py" "$source_dir" "$scratch/plume_feathers.zip" >/dev/null
export BLENDER_USER_SCRIPTS=$scratch/scripts BLENDER_USER_CONFIG=$scratch/config
export PLUME_BUILD_DIR=$build
[ -n "$render" ] && render=$(realpath -m "$render")
blender -b --factory-startup --python "$source_dir/blender/tests/test_addon.py" -- "$scratch/plume_feathers.zip" \
	${render:+"$render"} 2>&1 | grep -v '^Fra:' | tee "$scratch/log.txt"
grep -q '^all checks passed' "$scratch/log.txt"
