// Loads pages written by `plume view` in headless Chromium (playwright-core)
// and checks what a user would see: the file is drawn (the canvas is not one
// flat colour), and for an animated file Play advances the frame counter, Pause
// stops it and the slider shows the frame it is set to.
//   node tests/browser/view.mjs [--screenshot PNG] PAGE[:animated|:still] ...
// PAGE is an index.html (opened as file://) or the URL of `plume view --serve`.
// Exit 0 when every page passes; prints one line per check.
import { createRequire } from "node:module";
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
// playwright-core is a dev dependency of the viewer (viewer/package.json).
const require = createRequire(join(here, "..", "..", "viewer", "package.json"));
const { chromium } = require("playwright-core");

const args = process.argv.slice(2);
let screenshot = null;
const pages = [];
for (let i = 0; i < args.length; i++) {
	if (args[i] === "--screenshot") screenshot = args[++i];
	else pages.push(args[i]);
}
if (pages.length === 0) {
	console.error("usage: node view.mjs [--screenshot PNG] PAGE.html[:animated|:still] ...");
	process.exit(2);
}

const profile = mkdtempSync(join(tmpdir(), "plume-chromium-"));
const browser = await chromium.launchPersistentContext(profile, {
	executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
	headless: true,
	viewport: { width: 960, height: 640 },
	args: [
		"--headless",
		"--no-sandbox",
		"--disable-gpu",
		"--disable-quic",
		"--no-first-run",
		"--disable-background-networking",
		"--disable-component-update",
		"--disable-sync",
		// WebGL without a GPU: SwiftShader, Chromium's software renderer.
		"--use-angle=swiftshader",
		"--enable-unsafe-swiftshader",
	],
});

let failures = 0;
function check(ok, what) {
	console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
	if (!ok) failures++;
}

// The canvas read back in the page: the colour variance (summed over R, G
// and B, so a brown feather on a grey backdrop of the same luminance still
// counts) and the share of pixels that differ from the background colour (the
// top-left pixel).
async function canvasStats(page) {
	return page.evaluate(() => {
		const source = document.querySelector("#view canvas");
		const w = source.width,
			h = source.height;
		const copy = document.createElement("canvas");
		copy.width = w;
		copy.height = h;
		const context = copy.getContext("2d");
		context.drawImage(source, 0, 0);
		const data = context.getImageData(0, 0, w, h).data;
		const sum = [0, 0, 0],
			sum2 = [0, 0, 0];
		let differ = 0;
		for (let i = 0; i < data.length; i += 4) {
			for (let c = 0; c < 3; c++) {
				sum[c] += data[i + c];
				sum2[c] += data[i + c] * data[i + c];
			}
			if (Math.abs(data[i] - data[0]) + Math.abs(data[i + 1] - data[1]) + Math.abs(data[i + 2] - data[2]) > 24) differ++;
		}
		const n = w * h;
		let variance = 0;
		for (let c = 0; c < 3; c++) variance += sum2[c] / n - (sum[c] / n) ** 2;
		return { width: w, height: h, variance, covered: differ / n };
	});
}

try {
	for (const spec of pages) {
		const [file, kind = "still"] = spec.split(/:(?=animated$|still$)/);
		const url = (/^https?:/.test(file) ? file : pathToFileURL(resolve(file)).href) + "?frame=0";
		const page = await browser.newPage();
		const errors = [];
		page.on("pageerror", (e) => errors.push(e.message));
		page.on("console", (m) => m.type() === "error" && errors.push(m.text()));
		const started = Date.now();
		// Generous: SwiftShader on a loaded 2-core machine takes tens of seconds.
		await page.goto(url, { timeout: 180000 });
		await page.waitForFunction(() => window.plumeViewer && (window.plumeViewer.ready || window.plumeViewer.error), null, {
			timeout: 180000,
		});
		const state = await page.evaluate(() => ({ ...window.plumeViewer }));
		check(!state.error && errors.length === 0, `${file}: loaded ${state.file} in ${Date.now() - started} ms ${state.error || errors.join("; ")}`);
		check(state.vertices > 0, `${file}: ${state.objects} objects, ${state.vertices} vertices, ${state.triangles} triangles`);
		const stats = await canvasStats(page);
		check(stats.variance > 20 && stats.covered > 0.005,
			`${file}: canvas ${stats.width}x${stats.height} not empty (colour variance ${stats.variance.toFixed(1)}, ${(100 * stats.covered).toFixed(1)}% of pixels drawn)`);

		if (kind === "animated") {
			check(state.frameCount > 1 && state.frame === 0 && !state.playing,
				`${file}: ${state.frameCount} frames, paused at frame ${state.frame}`);
			const counter0 = await page.textContent("#counter");
			await page.click("#play");
			await page.waitForFunction(() => window.plumeViewer.frame >= 2, null, { timeout: 60000 });
			const counter1 = await page.textContent("#counter");
			check(counter1 !== counter0 && /^frame \d+ \/ \d+$/.test(counter1), `${file}: playing, counter "${counter0}" -> "${counter1}"`);
			const moved = await canvasStats(page);
			check(moved.variance > 20 && moved.covered > 0.005, `${file}: canvas still drawn while playing (variance ${moved.variance.toFixed(1)})`);
			await page.click("#play");
			const paused = await page.evaluate(() => window.plumeViewer.frame);
			await page.waitForTimeout(500);
			const still = await page.evaluate(() => window.plumeViewer.frame);
			check(paused === still, `${file}: paused stays at frame ${still}`);
			const last = state.frameCount - 1;
			await page.$eval("#slider", (s, v) => {
				s.value = String(v);
				s.dispatchEvent(new Event("input"));
			}, last);
			const counter2 = await page.textContent("#counter");
			check(counter2 === `frame ${last} / ${last}`, `${file}: slider to the last frame shows "${counter2}"`);
		} else {
			check(state.frameCount === 0, `${file}: no animation (${await page.textContent("#counter")})`);
		}
		if (screenshot) await page.screenshot({ path: screenshot });
		await page.close();
	}
} finally {
	await browser.close();
	rmSync(profile, { recursive: true, force: true });
}
if (failures > 0) {
	console.log(`${failures} check(s) failed`);
	process.exit(1);
}
