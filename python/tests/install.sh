#!/usr/bin/env bash
# `pip install ./python` the way a user does, offline: libplume installed with `make install` into a
# prefix, found through pkg-config; Debian's pip in a virtual environment with the system's cffi
# and NumPy, and no package index. Then a feather from it.
# Usage: python/tests/install.sh BUILD_DIR   (run by .ci/run)
set -euo pipefail
build=$(cd "$1" && pwd)
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

cmake --install "$build" --prefix "$scratch/prefix" >/dev/null
pc=$(dirname "$(find "$scratch/prefix" -name plume.pc | head -1)")
/usr/bin/python3 -m venv --system-site-packages "$scratch/venv"
cp -r "$source_dir/python" "$scratch/src"  # pip builds in place: keep the source tree clean
PKG_CONFIG_PATH=$pc "$scratch/venv/bin/pip" install -q --no-index "$scratch/src"
cd "$scratch"
"$scratch/venv/bin/python" - "$source_dir" "$scratch/prefix" <<'PY'
import sys
import plume

assert plume.library_path.startswith(sys.argv[2]), plume.library_path
feather = plume.generate(f"{sys.argv[1]}/examples/franco-walter/filoplume.json")
assert feather.barb_count > 0 and feather.points.shape == (feather.info["point_count"], 3)
print(f"ok: pip-installed plume loads {plume.library_path}: {feather}")
PY
