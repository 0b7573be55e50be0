#!/usr/bin/env node
// Writes a small .glb that follows the bake contract: one unlit
// (KHR_materials_unlit, baseColorFactor 1) triangle mesh whose COLOR_0 is
// linear radiance, and a perspective camera on a translated and rotated
// node. The camera sees a 2 × 2 grid of constant colours filling exactly known
// pixel bounds, so a screenshot can be checked. One quadrant is a lamp whose
// radiance exceeds 1; --lamp says how that is stored:
//   radiance (default)  COLOR_0 clamped to [0, 1], the unclamped radiance in
//                       the application attribute _RADIANCE (valid glTF)
//   color0              COLOR_0 holds values above 1 (the Khronos validator
//                       reports ACCESSOR_NON_CLAMPED errors)
//   clamped             COLOR_0 clamped to [0, 1], no _RADIANCE
//
//   node test/make-fixture.mjs [--out FILE.glb] [--color vec3|vec4]
//                              [--lamp radiance|color0|clamped] [--no-camera] [--json]
//
// Without --out the file goes into a fresh temporary directory. It prints the
// file's path; with --json, a JSON description (path, view size, quadrant
// colours and pixel rectangles) instead.

import { mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';

// The view: W × H pixels, tan(yfov / 2) = 0.5, the quad at distance 2 spans
// half the view's height and width: columns [W/4, 3W/4), rows [H/4, 3H/4).
export const W = 320;
export const H = 240;
const ASPECT = W / H;
const YFOV = 2 * Math.atan(0.5);
const DIST = 2;
const CAM_POS = [1, 2, 3];
// +90° about +Y: the camera's −Z (view direction) becomes world −X, its +X
// (right) becomes world −Z, its +Y (up) stays +Y.
const CAM_ROT = [0, Math.SQRT1_2, 0, Math.SQRT1_2];

// Quadrant colours (linear radiance), left/right × top/bottom in the image.
export const QUADRANTS = [
	{ name: 'top-left', color: [0.2, 0.5, 0.8] },
	{ name: 'top-right', color: [0.05, 0.01, 0.002] },
	{ name: 'bottom-left', color: [1.0, 0.25, 0.0] },
	{ name: 'bottom-right', color: [4.0, 2.0, 1.0] },
];

/** The linear value the viewer should display for a quadrant's colour. */
export function shownColor(color, lamp = 'radiance') {
	return lamp === 'clamped' ? color.map((x) => Math.min(1, x)) : color.slice();
}

/** Pixel rectangles [x0, y0, x1, y1) of the quadrants, in the order above. */
export function quadrantRects(w = W, h = H) {
	const x = [w / 4, w / 2, (3 * w) / 4];
	const y = [h / 4, h / 2, (3 * h) / 4];
	return [
		[x[0], y[0], x[1], y[1]],
		[x[1], y[0], x[2], y[1]],
		[x[0], y[1], x[1], y[2]],
		[x[1], y[1], x[2], y[2]],
	];
}

// camera frame (u right, v up) -> world, at the quad's distance
function world(u, v) {
	return [CAM_POS[0] - DIST, CAM_POS[1] + v, CAM_POS[2] - u];
}

export function buildGlb({ colorType = 'vec3', lamp = 'radiance', camera = true } = {}) {
	const halfV = 0.5 * Math.tan(YFOV / 2) * DIST; // = 0.5: half the visible half-height
	const halfU = halfV * ASPECT;
	const us = [-halfU, 0, halfU];
	const vs = [halfV, 0, -halfV]; // top row first
	const positions = [];
	const colors = [];
	const radiance = [];
	const indices = [];
	const comps = colorType === 'vec4' ? 4 : 3;
	QUADRANTS.forEach((q, i) => {
		const c = i % 2, r = Math.floor(i / 2);
		const u0 = us[c], u1 = us[c + 1], vTop = vs[r], vBot = vs[r + 1];
		const base = positions.length / 3;
		// counter-clockwise as seen by the camera: bottom-left, bottom-right, top-right, top-left
		for (const [u, v] of [[u0, vBot], [u1, vBot], [u1, vTop], [u0, vTop]]) {
			positions.push(...world(u, v));
			colors.push(...q.color.map((x) => (lamp === 'color0' ? x : Math.min(1, x))));
			if (comps === 4) colors.push(1);
			radiance.push(...q.color);
		}
		indices.push(base, base + 1, base + 2, base, base + 2, base + 3);
	});
	const n = positions.length / 3;
	const normals = [];
	for (let i = 0; i < n; i++) normals.push(1, 0, 0); // facing the camera (+X)

	const pos = new Float32Array(positions);
	const nor = new Float32Array(normals);
	const col = new Float32Array(colors);
	const idx = new Uint16Array(indices);
	const rad = new Float32Array(radiance);
	const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
	for (let i = 0; i < n; i++) for (let k = 0; k < 3; k++) {
		min[k] = Math.min(min[k], pos[3 * i + k]);
		max[k] = Math.max(max[k], pos[3 * i + k]);
	}

	const parts = [pos, nor, col, idx];
	if (lamp === 'radiance') parts.push(rad);
	const views = [];
	let offset = 0;
	for (const p of parts) {
		views.push({ buffer: 0, byteOffset: offset, byteLength: p.byteLength });
		offset += Math.ceil(p.byteLength / 4) * 4;
	}
	views[0].target = views[1].target = views[2].target = 34962; // ARRAY_BUFFER
	views[3].target = 34963; // ELEMENT_ARRAY_BUFFER
	if (lamp === 'radiance') views[4].target = 34962;
	const bin = Buffer.alloc(offset);
	offset = 0;
	for (const p of parts) {
		Buffer.from(p.buffer, p.byteOffset, p.byteLength).copy(bin, offset);
		offset += Math.ceil(p.byteLength / 4) * 4;
	}

	const attributes = { POSITION: 0, NORMAL: 1, COLOR_0: 2 };
	if (lamp === 'radiance') attributes._RADIANCE = 4;
	const gltf = {
		asset: { version: '2.0', generator: 'trilux viewer test fixture', extras: { trilux: { exposure: 0 } } },
		extensionsUsed: ['KHR_materials_unlit'],
		scene: 0,
		scenes: [{ nodes: [0, 1] }],
		nodes: [
			{ name: 'quad', mesh: 0 },
			{ name: 'view', camera: 0, translation: CAM_POS, rotation: CAM_ROT },
		],
		cameras: [{ name: 'view', type: 'perspective', perspective: { yfov: YFOV, aspectRatio: ASPECT, znear: 0.1 } }],
		meshes: [{ name: 'quad', primitives: [{ attributes, indices: 3, material: 0, mode: 4 }] }],
		materials: [{
			name: 'baked',
			pbrMetallicRoughness: { baseColorFactor: [1, 1, 1, 1], metallicFactor: 0, roughnessFactor: 1 },
			extensions: { KHR_materials_unlit: {} },
		}],
		accessors: [
			{ bufferView: 0, componentType: 5126, count: n, type: 'VEC3', min, max },
			{ bufferView: 1, componentType: 5126, count: n, type: 'VEC3' },
			{ bufferView: 2, componentType: 5126, count: n, type: comps === 4 ? 'VEC4' : 'VEC3' },
			{ bufferView: 3, componentType: 5123, count: idx.length, type: 'SCALAR' },
			...(lamp === 'radiance' ? [{ bufferView: 4, componentType: 5126, count: n, type: 'VEC3' }] : []),
		],
		bufferViews: views,
		buffers: [{ byteLength: bin.length }],
	};
	if (!camera) {
		delete gltf.cameras;
		gltf.nodes.pop();
		gltf.scenes[0].nodes = [0];
	}
	return encodeGlb(gltf, bin);
}

export function encodeGlb(json, bin) {
	let jsonBuf = Buffer.from(JSON.stringify(json), 'utf8');
	const jsonPad = (4 - (jsonBuf.length % 4)) % 4;
	jsonBuf = Buffer.concat([jsonBuf, Buffer.alloc(jsonPad, 0x20)]);
	const binPad = (4 - (bin.length % 4)) % 4;
	const binBuf = Buffer.concat([bin, Buffer.alloc(binPad, 0)]);
	const total = 12 + 8 + jsonBuf.length + 8 + binBuf.length;
	const header = Buffer.alloc(12);
	header.writeUInt32LE(0x46546c67, 0); // 'glTF'
	header.writeUInt32LE(2, 4);
	header.writeUInt32LE(total, 8);
	const jh = Buffer.alloc(8);
	jh.writeUInt32LE(jsonBuf.length, 0);
	jh.writeUInt32LE(0x4e4f534a, 4); // 'JSON'
	const bh = Buffer.alloc(8);
	bh.writeUInt32LE(binBuf.length, 0);
	bh.writeUInt32LE(0x004e4942, 4); // 'BIN\0'
	return Buffer.concat([header, jh, jsonBuf, bh, binBuf]);
}

function main() {
	const args = process.argv.slice(2);
	let out = null, colorType = 'vec3', lamp = 'radiance', camera = true, json = false;
	for (let i = 0; i < args.length; i++) {
		const a = args[i];
		if (a === '--out') out = args[++i];
		else if (a === '--color') colorType = args[++i];
		else if (a === '--lamp') lamp = args[++i];
		else if (a === '--no-camera') camera = false;
		else if (a === '--json') json = true;
		else {
			console.error(`make-fixture.mjs: unknown argument ${a}\nusage: node test/make-fixture.mjs [--out FILE.glb] [--color vec3|vec4] [--lamp radiance|color0|clamped] [--no-camera] [--json]`);
			process.exit(2);
		}
	}
	if (colorType !== 'vec3' && colorType !== 'vec4') {
		console.error(`make-fixture.mjs: --color takes vec3 or vec4, not ${colorType}`);
		process.exit(2);
	}
	if (!['radiance', 'color0', 'clamped'].includes(lamp)) {
		console.error(`make-fixture.mjs: --lamp takes radiance, color0 or clamped, not ${lamp}`);
		process.exit(2);
	}
	if (!out) out = join(mkdtempSync(join(tmpdir(), 'trilux-fixture-')), 'fixture.glb');
	writeFileSync(out, buildGlb({ colorType, lamp, camera }));
	if (json) {
		const rects = quadrantRects();
		console.log(JSON.stringify({
			path: out, width: W, height: H, lamp,
			quadrants: QUADRANTS.map((q, i) => ({ ...q, shown: shownColor(q.color, lamp), rect: rects[i] })),
			quad: [W / 4, H / 4, (3 * W) / 4, (3 * H) / 4],
		}));
	} else console.log(out);
}

if (process.argv[1] && import.meta.url === pathToFileURL(process.argv[1]).href) main();
