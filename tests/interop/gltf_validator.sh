#!/usr/bin/env bash
# Every kind of .glb the plume command writes (feather ribbons, shell, animated
# simulation, coat) through the Khronos glTF-Validator (npm "gltf-validator"):
# fails on any error or warning. Run by .ci/run; skips itself, saying why,
# where node/npm or the package cannot be had.
# Usage: tests/interop/gltf_validator.sh [PLUME_BINARY]
set -uo pipefail
cd "$(dirname "$0")/../.."
plume=${1:-build/plume}
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
	echo "gltf_validator: SKIPPED: node and npm are not installed" >&2
	exit 0
fi
scratch=$(mktemp -d /tmp/plume-gltf-XXXXXX)
trap 'rm -rf "$scratch"' EXIT
if ! (cd "$scratch" && npm install --silent --no-audit --no-fund gltf-validator@2.0.0-dev.3.10 >npm.log 2>&1); then
	echo "gltf_validator: SKIPPED: npm could not install gltf-validator: $(tail -3 "$scratch/npm.log")" >&2
	exit 0
fi
cat >"$scratch/validate.js" <<'JS'
const validator = require('gltf-validator');
const fs = require('fs');
(async () => {
	let failed = 0;
	for (const file of process.argv.slice(2)) {
		const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {maxIssues: 20});
		const {numErrors, numWarnings} = report.issues;
		console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings`);
		for (const m of report.issues.messages.filter(m => m.severity <= 1))
			console.log(`  ${m.code} ${m.pointer || ''} ${m.message}`);
		if (numErrors + numWarnings > 0)
			failed++;
	}
	process.exit(failed > 0 ? 1 : 0);
})();
JS
set -e
"$plume" generate examples/franco-walter/blue.json -o "$scratch/feather" --format glb >/dev/null
"$plume" mesh examples/franco-walter/blue.json -o "$scratch/mesh" --format glb -e 0.01 >/dev/null
# The texture embedded as a PNG image, read through TEXCOORD_1.
"$plume" generate examples/franco-walter/blue.json -o "$scratch/textured" --format glb --texture examples/textures/bands.png >/dev/null
"$plume" coat examples/coats/figure15-hexagonal.json -o "$scratch/coat" --format glb >/dev/null
cat >"$scratch/swing.json" <<JSON
{"feather": "$PWD/examples/franco-walter/blue.json", "mesh": {"edge_length": 0.01},
 "handles": [{"group": "rachis_clamp"}], "gravity": [0, 0, -9.81], "duration": 0.055}
JSON
"$plume" simulate "$scratch/swing.json" -o "$scratch/sim" >/dev/null
# Many feathers carried at barb level (--glb-feather) and a turning body, all keyed by one animation.
cat >"$scratch/many.json" <<JSON
{"body": {"mesh": {"shape": "ellipsoid", "center": [0, 0, 0], "radii": [0.05, 0.05, 0.05], "segments": 12},
          "keyframes": [{"time": 0}, {"time": 0.1, "rotation_axis": [0, 0, 1], "rotation_deg": 30}]},
 "feathers": [{"feather": "$PWD/examples/franco-walter/blue.json", "name": "top", "position": [0, 0, 0.05], "follicle": {}},
              {"feather": "$PWD/examples/franco-walter/blue.json", "position": [0.5, 0, 0]}],
 "mesh": {"edge_length": 0.015}, "handles": [{"group": "f1/rachis_clamp"}], "duration": 0.022}
JSON
"$plume" simulate "$scratch/many.json" -o "$scratch/many" --glb-feather >/dev/null
set +e
(cd "$scratch" && NODE_PATH="$scratch/node_modules" node validate.js feather/feather.glb textured/feather.glb mesh/mesh.glb coat/coat.glb sim/sim.glb many/sim.glb)
