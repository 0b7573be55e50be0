// The viewer on real bakes, in headless Chromium (node's test runner):
// walk mode in an interior, touch, the glossy notice (never on a diffuse
// bake), the baked glossy light of a --glossy bake and its toggle, the
// compact overlay,
// and `trilux view` serving a bake that the page loads.
//
//   TRILUX=target/release/trilux TRILUX_BAKES=target/viewer \
//     node --test docs/viewer/test/interior.test.mjs
//
// `cargo xtask viewer` runs it after baking every bundled scene into
// target/viewer (the defaults of both variables, from the repository root).
// The bakes used and what is known of them from their scene files:
// - crossing-room.glb (scenes/crossing-room.xml): a room x, z in [0, 4],
//   floor y = 0, ceiling y = 3, the camera at (3.6, 1.9, 3.7) inside it; a
//   glossy (roughconductor) box centred at (2.7, 0.45, 1.5), 0.6 × 0.9 ×
//   0.6, rotated 25° about y; the red wall at x = 0. Its glossy light is
//   left out (the notice).
// - crossing-room-glossy.glb: the same baked with `--glossy` (the glossy
//   light as spherical harmonics, glossy.js).
// - diffuse-textured.glb (tests/bake/diffuse-textured.xml): diffuse only, a
//   box open towards its camera at (0, 1, 3.6), outside it.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { existsSync, readFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { createInterface } from 'node:readline';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { CHROMIUM_ARGS, startServer } from './browser.mjs';

const viewerRoot = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const repo = resolve(viewerRoot, '..', '..');
const bakes = resolve(repo, process.env.TRILUX_BAKES || 'target/viewer');
const triluxBin = resolve(repo, process.env.TRILUX || 'target/release/trilux');
const ROOM = join(bakes, 'crossing-room.glb');
const DIFFUSE = join(bakes, 'diffuse-textured.glb');
const GLOSSY_NOTICE = 'glossy reflections not baked here (trilux render shows them)';
const EYE = 1.6; // walk.js's eye height, metres
const CLEARANCE = 0.25; // walk.js's closest approach to a wall, metres

let browser;
let server;
before(async () => {
	for (const f of [ROOM, DIFFUSE]) assert.ok(existsSync(f), `${f} is missing: run cargo xtask viewer (or set TRILUX_BAKES)`);
	browser = await chromium.launch({
		executablePath: process.env.CHROMIUM || '/usr/bin/chromium', headless: true, args: CHROMIUM_ARGS, timeout: 60_000,
	});
	server = await startServer(viewerRoot, bakes);
});
after(async () => {
	await browser?.close();
	server?.close();
});

/** A page of the viewer on `glb` (a file name in the bakes folder); `query` adds parameters. */
async function open(glb, { width = 640, height = 480, query = {} } = {}) {
	const context = await browser.newContext({ viewport: { width, height }, deviceScaleFactor: 1, hasTouch: true });
	const page = await context.newPage();
	const errors = [];
	page.on('pageerror', (e) => errors.push(e.message));
	const q = new URLSearchParams({ file: `/model/${glb}`, ...query });
	await page.goto(`http://127.0.0.1:${server.address().port}/index.html?${q}`);
	await page.waitForFunction(() => window.viewerReady === true || typeof window.viewerError === 'string', null, { timeout: 120_000 });
	const error = await page.evaluate(() => window.viewerError);
	assert.equal(error, undefined, `viewer error: ${error}`);
	assert.deepEqual(errors, []);
	return { page, context };
}

/** Waits for `n` animation frames of the page. */
const frames = (page, n) => page.evaluate((n) => new Promise((ok) => {
	const tick = () => (--n <= 0 ? ok() : requestAnimationFrame(tick));
	requestAnimationFrame(tick);
}), n);

const pose = (page) => page.evaluate(() => {
	const c = window.viewer.camera;
	const f = new window.viewer.THREE.Vector3(0, 0, -1).applyQuaternion(c.quaternion);
	return { p: c.position.toArray(), f: f.toArray(), mode: window.viewer.state.mode };
});

