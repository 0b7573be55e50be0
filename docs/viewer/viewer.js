// trilux viewer: shows a baked .glb (unlit, COLOR_0 = linear outgoing
// radiance) exactly as trilux's PNG encoding would: value × 2^stops, clamped
// to [0, 1], then the sRGB transfer function. Any other glTF opens too (lit
// materials get a default headlight; a file without a camera is framed).
//
// Query parameters: file=URL, exposure=STOPS, ui=0 (no overlays),
// width=PX & height=PX (fixed canvas size instead of the window's),
// mode=walk|orbit|fly (else walk when the file's camera is enclosed by the
// scene, orbit when not), glossy=0 (diffuse only: the baked glossy light,
// glossy.js, left out; G toggles it), lookat=ox,oy,oz,tx,ty,tz[,ux,uy,uz]
// (the first view from that eye towards that target, up +y unless given,
// with the file camera's field of view: trilux render's --lookat),
// mask=glossy (glossy sides white, the rest black, no tone mapping: which
// pixels show baked glossy light, for tests).
// The bar shows the frame rate (frames drawn back to back while moving);
// window.viewer.frameTime(n) times n frames drawn on demand (for tests).
// window.viewerReady becomes true once the first frame of a file is drawn;
// window.viewerError holds the message of a failure (also shown on the page).

import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { PointerLockControls } from 'three/addons/controls/PointerLockControls.js';
import { Walker } from './walk.js';
import { useGlossyAttributes } from './glossy.js';

const params = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);
const ui = {
	stage: $('stage'), file: $('file'), exposure: $('exposure'), exposureText: $('exposure-text'),
	sceneCamera: $('scene-camera'), navMode: $('nav-mode'), info: $('info'), error: $('error'),
	menu: $('menu'), panel: $('panel'), notice: $('notice'), glossyList: $('glossy-list'),
	glossy: $('glossy'), fps: $('fps'),
};
const MODES = ['orbit', 'walk', 'fly'];

window.viewerReady = false;
window.viewerError = undefined;
window.viewerInfo = undefined;
window.viewerNotice = null;

if (params.get('ui') === '0') document.body.classList.add('no-ui');

function fail(message) {
	window.viewerError = message;
	window.viewerReady = false;
	ui.error.textContent = message;
	ui.error.classList.add('shown');
	console.error(`viewer: ${message}`);
}
function clearError() {
	window.viewerError = undefined;
	ui.error.textContent = '';
	ui.error.classList.remove('shown');
}

// ---------------------------------------------------------------- size

function positiveInt(name) {
	const v = params.get(name);
	if (v === null) return null;
	const n = Number(v);
	if (!Number.isInteger(n) || n <= 0 || n > 16384) {
		fail(`${name}=${v} is not a size in pixels (1..16384)`);
		return null;
	}
	return n;
}
const fixedW = positiveInt('width');
const fixedH = positiveInt('height');
const fixedSize = fixedW !== null || fixedH !== null;
const modeParam = params.get('mode');
if (modeParam !== null && !['orbit', 'walk', 'fly'].includes(modeParam)) fail(`mode=${modeParam} is not walk, orbit or fly`);

function viewSize() {
	return {
		w: fixedW ?? window.innerWidth,
		h: fixedH ?? window.innerHeight,
	};
}

// ---------------------------------------------------------------- renderer

let frameRequested = false; // a frame is scheduled (rendering is on demand)
let afterFrame = []; // callbacks run once the next frame is drawn

let renderer;
try {
	renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
} catch (e) {
	fail(`WebGL is not available in this browser: ${e && e.message ? e.message : e}`);
	throw e;
}
// The tone-mapping rule of trilux's PNGs: clamp(value × 2^stops, 0, 1), then
// the sRGB curve. LinearToneMapping is saturate(toneMappingExposure × c), and
// SRGBColorSpace output applies the sRGB transfer function after it, in the
// fragment shader of every material whose toneMapped is true (the default,
// MeshBasicMaterial included) when drawing to the canvas.
renderer.outputColorSpace = THREE.SRGBColorSpace;
renderer.toneMapping = THREE.LinearToneMapping;
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setClearColor(0x000000, 1);
ui.stage.appendChild(renderer.domElement);
renderer.domElement.tabIndex = 0;
if (fixedSize) ui.stage.classList.add('fixed-size');

