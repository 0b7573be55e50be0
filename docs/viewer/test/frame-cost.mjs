#!/usr/bin/env node
// What the glossy shader costs: the viewer opens FILE in headless Chromium
// (as screenshot.mjs does, W × H, the file's camera) and times N frames with
// the baked glossy light shown and N with it off (diffuse only), each frame
// drawn and waited for (window.viewer.frameTime), alternating the two
// three times so that a changing machine load falls on both.
//
//   node test/frame-cost.mjs --glb FILE [--frames N] [--width W] [--height H]
//
// Prints one JSON line: triangles, glossy meshes, ms per frame glossy and
// diffuse, and their ratio.

import { dirname, basename, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { CHROMIUM_ARGS, startServer } from './browser.mjs';

function usage(msg) {
	console.error(`frame-cost.mjs: ${msg}\nusage: node test/frame-cost.mjs --glb FILE [--frames N] [--width W] [--height H]`);
	process.exit(2);
}
const argv = process.argv.slice(2);
const o = { glb: null, frames: 10, width: 640, height: 480 };
for (let i = 0; i < argv.length; i++) {
	const k = argv[i].replace(/^--/, '');
	if (!(k in o) || i + 1 >= argv.length) usage(`unknown argument ${argv[i]}`);
	o[k] = k === 'glb' ? resolve(argv[++i]) : Number(argv[++i]);
}
if (!o.glb) usage('--glb is required');
for (const k of ['frames', 'width', 'height']) if (!Number.isInteger(o[k]) || o[k] < 1) usage(`--${k} takes a positive whole number`);

const viewerRoot = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const server = await startServer(viewerRoot, dirname(o.glb));
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', args: CHROMIUM_ARGS });
try {
	const page = await browser.newPage({ viewport: { width: o.width, height: o.height }, deviceScaleFactor: 1 });
	const q = new URLSearchParams({ file: `/model/${basename(o.glb)}`, ui: '0', mode: 'orbit', width: o.width, height: o.height });
	await page.goto(`http://127.0.0.1:${server.address().port}/index.html?${q}`);
	await page.waitForFunction(() => window.viewerReady === true || typeof window.viewerError === 'string', null, { timeout: 600_000 });
	const r = await page.evaluate((n) => {
		if (window.viewerError) return { error: window.viewerError };
		const v = window.viewer;
		const t = { glossy: 0, diffuse: 0 };
		for (let round = 0; round < 3; round++) {
			for (const on of [true, false]) {
				v.setGlossy(on);
				t[on ? 'glossy' : 'diffuse'] += v.frameTime(n) / 3;
			}
		}
		v.setGlossy(true);
		return { triangles: window.viewerInfo.triangles, glossyMeshes: window.viewerInfo.glossyMeshes, ...t };
	}, o.frames);
	if (r.error) throw new Error(r.error);
	console.log(JSON.stringify({
		file: basename(o.glb), width: o.width, height: o.height, triangles: r.triangles, glossy_meshes: r.glossyMeshes,
		glossy_ms: r.glossy, diffuse_ms: r.diffuse, ratio: r.glossy / r.diffuse,
	}));
} finally {
	await browser.close();
	server.close();
}
