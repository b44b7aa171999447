// Builds plume's browser viewer: one classic script (no ES modules, which
// Chromium refuses from file:// pages) beside the page, three.js's licence kept.
//   node build.mjs [--outdir DIR]   (default ../build/viewer)
import { build } from "esbuild";
import { copyFileSync, mkdirSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const at = process.argv.indexOf("--outdir");
const outdir = resolve(at > 0 ? process.argv[at + 1] : join(here, "..", "build", "viewer"));
mkdirSync(outdir, { recursive: true });

await build({
	entryPoints: [join(here, "src", "main.js")],
	bundle: true,
	format: "iife",
	target: "es2020",
	minify: true,
	legalComments: "eof",
	outfile: join(outdir, "plume-viewer.js"),
	logLevel: "warning",
});
copyFileSync(join(here, "src", "index.html"), join(outdir, "index.html"));
copyFileSync(join(here, "node_modules", "three", "LICENSE"), join(outdir, "LICENSE.three.txt"));
console.log(`plume viewer: ${outdir}`);
