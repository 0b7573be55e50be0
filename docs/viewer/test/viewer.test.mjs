// Tests of the viewer and its scripts (node's test runner):
//   node --test test/            (in docs/viewer, after npm ci)
// The screenshot tests need Chromium (/usr/bin/chromium or $CHROMIUM).

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { PNG } from 'pngjs';
import { buildGlb, encodeGlb, quadrantRects, shownColor, QUADRANTS, W, H } from './make-fixture.mjs';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const repo = resolve(root, '..', '..');
const tmp = mkdtempSync(join(tmpdir(), 'trilux-viewer-test-'));
process.on('exit', () => rmSync(tmp, { recursive: true, force: true }));

function run(script, args) {
	const r = spawnSync(process.execPath, [join(root, script), ...args], { encoding: 'utf8', timeout: 180_000 });
	return { code: r.status, out: r.stdout, err: r.stderr };
}

function fixture(name, opts) {
	const p = join(tmp, name);
	writeFileSync(p, buildGlb(opts));
	return p;
}

// trilux's PNG encoding of a linear value (trilux_render::image::to_srgb8).
function encode8(linear, stops) {
	const v = Math.min(1, Math.max(0, linear * Math.pow(2, stops)));
	const e = v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
	return Math.round(e * 255);
}

function screenshot(glb, w, h, stops, extra = []) {
	const out = join(tmp, `shot-${Math.random().toString(36).slice(2)}.png`);
	const info = out.replace(/\.png$/, '.json');
	const args = ['--glb', glb, '--width', String(w), '--height', String(h), '--out', out, '--info', info, ...extra];
	if (stops !== null) args.push('--exposure', String(stops));
	const r = run('test/screenshot.mjs', args);
	assert.equal(r.code, 0, `screenshot.mjs failed:\n${r.err}${r.out}`);
	return { png: PNG.sync.read(readFileSync(out)), info: JSON.parse(readFileSync(info, 'utf8')), stderr: r.err };
}

const px = (png, x, y) => {
	const i = 4 * (y * png.width + x);
	return [png.data[i], png.data[i + 1], png.data[i + 2]];
};

let worst = 0; // the largest difference seen inside the quadrants, in 8-bit steps

// Every pixel of each quadrant within ±tol of the encoded colour; every pixel
// outside the quad black: the view is the file's camera.
function checkFixture(png, stops, lamp, tol = 2) {
	assert.equal(png.width, W);
	assert.equal(png.height, H);
	const rects = quadrantRects();
	const inQuad = (x, y) => x >= W / 4 && x < (3 * W) / 4 && y >= H / 4 && y < (3 * H) / 4;
	QUADRANTS.forEach((q, i) => {
		const want = shownColor(q.color, lamp).map((c) => encode8(c, stops));
		const [x0, y0, x1, y1] = rects[i];
		for (let y = y0; y < y1; y++) for (let x = x0; x < x1; x++) {
			const got = px(png, x, y);
			const d = Math.max(...got.map((g, k) => Math.abs(g - want[k])));
			worst = Math.max(worst, d);
			if (d > tol) assert.fail(`${q.name} at (${x}, ${y}), exposure ${stops}: got ${got}, want ${want} ±${tol}`);
		}
	});
	for (let y = 0; y < H; y++) for (let x = 0; x < W; x++) {
		if (inQuad(x, y)) continue;
		const got = px(png, x, y);
		if (Math.max(...got) > 0) assert.fail(`outside the quad at (${x}, ${y}): got ${got}, want black`);
	}
}

test('vendor/ matches node_modules/three (vendor.mjs --check)', () => {
	const r = run('scripts/vendor.mjs', ['--check']);
	assert.equal(r.code, 0, r.err + r.out);
});

test('vendor.mjs --check fails on a changed vendored file', () => {
	const f = join(root, 'vendor', 'three', 'examples', 'jsm', 'controls', 'PointerLockControls.js');
	const orig = readFileSync(f);
	try {
		writeFileSync(f, Buffer.concat([orig, Buffer.from('\n')]));
		const r = run('scripts/vendor.mjs', ['--check']);
		assert.equal(r.code, 1);
		assert.match(r.err, /differs +vendor\/three\/examples\/jsm\/controls\/PointerLockControls\.js/);
	} finally {
		writeFileSync(f, orig);
	}
});

test('validate.mjs: the fixture is valid glTF in each valid form', () => {
	const files = [
		fixture('v-radiance.glb', { lamp: 'radiance' }),
		fixture('v-radiance4.glb', { lamp: 'radiance', colorType: 'vec4' }),
		fixture('v-clamped.glb', { lamp: 'clamped' }),
		fixture('v-nocam.glb', { camera: false }),
	];
	const r = run('test/validate.mjs', files);
	assert.equal(r.code, 0, r.out + r.err);
	for (const f of files) assert.match(r.out, new RegExp(`${f.replace(/[.*+?^${}()|[\]\\]/g, '\\$&')}: ok: 0 errors, 0 warnings, 0 infos, 0 hints`));
});

test('validate.mjs: COLOR_0 above 1 is an error (ACCESSOR_NON_CLAMPED)', () => {
	const f = fixture('v-color0.glb', { lamp: 'color0' });
	const r = run('test/validate.mjs', [f]);
	assert.equal(r.code, 1);
	// the lamp quadrant: 4 vertices × 2 components (4 and 2) above 1
	assert.match(r.out, /: FAIL: 8 errors, 0 warnings/);
	assert.match(r.out, /error ACCESSOR_NON_CLAMPED: Accessor element at index \d+ is not clamped to 0\.\.1 range: 4\. \(\/meshes\/0\/primitives\/0\/attributes\/COLOR_0\)/);
});