const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 1000);
scene.add(camera);

// A headlight for lit (non-unlit) materials only; baked unlit files ignore it.
const lights = new THREE.Group();
lights.add(new THREE.HemisphereLight(0xffffff, 0x404040, 1.5));
const headlight = new THREE.DirectionalLight(0xffffff, 2.0);
headlight.position.set(0.3, 0.6, 1);
camera.add(headlight);
camera.add(headlight.target);
headlight.target.position.set(0, 0, -1);
headlight.visible = false;
lights.visible = false;
scene.add(lights);

// ---------------------------------------------------------------- state

const state = {
	model: null, // THREE.Object3D of the loaded scene
	name: '',
	bbox: new THREE.Box3(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1)),
	center: new THREE.Vector3(),
	radius: 1,
	view: null, // the scene camera: {position, quaternion, fovY (deg), aspect|null, near, from}
	fovY: 45, // vertical field of view of the current view, degrees, before fitting
	aspect: null, // the aspect whose full width must stay visible (the scene camera's)
	near: 0.01,
	mode: 'orbit',
	inside: false, // the file's camera is enclosed by the scene (walk by default)
	exposureFromUrl: params.has('exposure'),
	exposureTouched: false,
	loadSeq: 0,
	glossy: [], // names of the materials whose glossy light the bake left out
};

// ---------------------------------------------------------------- exposure

function setExposure(stops, fromUser = false) {
	if (!Number.isFinite(stops)) return;
	state.stops = stops;
	if (fromUser) state.exposureTouched = true;
	renderer.toneMappingExposure = Math.pow(2, stops);
	ui.exposure.value = String(Math.max(-8, Math.min(8, stops)));
	const factor = Math.pow(2, stops);
	const f = factor >= 100 || factor < 0.01 ? factor.toExponential(2) : factor.toPrecision(3);
	ui.exposureText.textContent = `${stops >= 0 ? '+' : '−'}${Math.abs(stops).toFixed(1)} stops (×${f})`;
	requestRender();
}
{
	const e = params.get('exposure');
	if (e !== null) {
		const v = Number(e);
		if (e.trim() === '' || !Number.isFinite(v)) fail(`exposure=${e} is not a number of stops`);
		else setExposure(v);
	} else setExposure(0);
}
ui.exposure.addEventListener('input', () => setExposure(Number(ui.exposure.value), true));

// ---------------------------------------------------------------- controls

const orbit = new OrbitControls(camera, renderer.domElement);
orbit.addEventListener('change', () => requestRender());

const fly = new PointerLockControls(camera, renderer.domElement);
fly.addEventListener('change', () => requestRender());
fly.addEventListener('lock', () => requestRender());
fly.addEventListener('unlock', () => requestRender());
const keys = new Set();
const walker = new Walker(camera, renderer.domElement, () => state.model, () => requestRender());

function forward(out = new THREE.Vector3()) {
	return out.set(0, 0, -1).applyQuaternion(camera.quaternion);
}

function setMode(mode) {
	if (!MODES.includes(mode)) return;
	const was = state.mode;
	state.mode = mode;
	if (mode !== 'fly' && fly.isLocked) fly.unlock();
	if (mode !== was) keys.clear();
	if (mode === 'walk') walker.enable();
	else walker.disable();
	if (mode !== 'orbit') {
		orbit.enabled = false;
	} else if (was !== 'orbit') {
		const d = Math.max(camera.position.distanceTo(orbit.target), state.radius * 0.05);
		orbit.target.copy(camera.position).addScaledVector(forward(), d);
		orbit.enabled = true;
		orbit.update();
	}
	ui.navMode.textContent = mode;
	ui.navMode.setAttribute('aria-pressed', String(mode !== 'orbit'));
	if (window.viewerInfo) window.viewerInfo.mode = mode;
	requestRender();
}
const nextMode = () => MODES[(MODES.indexOf(state.mode) + 1) % MODES.length];
ui.navMode.addEventListener('click', () => setMode(nextMode()));
renderer.domElement.addEventListener('click', () => {
	if (state.mode === 'fly' && !fly.isLocked) fly.lock();
});

