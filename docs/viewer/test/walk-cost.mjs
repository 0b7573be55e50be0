#!/usr/bin/env node
// What walk mode's rays cost on a bake: the viewer opens FILE in headless
// Chromium (as screenshot.mjs does) in walk mode, and times N steps of 5 cm
// (walk.js's step: the rays along the step, down to the floor, up to the
// ceiling) and N glossy-notice probes (one ray from the centre of the view).
//
//   node test/walk-cost.mjs --glb FILE [--steps N]
//
// Prints one line: triangles, milliseconds per step and per probe (means).
// A figure for docs/results.md, not a test.

import { dirname, basename, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { CHROMIUM_ARGS, startServer } from './browser.mjs';

function usage(msg) {
	console.error(`walk-cost.mjs: ${msg}\nusage: node test/walk-cost.mjs --glb FILE [--steps N]`);
	process.exit(2);
}
const argv = process.argv.slice(2);
let glb = null;
let steps = 20;
for (let i = 0; i < argv.length; i++) {
	if (argv[i] === '--glb' && i + 1 < argv.length) glb = resolve(argv[++i]);
	else if (argv[i] === '--steps' && i + 1 < argv.length) steps = Number(argv[++i]);
	else usage(`unknown argument ${argv[i]}`);
}
if (!glb) usage('--glb is required');
if (!Number.isInteger(steps) || steps < 1) usage('--steps takes a positive whole number');

const viewerRoot = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const server = await startServer(viewerRoot, dirname(glb));
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', args: CHROMIUM_ARGS });
try {
	const page = await browser.newPage({ viewport: { width: 320, height: 240 } });
	const q = new URLSearchParams({ file: `/model/${basename(glb)}`, mode: 'walk', ui: '0' });
	await page.goto(`http://127.0.0.1:${server.address().port}/index.html?${q}`);
	await page.waitForFunction(() => window.viewerReady === true || typeof window.viewerError === 'string', null, { timeout: 300_000 });
	const r = await page.evaluate((n) => {
		if (window.viewerError) return { error: window.viewerError };
		const v = window.viewer;
		const t0 = performance.now();
		for (let i = 0; i < n; i++) v.walker.step(0.05, 0);
		const t1 = performance.now();
		const ray = new v.THREE.Raycaster();
		for (let i = 0; i < n; i++) {
			ray.setFromCamera(new v.THREE.Vector2(0, 0), v.camera);
			ray.intersectObject(v.state.model, true);
		}
		const t2 = performance.now();
		return { triangles: window.viewerInfo.triangles, step: (t1 - t0) / n, probe: (t2 - t1) / n };
	}, steps);
	if (r.error) throw new Error(r.error);
	console.log(`${basename(glb)}: ${r.triangles} triangles, ${r.step.toFixed(1)} ms a step, ${r.probe.toFixed(1)} ms a probe (${steps} each)`);
} finally {
	await browser.close();
	server.close();
}