/** Turns the walker to look horizontally along (x, 0, z) (test set-up, not under test). */
const face = (page, x, z) => page.evaluate(([x, z]) => {
	const w = window.viewer.walker;
	w.yaw = Math.atan2(-x, -z);
	w.pitch = 0;
	w.turn(0, 0);
}, [x, z]);

/** Holds `key` until the camera has not moved for 10 frames (at most 5000 frames), then releases it. */
async function walkUntilStopped(page, key) {
	await page.keyboard.down(key);
	const stopped = await page.evaluate(() => new Promise((ok) => {
		let last = null, same = 0, n = 0;
		const tick = () => {
			const p = window.viewer.camera.position.clone();
			same = last && p.distanceTo(last) < 1e-7 ? same + 1 : 0;
			last = p;
			if (same >= 10) ok(true);
			else if (++n > 5000) ok(false);
			else requestAnimationFrame(tick);
		};
		requestAnimationFrame(tick);
	}));
	await page.keyboard.up(key);
	assert.ok(stopped, `holding ${key}, the camera never stopped`);
}

test('an interior opens in walk mode, a scene seen from outside in orbit mode', async () => {
	const room = await open('crossing-room.glb');
	const info = await room.page.evaluate(() => window.viewerInfo);
	assert.equal(info.inside, true);
	assert.equal(info.mode, 'walk');
	await room.context.close();
	const box = await open('diffuse-textured.glb');
	const boxInfo = await box.page.evaluate(() => window.viewerInfo);
	assert.equal(boxInfo.inside, false);
	assert.equal(boxInfo.mode, 'orbit');
	await box.context.close();
});

test('?mode= overrides the default; an unknown mode is an error on the page', async () => {
	const { page, context } = await open('crossing-room.glb', { query: { mode: 'orbit' } });
	assert.equal(await page.evaluate(() => window.viewerInfo.mode), 'orbit');
	await page.goto(page.url().replace('mode=orbit', 'mode=run'));
	await page.waitForFunction(() => typeof window.viewerError === 'string', null, { timeout: 60_000 });
	assert.equal(await page.evaluate(() => window.viewerError), 'mode=run is not walk, orbit or fly');
	await context.close();
});

test('walk: W towards a wall stops the eye 0.25 m short of it, 1.6 m above the floor', async () => {
	const { page, context } = await open('crossing-room.glb');
	// From (3.6, ·, 3.7) towards the red wall at x = 0: nothing in between.
	await face(page, -1, 0);
	await walkUntilStopped(page, 'KeyW');
	const { p } = await pose(page);
	assert.ok(Math.abs(p[0] - CLEARANCE) < 1e-3, `x = ${p[0]}, want ${CLEARANCE}`);
	assert.ok(Math.abs(p[1] - EYE) < 1e-3, `y = ${p[1]}, want ${EYE}`);
	assert.ok(Math.abs(p[2] - 3.7) < 1e-6, `z = ${p[2]}, want 3.7`);
	// Into the corner (x = 0, z = 4) at Shift speed: it slides along the wall and stays in.
	await face(page, -1, 1);
	await page.keyboard.down('ShiftLeft');
	await walkUntilStopped(page, 'KeyW');
	await page.keyboard.up('ShiftLeft');
	const q = (await pose(page)).p;
	assert.ok(Math.abs(q[0] - CLEARANCE) < 1e-3 && Math.abs(q[2] - (4 - CLEARANCE)) < 1e-3, `corner at ${q}`);
	// Across the room into the glossy box (↑ walks too): around it or stopped, never out.
	await face(page, 1, -1);
	await walkUntilStopped(page, 'ArrowUp');
	const r = (await pose(page)).p;
	for (const v of [r[0], r[2]]) assert.ok(v > CLEARANCE - 1e-3 && v < 4 - CLEARANCE + 1e-3, `left the room: ${r}`);
	assert.ok(Math.abs(r[1] - EYE) < 1e-3);
	await context.close();
});