const FLY_KEYS = new Set(['KeyW', 'KeyA', 'KeyS', 'KeyD', 'KeyQ', 'KeyE', 'ArrowUp', 'ArrowDown',
	'ArrowLeft', 'ArrowRight', 'PageUp', 'PageDown']);
window.addEventListener('keydown', (e) => {
	if (e.target instanceof HTMLInputElement) return;
	if (e.ctrlKey || e.metaKey || e.altKey) return;
	if (e.code === 'KeyV') setMode(nextMode());
	else if (e.code === 'KeyH') togglePanel();
	else if (e.code === 'KeyC') goToSceneCamera();
	else if (e.code === 'KeyG') setGlossy(glossyUniform.value === 0);
	else if (e.code === 'BracketLeft') setExposure(Math.round((state.stops - 0.5) * 2) / 2, true);
	else if (e.code === 'BracketRight') setExposure(Math.round((state.stops + 0.5) * 2) / 2, true);
	else if (state.mode !== 'orbit' && FLY_KEYS.has(e.code)) {
		keys.add(e.code);
		e.preventDefault();
		requestRender();
	}
});
window.addEventListener('keyup', (e) => keys.delete(e.code));
window.addEventListener('blur', () => keys.clear());

let lastTime = null;
function flyStep(now) {
	if (state.mode === 'orbit' || keys.size === 0) {
		lastTime = null;
		return false;
	}
	const dt = lastTime === null ? 1 / 60 : Math.min(0.1, (now - lastTime) / 1000);
	lastTime = now;
	if (state.mode === 'walk') return walker.keys(keys, dt);
	const speed = state.radius * 0.6 * (keys.has('ShiftLeft') || keys.has('ShiftRight') ? 4 : 1);
	const d = speed * dt;
	const has = (...c) => c.some((k) => keys.has(k));
	if (has('KeyW', 'ArrowUp')) camera.position.addScaledVector(forward(), d);
	if (has('KeyS', 'ArrowDown')) camera.position.addScaledVector(forward(), -d);
	if (has('KeyD', 'ArrowRight')) fly.moveRight(d);
	if (has('KeyA', 'ArrowLeft')) fly.moveRight(-d);
	if (has('KeyE', 'PageUp')) camera.position.y += d;
	if (has('KeyQ', 'PageDown')) camera.position.y -= d;
	return true;
}
// Shift is tracked for the speed only.
window.addEventListener('keydown', (e) => {
	if (e.code === 'ShiftLeft' || e.code === 'ShiftRight') keys.add(e.code);
});

// ---------------------------------------------------------------- rendering

function requestRender() {
	if (frameRequested || !renderer) return;
	frameRequested = true;
	requestAnimationFrame(frame);
}
function frame(now) {
	frameRequested = false;
	const moving = flyStep(now);
	showFrameRate(now, moving);
	drawNow();
	updateNotice();
	if (moving) requestRender();
	const callbacks = afterFrame;
	afterFrame = [];
	for (const cb of callbacks) cb();
}
function drawNow() {
	const { w, h } = viewSize();
	const size = renderer.getSize(new THREE.Vector2());
	if (size.x !== w || size.y !== h) renderer.setSize(w, h, true);
	const canvasAspect = w / h;
	camera.aspect = canvasAspect;
	// yfov is vertical; when the canvas is narrower than the scene camera's
	// aspect ratio, widen the vertical field so that its full width stays visible.
	let fov = state.fovY;
	if (state.aspect !== null && canvasAspect < state.aspect) {
		const t = Math.tan(THREE.MathUtils.degToRad(fov) / 2) * state.aspect / canvasAspect;
		fov = THREE.MathUtils.radToDeg(2 * Math.atan(t));
	}
	camera.fov = fov;
	camera.near = state.near;
	camera.far = Math.max(state.near * 10, camera.position.distanceTo(state.center) + 2 * state.radius);
	camera.updateProjectionMatrix();
	renderer.render(scene, camera);
}
window.addEventListener('resize', () => requestRender());

