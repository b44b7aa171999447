#!/usr/bin/env bash
# Installs the Debian packages plume needs when they are missing.
# As root: apt-get installs them. Otherwise: prints the exact command and fails.
set -euo pipefail

packages=(build-essential cmake pkg-config libcairo2-dev libjansson-dev libstb-dev libcmocka-dev
	libsuitesparse-dev libopenblas0-serial libembree-dev libqhull-dev libplplot-dev libgmp-dev)
# The Python binding (python/) and its tests.
packages+=(python3-cffi python3-numpy python3-pytest)
# PNG decoding in the .glb texture check (tests/glb_check.py) and the plots of python/examples.
packages+=(python3-matplotlib)

missing=()
for package in "${packages[@]}"; do
	status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
	[[ "$status" == "install ok installed" ]] || missing+=("$package")
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

if [[ $(id -u) -eq 0 ]]; then
	echo "plume: installing ${missing[*]}" >&2
	export DEBIAN_FRONTEND=noninteractive
	apt-get update -qq
	apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
	echo "plume: missing Debian packages. Run as root:" >&2
	echo "  apt-get update && apt-get install -y ${missing[*]}" >&2
	exit 1
fi