/** Touches through Chromium's input domain (real touch, so pointer events of type touch). */
async function touch(context, page, strokes) {
	const cdp = await context.newCDPSession(page);
	const pts = (i) => strokes.map((s, id) => ({ x: s[i][0], y: s[i][1], id }));
	await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: pts(0) });
	for (let i = 1; i < strokes[0].length; i++) {
		await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: pts(i) });
	}
	await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
	await frames(page, 2);
}

/** A stroke from (x0, y0) by (dx, dy) in `n` moves. */
const stroke = (x0, y0, dx, dy, n = 10) => Array.from({ length: n + 1 }, (_, i) => [x0 + (dx * i) / n, y0 + (dy * i) / n]);

// The heading's angle about +y: it grows as the view turns left.
const heading = (f) => Math.atan2(f[0], f[2]);

test('touch: one finger turns, two fingers walk and pinch walks', async () => {
	const { page, context } = await open('crossing-room.glb');
	await face(page, -1, 0);
	const a = await pose(page);
	// One finger 100 px to the right: the view turns left (the scene follows the finger), 0.4 rad, in place.
	await touch(context, page, [stroke(300, 240, 100, 0)]);
	const b = await pose(page);
	assert.deepEqual(b.p, a.p);
	let turned = heading(b.f) - heading(a.f);
	turned = Math.atan2(Math.sin(turned), Math.cos(turned));
	assert.ok(Math.abs(turned - 0.4) < 0.02, `turned ${turned} rad to the left, want 0.4`);
	// Two fingers dragged 100 px down: 1 m forward along the view.
	await face(page, -1, 0);
	const c = await pose(page);
	await touch(context, page, [stroke(280, 200, 0, 100), stroke(360, 200, 0, 100)]);
	const d = await pose(page);
	assert.ok(Math.abs(c.p[0] - d.p[0] - 1) < 0.02 && Math.abs(d.p[2] - c.p[2]) < 1e-6, `moved from ${c.p} to ${d.p}`);
	assert.ok(Math.abs(d.p[1] - EYE) < 1e-3);
	// Fingers spreading 100 px apart (50 each way): 1 m forward too.
	await touch(context, page, [stroke(300, 240, -50, 0), stroke(340, 240, 50, 0)]);
	const e = await pose(page);
	assert.ok(Math.abs(d.p[0] - e.p[0] - 1) < 0.02, `pinch moved from ${d.p} to ${e.p}`);
	await context.close();
});

/** Points the camera at `target` from where it is, draws, and returns the notice. */
const noticeLookingAt = (page, target) => page.evaluate((t) => new Promise((ok) => {
	window.viewer.camera.lookAt(...t);
	if (window.viewer.state.mode === 'walk') window.viewer.walker.enable();
	window.viewer.camera.updateMatrixWorld();
	window.viewer.requestRender();
	requestAnimationFrame(() => requestAnimationFrame(() => {
		const el = document.getElementById('notice');
		ok({ text: window.viewerNotice, shown: !el.hidden && el.getBoundingClientRect().width > 0 });
	}));
}), target);