// ---------------------------------------------------------------- glossy light, frame rate

// Scales the baked glossy light (glossy.js): 1 shown, 0 diffuse only.
const glossyUniform = { value: params.get('glossy') === '0' ? 0 : 1 };
function setGlossy(on) {
	glossyUniform.value = on ? 1 : 0;
	ui.glossy.setAttribute('aria-pressed', String(on));
	ui.glossy.textContent = on ? 'glossy' : 'diffuse';
	if (window.viewerInfo) window.viewerInfo.glossyShown = on;
	requestRender();
}
ui.glossy.addEventListener('click', () => setGlossy(glossyUniform.value === 0));

// Frames drawn back to back (a frame scheduled by the one before, while
// moving) give the rate; the bar keeps the last figure when idle.
let lastFrame = null;
let frameMs = null;
function showFrameRate(now, moving) {
	if (lastFrame !== null && now - lastFrame < 1000) {
		frameMs = frameMs === null ? now - lastFrame : 0.8 * frameMs + 0.2 * (now - lastFrame);
		ui.fps.textContent = `${(1000 / frameMs).toFixed(0)} fps`;
	}
	lastFrame = moving ? now : null;
}

// Milliseconds per frame over n frames, each drawn and waited for (one
// pixel read back), after one frame not counted (shader compilation).
function frameTime(n = 20) {
	const gl = renderer.getContext();
	const px = new Uint8Array(4);
	const one = () => {
		drawNow();
		gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
	};
	one();
	const t0 = performance.now();
	for (let i = 0; i < n; i++) one();
	return (performance.now() - t0) / n;
}

// ---------------------------------------------------------------- overlay

// The panel (file, exposure, what was loaded, help) is folded by default so
// that a small screen keeps the view: only the bar and, where it applies,
// the one-line notice show.
function togglePanel(open = ui.panel.hidden) {
	ui.panel.hidden = !open;
	ui.menu.setAttribute('aria-expanded', String(open));
}
ui.menu.addEventListener('click', () => togglePanel());

// A bake leaves out the glossy (view-dependent) light of the materials it
// marks extras.trilux.glossy_left_out; such a surface under the mouse (or at
// the centre of the view) says so instead of just looking dark.
const GLOSSY_NOTICE = 'glossy reflections not baked here (trilux render shows them)';
const probe = new THREE.Raycaster();

function glossyLeftOut(material) {
	const t = material && material.userData && material.userData.trilux;
	return !!(t && t.glossy_left_out === true);
}

function materialAt(hit) {
	const m = hit.object.material;
	if (!Array.isArray(m)) return m;
	return hit.face ? m[hit.face.materialIndex] : m[0];
}

function updateNotice() {
	let text = null;
	if (state.model && state.glossy.length > 0) {
		const { w, h } = viewSize();
		const at = walker.hover ?? { x: w / 2, y: h / 2 };
		const rect = renderer.domElement.getBoundingClientRect();
		const ndc = new THREE.Vector2(((at.x - rect.left) / w) * 2 - 1, -((at.y - rect.top) / h) * 2 + 1);
		probe.setFromCamera(ndc, camera);
		const hit = probe.intersectObject(state.model, true).find((x) => x.object.isMesh);
		if (hit && glossyLeftOut(materialAt(hit))) text = GLOSSY_NOTICE;
	}
	if (text === window.viewerNotice) return;
	window.viewerNotice = text;
	ui.notice.textContent = text ?? '';
	ui.notice.hidden = text === null;
}

// ---------------------------------------------------------------- views

function goToSceneCamera() {
	const v = state.view;
	if (!v) return;
	if (fly.isLocked) fly.unlock();
	camera.position.copy(v.position);
	camera.quaternion.copy(v.quaternion);
	camera.updateMatrixWorld();
	state.fovY = v.fovY;
	state.aspect = v.aspect;
	state.near = v.near;
	// The orbit target lies on the view axis (so the pose is kept exactly
	// until the user drags), at the depth of the bounding box's centre.
	let t = state.center.clone().sub(v.position).dot(forward());
	if (!(t > state.radius * 0.05)) t = state.radius;
	orbit.target.copy(v.position).addScaledVector(forward(), t);
	if (state.mode === 'walk') walker.enable();
	requestRender();
}
ui.sceneCamera.addEventListener('click', () => goToSceneCamera());

