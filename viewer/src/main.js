// plume's browser viewer: shows a feather, a coat or a simulation from the
// .glb files that `plume view` lists in models.js (window.PLUME_MODELS), with
// orbit controls and, for animated files, play/pause, a frame slider and a
// frame counter. window.plumeViewer reports what is shown (the browser test
// and the docs' screenshot script read it).
import * as THREE from "three";
import { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";

const models = Array.isArray(window.PLUME_MODELS) ? window.PLUME_MODELS : [];
const params = new URLSearchParams(window.location.search);

const state = {
	ready: false, // true once a file is loaded and drawn once
	error: null,
	file: null,
	files: models.map((m) => m.name),
	frame: 0, // keyframe index shown, 0-based like plume's frame files
	frameCount: 0, // keyframes of the animation; 0 when the file has none
	playing: false,
	objects: 0, // drawn meshes and line sets (an instance counts once per node)
	geometries: 0, // distinct geometries (a coat's instances share one)
	vertices: 0, // summed over drawn objects
	triangles: 0,
	frames: 0, // frames drawn since the page loaded
};
window.plumeViewer = state;
state.scriptAt = Math.round(performance.now()); // after the page and models.js were read

const $ = (id) => document.getElementById(id);
const view = $("view");
const playButton = $("play");
const slider = $("slider");
const counter = $("counter");
const info = $("info");
const select = $("model");
const message = $("message");

// preserveDrawingBuffer: the test and the screenshot read the canvas back.
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
// Tone mapping keeps pale feathers (and shells) from washing out to white.
renderer.toneMapping = THREE.NeutralToneMapping;
view.appendChild(renderer.domElement);

const scene = new THREE.Scene();
// A dark backdrop: feathers range from white down to near black, and light
// ones (and unlit line strips) vanish on a pale one.
scene.background = new THREE.Color(0x2f3338);
// Plain lights, no environment map: a PMREM environment costs seconds in a
// software WebGL (13 s in SwiftShader on a loaded 2-core machine), and plume's
// materials are non-metallic, so sky, ground and a key light from the camera's
// side are enough.
scene.add(new THREE.HemisphereLight(0xfff8f0, 0x6b6257, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 2.4);
scene.add(sun);

const camera = new THREE.PerspectiveCamera(35, 1, 0.001, 1000);
const controls = new OrbitControls(camera, renderer.domElement);
controls.enableDamping = true;

let content = null;
let mixer = null;
let actions = [];
let times = null; // keyframe times of the longest track
let lastTime = performance.now();

function fail(text) {
	state.error = text;
	message.textContent = text;
}

function resize() {
	const w = view.clientWidth || 1;
	const h = view.clientHeight || 1;
	renderer.setSize(w, h, false);
	camera.aspect = w / h;
	camera.updateProjectionMatrix();
}
window.addEventListener("resize", resize);

function decodeBase64(text) {
	// Native where the browser has it (Chromium 140+), else through atob.
	if (typeof Uint8Array.fromBase64 === "function") return Uint8Array.fromBase64(text).buffer;
	const binary = atob(text);
	const bytes = new Uint8Array(binary.length);
	for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
	return bytes.buffer;
}

// The box of the rest shapes and the box a sequence stays in (every morph
// target, absolute or relative to the rest positions).
function bounds(root) {
	root.updateMatrixWorld(true);
	const rest = new THREE.Box3();
	const all = new THREE.Box3();
	const p = new THREE.Vector3();
	root.traverse((object) => {
		const geometry = object.geometry;
		if (!geometry || !geometry.attributes.position) return;
		const base = geometry.attributes.position;
		for (let i = 0; i < base.count; i++) rest.expandByPoint(p.fromBufferAttribute(base, i).applyMatrix4(object.matrixWorld));
		const targets = geometry.morphAttributes.position || [];
		const relative = geometry.morphTargetsRelative;
		for (const target of targets) {
			for (let i = 0; i < target.count; i++) {
				p.fromBufferAttribute(target, i);
				if (relative) p.x += base.getX(i), p.y += base.getY(i), p.z += base.getZ(i);
				all.expandByPoint(p.applyMatrix4(object.matrixWorld));
			}
		}
	});
	all.union(rest);
	return { rest, all };
}

function frameCamera(box) {
	state.bounds = [box.min.toArray(), box.max.toArray()];
	const center = box.getCenter(new THREE.Vector3());
	const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-6);
	const distance = (1.15 * radius) / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2));
	// Three-quarters from the front (+z) and a little above: bending out of the
	// vane's plane shows, and a flat feather still fills the view.
	const direction = new THREE.Vector3(0.6, 0.25, 1).normalize();
	camera.position.copy(center).addScaledVector(direction, distance);
	camera.near = distance / 100;
	camera.far = distance * 100;
	camera.updateProjectionMatrix();
	controls.target.copy(center);
	controls.update();
	sun.position.copy(camera.position).add(new THREE.Vector3(0, distance, 0));
	sun.target.position.copy(center);
	sun.target.updateMatrixWorld();
}