/** The RGB bytes at the centre of the view looking at `target`, the baked glossy light on or off. */
const centreLookingAt = (page, target, glossy) => page.evaluate(([t, g]) => {
	const v = window.viewer;
	v.camera.lookAt(...t);
	v.camera.updateMatrixWorld();
	v.setGlossy(g);
	v.frameTime(1);
	const gl = v.renderer.getContext();
	const px = new Uint8Array(4);
	gl.readPixels(gl.drawingBufferWidth >> 1, gl.drawingBufferHeight >> 1, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
	return [px[0], px[1], px[2]];
}, [target, glossy]);

test('glossy notice: on the glossy box of a bake, not on its diffuse walls', async () => {
	const { page, context } = await open('crossing-room.glb');
	const info = await page.evaluate(() => window.viewerInfo);
	assert.ok(info.glossyLeftOut.length > 0, 'the bake marks glossy materials');
	// Every marked material is on the glossy box: its meshes lie within the box's bounds,
	// x, z within 0.3 (cos 25° + sin 25°) = 0.399 of (2.7, 1.5), y in [0, 0.9].
	const boxes = await page.evaluate(() => {
		const out = [];
		window.viewer.state.model.traverse((o) => {
			if (!o.isMesh) return;
			const ms = Array.isArray(o.material) ? o.material : [o.material];
			if (!ms.some((m) => m.userData?.trilux?.glossy_left_out === true)) return;
			const b = new window.viewer.THREE.Box3().setFromObject(o);
			out.push([b.min.toArray(), b.max.toArray()]);
		});
		return out;
	});
	assert.ok(boxes.length > 0);
	const half = 0.3 * (Math.cos(Math.PI * 25 / 180) + Math.sin(Math.PI * 25 / 180)) + 1e-3;
	for (const [lo, hi] of boxes) {
		assert.ok(lo[0] > 2.7 - half && hi[0] < 2.7 + half && lo[2] > 1.5 - half && hi[2] < 1.5 + half, `a glossy mesh in ${lo}..${hi}`);
		assert.ok(lo[1] > -1e-3 && hi[1] < 0.9 + 1e-3, `a glossy mesh in ${lo}..${hi}`);
	}
	const list = await page.evaluate(() => document.getElementById('glossy-list').textContent);
	assert.match(list, /^glossy reflections not baked on: /);
	assert.deepEqual(await noticeLookingAt(page, [2.7, 0.45, 1.5]), { text: GLOSSY_NOTICE, shown: true });
	assert.deepEqual(await noticeLookingAt(page, [0, 1.5, 2]), { text: null, shown: false });
	assert.deepEqual(await noticeLookingAt(page, [2, 0, 3]), { text: null, shown: false });
	await context.close();
});

test('glossy light: the glossy box of a --glossy bake carries it, G turns it off, no notice', async () => {
	const { page, context } = await open('crossing-room-glossy.glb');
	const info = await page.evaluate(() => window.viewerInfo);
	assert.ok(info.glossyMeshes > 0, 'the bake has directional glossy light');
	assert.deepEqual(info.glossyLeftOut, [], 'nothing is left out');
	// Every mesh with glossy light is on the glossy box: within its bounds,
	// x, z within 0.3 (cos 25° + sin 25°) = 0.399 of (2.7, 1.5), y in [0, 0.9].
	const boxes = await page.evaluate(() => {
		const out = [];
		window.viewer.state.model.traverse((o) => {
			if (!o.isMesh) return;
			const ms = Array.isArray(o.material) ? o.material : [o.material];
			if (!ms.some((m) => m.userData?.triluxGlossy === true)) return;
			const b = new window.viewer.THREE.Box3().setFromObject(o);
			out.push([b.min.toArray(), b.max.toArray()]);
		});
		return out;
	});
	assert.equal(boxes.length, info.glossyMeshes);
	const half = 0.3 * (Math.cos(Math.PI * 25 / 180) + Math.sin(Math.PI * 25 / 180)) + 1e-3;
	for (const [lo, hi] of boxes) {
		assert.ok(lo[0] > 2.7 - half && hi[0] < 2.7 + half && lo[2] > 1.5 - half && hi[2] < 1.5 + half, `a glossy mesh in ${lo}..${hi}`);
		assert.ok(lo[1] > -1e-3 && hi[1] < 0.9 + 1e-3, `a glossy mesh in ${lo}..${hi}`);
	}
	assert.equal(await page.evaluate(() => document.getElementById('glossy').hidden), false, 'the toggle shows');
	// The box is a rough conductor: no diffuse light, all it shows is glossy.
	const on = await centreLookingAt(page, [2.7, 0.45, 1.5], true);
	const off = await centreLookingAt(page, [2.7, 0.45, 1.5], false);
	assert.ok(on.some((c) => c > 10), `the box shows its glossy light: ${on}`);
	assert.ok(off.every((c) => c <= 1), `diffuse only, the box is black: ${off}`);
	// The walls have no glossy light: the toggle leaves them as they are.
	const wallOn = await centreLookingAt(page, [0, 1.5, 2], true);
	assert.deepEqual(await centreLookingAt(page, [0, 1.5, 2], false), wallOn);
	assert.deepEqual(await noticeLookingAt(page, [2.7, 0.45, 1.5]), { text: null, shown: false });
	await context.close();
});

test('glossy notice: never on a diffuse bake', async () => {
	const { page, context } = await open('diffuse-textured.glb');
	const info = await page.evaluate(() => window.viewerInfo);
	assert.deepEqual(info.glossyLeftOut, []);
	const targets = await page.evaluate(() => {
		const out = [];
		window.viewer.state.model.traverse((o) => {
			if (o.isMesh) out.push(new window.viewer.THREE.Box3().setFromObject(o).getCenter(new window.viewer.THREE.Vector3()).toArray());
		});
		return out;
	});
	assert.ok(targets.length >= 5);
	for (const t of targets) assert.deepEqual(await noticeLookingAt(page, t), { text: null, shown: false }, `looking at ${t}`);
	await context.close();
});

test('compact overlay: on a 360 × 640 screen the overlays cover under 5 %, the panel opens on ☰', async () => {
	const { page, context } = await open('crossing-room.glb', { width: 360, height: 640 });
	const covered = () => page.evaluate(() => [...document.querySelectorAll('.overlay')]
		.map((e) => e.getBoundingClientRect())
		.reduce((sum, r) => sum + Math.max(0, Math.min(r.right, innerWidth) - Math.max(r.left, 0)) * Math.max(0, Math.min(r.bottom, innerHeight) - Math.max(r.top, 0)), 0)
		/ (innerWidth * innerHeight));
	const folded = await covered();
	console.log(`the folded overlays cover ${(100 * folded).toFixed(2)} % of a 360 × 640 screen`);
	assert.ok(folded < 0.05, `the folded overlays cover ${(100 * folded).toFixed(1)} % of the screen`);
	await page.tap('#menu');
	assert.equal(await page.isVisible('#exposure'), true);
	const box = await page.locator('#panel').boundingBox();
	assert.ok(box.x >= 0 && box.x + box.width <= 360, `the panel spans ${box.x}..${box.x + box.width}`);
	await page.tap('#menu');
	assert.equal(await page.isVisible('#panel'), false);
	await page.tap('#nav-mode');
	assert.equal((await pose(page)).mode, 'fly');
	await context.close();
});

test('trilux view serves a bake that the page loads', async () => {
	assert.ok(existsSync(triluxBin), `${triluxBin} is missing: cargo build --release (or set TRILUX)`);
	const child = spawn(triluxBin, ['view', ROOM], { stdio: ['ignore', 'pipe', 'inherit'], env: { ...process.env, BROWSER: '' } });
	try {
		const lines = createInterface({ input: child.stdout });
		const first = await new Promise((ok, fail) => {
			lines.once('line', ok);
			child.once('exit', (code) => fail(new Error(`trilux view exited with ${code}`)));
		});
		const url = first.match(/^viewer: (http:\/\/127\.0\.0\.1:\d+\/index\.html\?file=\/model\.glb) \(Ctrl-C stops it\)$/);
		assert.ok(url, first);
		const context = await browser.newContext({ viewport: { width: 320, height: 240 } });
		const page = await context.newPage();
		await page.goto(url[1]);
		await page.waitForFunction(() => window.viewerReady === true || typeof window.viewerError === 'string', null, { timeout: 120_000 });
		const info = await page.evaluate(() => ({ error: window.viewerError, info: window.viewerInfo }));
		assert.equal(info.error, undefined);
		assert.equal(info.info.name, 'model.glb');
		assert.equal(info.info.triangles, glbTriangles(readFileSync(ROOM)));
		assert.equal(info.info.mode, 'walk');
		await context.close();
	} finally {
		child.kill();
	}
});

/** Triangles of a glTF binary, counted from its JSON: each primitive's indices (or positions) / 3, for every node's mesh. */
function glbTriangles(buf) {
	const json = JSON.parse(buf.subarray(20, 20 + buf.readUInt32LE(12)).toString('utf8'));
	let n = 0;
	for (const node of json.nodes) {
		if (node.mesh === undefined) continue;
		for (const p of json.meshes[node.mesh].primitives) {
			const acc = json.accessors[p.indices ?? p.attributes.POSITION];
			n += acc.count / 3;
		}
	}
	return n;
}