function frameBox() {
	const fovY = 45;
	const dir = new THREE.Vector3(0.55, 0.45, 1).normalize();
	const dist = state.radius / Math.sin(THREE.MathUtils.degToRad(fovY) / 2) * 1.05;
	const position = state.center.clone().addScaledVector(dir, dist);
	const m = new THREE.Matrix4().lookAt(position, state.center, new THREE.Vector3(0, 1, 0));
	return {
		position, quaternion: new THREE.Quaternion().setFromRotationMatrix(m), fovY,
		aspect: null, near: Math.max(dist - 2 * state.radius, dist * 1e-3), from: 'bounding box',
	};
}

// The file's first camera (cameras[0]) where a node of the loaded scene
// carries it, else any camera in the scene, else null.
function findSceneCamera(gltf) {
	const json = gltf.parser.json;
	if (!Array.isArray(json.cameras) || json.cameras.length === 0) return null;
	gltf.scene.updateMatrixWorld(true);
	let node = null;
	let camIndex = 0;
	gltf.scene.traverse((obj) => {
		if (node) return;
		const a = gltf.parser.associations.get(obj);
		if (a && a.nodes !== undefined && json.nodes[a.nodes] && json.nodes[a.nodes].camera === 0) node = obj;
	});
	if (!node) {
		gltf.scene.traverse((obj) => {
			if (node) return;
			const a = gltf.parser.associations.get(obj);
			if (a && a.nodes !== undefined && json.nodes[a.nodes] && json.nodes[a.nodes].camera !== undefined) {
				node = obj;
				camIndex = json.nodes[a.nodes].camera;
			}
		});
	}
	if (!node) return null;
	const def = json.cameras[camIndex];
	if (!def || def.type !== 'perspective' || !def.perspective) {
		console.warn(`viewer: camera ${camIndex} is not perspective; framing the bounding box instead`);
		return null;
	}
	const p = def.perspective;
	const position = new THREE.Vector3();
	const quaternion = new THREE.Quaternion();
	node.matrixWorld.decompose(position, quaternion, new THREE.Vector3());
	return {
		position, quaternion,
		fovY: THREE.MathUtils.radToDeg(p.yfov),
		aspect: p.aspectRatio > 0 ? p.aspectRatio : null,
		near: p.znear > 0 ? p.znear : state.radius * 1e-3,
		zfar: p.zfar,
		from: `camera ${camIndex}${def.name ? ` "${def.name}"` : ''}`,
	};
}

// The view `v` seen from the lookat parameter's eye, if there is one.
function withLookat(v) {
	const text = params.get('lookat');
	if (text === null) return v;
	const n = text.split(',').map(Number);
	if (!(n.length === 6 || n.length === 9) || !n.every(Number.isFinite)) {
		fail(`lookat=${text} is not ox,oy,oz,tx,ty,tz[,ux,uy,uz]`);
		return v;
	}
	const eye = new THREE.Vector3(n[0], n[1], n[2]);
	const up = n.length === 9 ? new THREE.Vector3(n[6], n[7], n[8]) : new THREE.Vector3(0, 1, 0);
	const m = new THREE.Matrix4().lookAt(eye, new THREE.Vector3(n[3], n[4], n[5]), up);
	return { ...v, position: eye, quaternion: new THREE.Quaternion().setFromRotationMatrix(m), from: `lookat ${text}` };
}

// Glossy sides (extras.trilux.glossy) white, every other surface black.
function maskGlossy(root) {
	const white = new THREE.MeshBasicMaterial({ color: 0xffffff, toneMapped: false });
	const black = new THREE.MeshBasicMaterial({ color: 0x000000, toneMapped: false });
	root.traverse((obj) => {
		if (!obj.isMesh) return;
		const pick = (m) => {
			const t = m && m.userData && m.userData.trilux;
			return t && t.glossy ? white : black;
		};
		obj.material = Array.isArray(obj.material) ? obj.material.map(pick) : pick(obj.material);
	});
}