function count(root) {
	let objects = 0,
		vertices = 0,
		triangles = 0;
	const geometries = new Set();
	root.traverse((object) => {
		if (!object.isMesh && !object.isLine && !object.isPoints) return;
		const geometry = object.geometry;
		const n = geometry.attributes.position.count;
		const instances = object.isInstancedMesh ? object.count : 1;
		objects += instances;
		vertices += n * instances;
		if (object.isMesh) triangles += ((geometry.index ? geometry.index.count : n) / 3) * instances;
		geometries.add(geometry);
		// Shapes move with their morph targets: bounds of the rest pose would cull them.
		if (geometry.morphAttributes.position) object.frustumCulled = false;
		// Ribbons and shells are open surfaces seen from both sides.
		for (const material of [].concat(object.material)) material.side = THREE.DoubleSide;
	});
	Object.assign(state, { objects, geometries: geometries.size, vertices, triangles });
}

function setFrame(index) {
	if (!times) return;
	index = Math.max(0, Math.min(times.length - 1, index));
	for (const action of actions) action.time = times[index];
	mixer.update(0);
	showFrame(index);
}

function showFrame(index) {
	state.frame = index;
	slider.value = String(index);
	counter.textContent = `frame ${index} / ${times.length - 1}`;
}

function setPlaying(playing) {
	state.playing = playing && !!times;
	playButton.textContent = state.playing ? "Pause" : "Play";
	lastTime = performance.now();
}

function show(gltf, name) {
	if (content) scene.remove(content);
	content = gltf.scene;
	scene.add(content);
	count(content);
	// The whole sequence in view, unless the shape travels far (a falling
	// feather): then the rest shape, which a user can follow with the controls.
	const box = bounds(content);
	const size = (b) => b.getSize(new THREE.Vector3()).length();
	frameCamera(size(box.all) > 3 * size(box.rest) ? box.rest : box.all);

	mixer = null;
	actions = [];
	times = null;
	if (gltf.animations.length > 0) {
		mixer = new THREE.AnimationMixer(content);
		for (const clip of gltf.animations) {
			actions.push(mixer.clipAction(clip).play());
			for (const track of clip.tracks)
				if (!times || track.times.length > times.length) times = track.times;
		}
		if (times.length < 2) times = null;
	}
	state.file = name;
	state.frameCount = times ? times.length : 0;
	slider.disabled = playButton.disabled = !times;
	if (times) {
		slider.max = String(times.length - 1);
		const start = params.has("frame") ? Number.parseInt(params.get("frame"), 10) || 0 : 0;
		setFrame(start);
		setPlaying(!params.has("frame"));
	} else {
		counter.textContent = "no animation";
		setPlaying(false);
	}
	const n = (x) => Math.round(x).toLocaleString("en-US");
	info.textContent = `${name}: ${n(state.objects)} objects, ${n(state.vertices)} vertices, ${n(state.triangles)} triangles`;
	info.title = info.textContent;
	state.ready = false;
	state.drawnAt = state.frames;
}

function load(index) {
	const model = models[index];
	state.error = null;
	message.textContent = "";
	const loader = new GLTFLoader();
	const requested = performance.now();
	const done = (gltf) => {
		state.parseMs = Math.round(performance.now() - requested);
		show(gltf, model.name);
	};
	const error = (e) => fail(`plume viewer: cannot read ${model.name}: ${e && e.message ? e.message : e}`);
	try {
		if (model.data !== undefined) {
			const started = performance.now();
			const buffer = decodeBase64(model.data);
			state.decodeMs = Math.round(performance.now() - started);
			loader.parse(buffer, "", done, error);
		}
		else loader.load(model.url, done, undefined, error);
	} catch (e) {
		error(e);
	}
}

playButton.addEventListener("click", () => setPlaying(!state.playing));
slider.addEventListener("input", () => {
	setPlaying(false);
	setFrame(Number.parseInt(slider.value, 10));
});
window.addEventListener("keydown", (event) => {
	if (event.target !== document.body || !times) return;
	if (event.key === " ") setPlaying(!state.playing), event.preventDefault();
	else if (event.key === "ArrowRight") setPlaying(false), setFrame(state.frame + 1);
	else if (event.key === "ArrowLeft") setPlaying(false), setFrame(state.frame - 1);
});
select.addEventListener("change", () => load(select.selectedIndex));

function animate() {
	const now = performance.now();
	const dt = Math.min(0.25, (now - lastTime) / 1000); // a hidden tab does not jump ahead
	lastTime = now;
	if (state.playing && mixer) {
		mixer.update(dt);
		// The keyframe at or before the clip's time (the clip loops).
		const t = actions[0].time;
		let i = 0;
		while (i + 1 < times.length && times[i + 1] <= t + 1e-6) i++;
		if (i !== state.frame) showFrame(i);
	}
	controls.update();
	renderer.render(scene, camera);
	state.frames++;
	if (content && state.frames > state.drawnAt) state.ready = true;
	requestAnimationFrame(animate);
}

resize();
if (models.length === 0) {
	fail("plume viewer: no .glb file listed (models.js). Write the page with `plume view DIR`.");
} else {
	if (models.length > 1) {
		for (const m of models) select.add(new Option(m.name));
		select.hidden = false;
	}
	const wanted = params.has("file") ? models.findIndex((m) => m.name === params.get("file")) : 0;
	select.selectedIndex = Math.max(0, wanted);
	load(Math.max(0, wanted));
}
requestAnimationFrame(animate);