test('validate.mjs: the repository scenes are valid', () => {
	const r = run('test/validate.mjs', [join(repo, 'scenes', 'product-shot.glb'), join(repo, 'scenes', 'cornell-box-gltf.gltf'), join(repo, 'scenes', 'textured-room.gltf')]);
	assert.equal(r.code, 0, r.out + r.err);
});

test('validate.mjs: usage and unreadable files', () => {
	assert.equal(run('test/validate.mjs', []).code, 2);
	assert.equal(run('test/validate.mjs', ['--bogus', 'x.glb']).code, 2);
	const missing = run('test/validate.mjs', [join(tmp, 'missing.glb')]);
	assert.equal(missing.code, 1);
	assert.match(missing.out, /cannot read/);
	const junk = join(tmp, 'junk.glb');
	writeFileSync(junk, 'not a gltf');
	assert.equal(run('test/validate.mjs', [junk]).code, 1);
});

for (const [lamp, colorType, stops] of [
	['radiance', 'vec3', 0], ['radiance', 'vec3', -2], ['radiance', 'vec3', 1.5], ['radiance', 'vec3', -6.5],
	['radiance', 'vec4', -2], ['color0', 'vec3', -2], ['color0', 'vec4', 0.5], ['clamped', 'vec3', -1],
]) {
	test(`screenshot: fixture (lamp in ${lamp}, COLOR_0 ${colorType}) at ${stops} stops = sRGB(clamp(c × 2^stops)) ±2, quad at its pixel bounds`, () => {
		const f = fixture(`s-${lamp}-${colorType}.glb`, { lamp, colorType });
		const { png, info } = screenshot(f, W, H, stops);
		checkFixture(png, stops, lamp);
		assert.equal(info.camera, 'camera 0 "view"');
		assert.equal(info.lit, false);
		for (const m of info.materials) {
			assert.equal(m.type, 'MeshBasicMaterial');
			assert.equal(m.vertexColors, true);
			assert.equal(m.toneMapped, true);
		}
		assert.equal(info.radianceAttributeMeshes, lamp === 'radiance' ? 1 : 0);
	});
}

test('screenshot: without --exposure the file\'s asset.extras.trilux.exposure applies', () => {
	const f = join(tmp, 'extras.glb');
	// the fixture with extras.trilux.exposure = -2 and an unknown key
	const glb = buildGlb({});
	const jsonLen = glb.readUInt32LE(12);
	const json = JSON.parse(glb.subarray(20, 20 + jsonLen).toString('utf8'));
	const bin = glb.subarray(20 + jsonLen + 8);
	json.asset.extras.trilux = { exposure: -2, somethingNew: [1, 2] };
	writeFileSync(f, encodeGlb(json, bin));
	const { png, info } = screenshot(f, W, H, null);
	checkFixture(png, -2, 'radiance');
	assert.deepEqual(info.trilux, { exposure: -2, somethingNew: [1, 2] });
});

test('screenshot: a canvas narrower than the camera keeps the camera\'s full width', () => {
	// 240 × 240 for a 4:3 camera: the quad spans half the width, centred.
	const f = fixture('narrow.glb', {});
	const { png } = screenshot(f, 240, 240, -2);
	const row = 120;
	assert.equal(Math.max(...px(png, 59, row)), 0);
	assert.ok(Math.max(...px(png, 61, row)) > 0);
	assert.ok(Math.max(...px(png, 178, row)) > 0);
	assert.equal(Math.max(...px(png, 181, row)), 0);
});

test('screenshot: a file without a camera is framed (its bounding box in view)', () => {
	const f = fixture('nocam.glb', { camera: false });
	const { png, info } = screenshot(f, 200, 150, -2);
	assert.equal(info.camera, 'bounding box');
	assert.ok(Math.max(...px(png, 100, 75)) > 0, 'the centre shows the quad');
	for (const [x, y] of [[0, 0], [199, 0], [0, 149], [199, 149]]) assert.equal(Math.max(...px(png, x, y)), 0, `corner ${x},${y} is background`);
});

test('screenshot: a lit glTF (scenes/product-shot.glb) opens from its camera', () => {
	const { png, info } = screenshot(join(repo, 'scenes', 'product-shot.glb'), 256, 256, null);
	assert.equal(info.lit, true);
	assert.equal(info.camera, 'camera 0 "front"');
	let lit = 0;
	for (let i = 0; i < png.data.length; i += 4) if (png.data[i] + png.data[i + 1] + png.data[i + 2] > 30) lit++;
	assert.ok(lit > 256 * 256 * 0.5, `only ${lit} pixels are not dark`);
});

test('screenshot: a bad file fails with one clear line and exit 1', () => {
	const f = join(tmp, 'bad.glb');
	writeFileSync(f, 'glTF this is not');
	const out = join(tmp, 'bad.png');
	const r = run('test/screenshot.mjs', ['--glb', f, '--width', '64', '--height', '64', '--out', out]);
	assert.equal(r.code, 1);
	assert.match(r.err.trim().split('\n').pop(), /^screenshot\.mjs: viewer error: could not read bad\.glb: /);
});

test('screenshot: usage errors exit 2', () => {
	assert.equal(run('test/screenshot.mjs', ['--glb', 'x.glb']).code, 2);
	assert.equal(run('test/screenshot.mjs', ['--glb', 'x.glb', '--width', '0', '--height', '5', '--out', 'o.png']).code, 2);
});

test('fixture accuracy (report)', () => {
	console.log(`largest 8-bit difference inside the fixture's quadrants: ${worst}`);
	assert.ok(worst <= 2);
});