// ---------------------------------------------------------------- loading

const loader = new GLTFLoader();

function disposeModel() {
	if (!state.model) return;
	scene.remove(state.model);
	state.model.traverse((obj) => {
		if (obj.geometry) obj.geometry.dispose();
		const mats = obj.material ? (Array.isArray(obj.material) ? obj.material : [obj.material]) : [];
		for (const m of mats) {
			for (const v of Object.values(m)) if (v && v.isTexture) v.dispose();
			m.dispose();
		}
	});
	state.model = null;
}

// A bake may keep COLOR_0 within [0, 1], as glTF requires of it, and store the
// unclamped radiance in the application attribute _RADIANCE (three.js names
// it "_radiance"); where it exists it is what is shown.
function useRadianceAttribute(root) {
	let n = 0;
	root.traverse((obj) => {
		if (!obj.isMesh || !obj.geometry.attributes._radiance) return;
		const rad = obj.geometry.attributes._radiance;
		if (rad.itemSize !== 3 && rad.itemSize !== 4) return;
		obj.geometry.setAttribute('color', rad);
		const mats = Array.isArray(obj.material) ? obj.material : [obj.material];
		const fixed = mats.map((m) => {
			if (m.vertexColors) return m;
			const c = m.clone();
			c.vertexColors = true;
			return c;
		});
		obj.material = Array.isArray(obj.material) ? fixed : fixed[0];
		n++;
	});
	return n;
}

async function openBuffer(buffer, name, basePath) {
	const seq = ++state.loadSeq;
	window.viewerReady = false;
	clearError();
	ui.info.textContent = `loading ${name} …`;
	let gltf;
	try {
		gltf = await loader.parseAsync(buffer, basePath);
	} catch (e) {
		if (seq === state.loadSeq) fail(`could not read ${name}: ${e && e.message ? e.message : e}`);
		return;
	}
	if (seq !== state.loadSeq) return;
	disposeModel();
	const hdrMeshes = useRadianceAttribute(gltf.scene);
	const glossyMeshes = useGlossyAttributes(gltf.scene, glossyUniform);
	ui.glossy.hidden = glossyMeshes === 0;
	state.model = gltf.scene;
	state.name = name;
	scene.add(gltf.scene);
	gltf.scene.updateMatrixWorld(true);

	const bbox = new THREE.Box3().setFromObject(gltf.scene, true);
	if (bbox.isEmpty()) bbox.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
	state.bbox.copy(bbox);
	bbox.getCenter(state.center);
	state.radius = Math.max(bbox.getSize(new THREE.Vector3()).length() / 2, 1e-6);

	// What the file holds, for the info line and for tests.
	let triangles = 0, vertices = 0, meshes = 0;
	const materials = new Map();
	gltf.scene.traverse((obj) => {
		if (!obj.isMesh) return;
		meshes++;
		const g = obj.geometry;
		const n = g.index ? g.index.count : g.attributes.position.count;
		triangles += Math.floor(n / 3);
		vertices += g.attributes.position.count;
		for (const m of Array.isArray(obj.material) ? obj.material : [obj.material]) {
			materials.set(m.uuid, {
				type: m.type, vertexColors: m.vertexColors, toneMapped: m.toneMapped,
				hasColor0: !!g.attributes.color, color0ItemSize: g.attributes.color ? g.attributes.color.itemSize : 0,
			});
		}
	});
	const mats = [...materials.values()];
	const glossy = new Set();
	gltf.scene.traverse((obj) => {
		if (!obj.isMesh) return;
		for (const m of Array.isArray(obj.material) ? obj.material : [obj.material]) if (glossyLeftOut(m)) glossy.add(m.name || obj.name);
	});
	state.glossy = [...glossy].sort();
	ui.glossyList.textContent = state.glossy.length
		? `glossy reflections not baked on: ${state.glossy.join(', ')}` : '';
	ui.glossyList.hidden = state.glossy.length === 0;
	const lit = mats.some((m) => m.type !== 'MeshBasicMaterial');
	lights.visible = lit;
	headlight.visible = lit;

	const extras = gltf.asset && gltf.asset.extras;
	const trilux = extras && typeof extras.trilux === 'object' && extras.trilux !== null ? extras.trilux : null;
	if (trilux && !state.exposureFromUrl && !state.exposureTouched && Number.isFinite(trilux.exposure)) {
		setExposure(trilux.exposure);
	}

	state.view = withLookat(findSceneCamera(gltf) ?? frameBox());
	if (params.get('mask') === 'glossy') maskGlossy(gltf.scene);
	state.inside = walker.encloses(state.view.position);
	goToSceneCamera();
	setMode(modeParam ?? (state.inside ? 'walk' : 'orbit'));

	window.viewerInfo = {
		name, meshes, triangles, vertices, materials: mats, lit, radianceAttributeMeshes: hdrMeshes,
		camera: state.view.from, trilux, inside: state.inside, mode: state.mode, glossyLeftOut: state.glossy,
		glossyMeshes, glossyShown: glossyUniform.value !== 0,
		bbox: { min: bbox.min.toArray(), max: bbox.max.toArray() },
	};
	window.viewerNotice = undefined; // drawn afresh for this file
	const unlitNote = lit ? 'lit materials (default headlight)' : 'unlit';
	ui.info.textContent = `${name}: ${triangles.toLocaleString('en')} triangles, ${unlitNote}, view from ${state.view.from}`;

	// Ready once this frame is drawn and the next one has begun (so the
	// drawn frame has been presented).
	afterFrame.push(() => requestAnimationFrame(() => {
		if (seq === state.loadSeq && !window.viewerError) window.viewerReady = true;
	}));
	requestRender();
}

async function openUrl(url) {
	const name = decodeURIComponent(url.split(/[?#]/)[0].split('/').pop() || url);
	let buffer;
	try {
		const res = await fetch(url);
		if (!res.ok) throw new Error(`HTTP ${res.status} ${res.statusText}`);
		buffer = await res.arrayBuffer();
	} catch (e) {
		fail(`could not fetch ${url}: ${e && e.message ? e.message : e}`);
		return;
	}
	const base = THREE.LoaderUtils.extractUrlBase(new URL(url, location.href).href);
	await openBuffer(buffer, name, base);
}

async function openFile(file) {
	let buffer;
	try {
		buffer = await file.arrayBuffer();
	} catch (e) {
		fail(`could not read ${file.name}: ${e && e.message ? e.message : e}`);
		return;
	}
	// A dropped .gltf can only use embedded (data:) resources.
	await openBuffer(buffer, file.name, '');
}

ui.file.addEventListener('change', () => {
	if (ui.file.files && ui.file.files[0]) openFile(ui.file.files[0]);
});
let dragDepth = 0;
window.addEventListener('dragenter', (e) => {
	e.preventDefault();
	dragDepth++;
	document.body.classList.add('dragging');
});
window.addEventListener('dragleave', () => {
	if (--dragDepth <= 0) {
		dragDepth = 0;
		document.body.classList.remove('dragging');
	}
});
window.addEventListener('dragover', (e) => e.preventDefault());
window.addEventListener('drop', (e) => {
	e.preventDefault();
	dragDepth = 0;
	document.body.classList.remove('dragging');
	const f = e.dataTransfer && e.dataTransfer.files && e.dataTransfer.files[0];
	if (f) openFile(f);
});

window.addEventListener('unhandledrejection', (e) => {
	if (!window.viewerError) fail(`unexpected error: ${e.reason && e.reason.message ? e.reason.message : e.reason}`);
});

// Hooks for scripted use (tests, the console).
window.viewer = { THREE, renderer, scene, camera, setExposure, goToSceneCamera, setMode, openUrl, state, walker, togglePanel, requestRender, setGlossy, frameTime };

const fileParam = params.get('file');
if (window.viewerError) {
	// a bad query parameter: already shown
} else if (fileParam) {
	openUrl(fileParam);
} else {
	requestRender();
}
