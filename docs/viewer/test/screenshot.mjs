#!/usr/bin/env node
// Renders a .glb (or .gltf) with the viewer in headless Chromium and writes
// a W × H PNG of the page (ui=0: no overlays; --ui keeps them, for pictures
// of the page itself).
//
//   node test/screenshot.mjs --glb FILE --width W --height H --out OUT.png
//                            [--exposure STOPS] [--chromium PATH] [--timeout S]
//                            [--info INFO.json] [--ui] [--lookat CSV]
//                            [--glossy 0|1] [--mask glossy]
//
// --lookat, --glossy and --mask pass the viewer's query parameters of the
// same names (another view; the baked glossy light off; the mask of the
// glossy sides).
//
// A static HTTP server on 127.0.0.1 (a free port) serves docs/viewer at / and
// the model's directory at /model/; Debian's Chromium (/usr/bin/chromium, or
// --chromium, or $CHROMIUM) runs headless through playwright-core with a fresh
// temporary user-data-dir, a W × H viewport at device scale factor 1, and
// WebGL on ANGLE over SwiftShader (software Vulkan): no GPU is needed, and a
// machine that has one renders the same way. The page's console errors are
// printed; any failure exits 1 with one line saying why (after the page's
// console output when the viewer did not become ready). --info writes the
// viewer's description of what it loaded (window.viewerInfo) as JSON.

import { mkdtempSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { CHROMIUM_ARGS, startServer } from './browser.mjs';

const viewerRoot = resolve(dirname(fileURLToPath(import.meta.url)), '..');

function die(msg) {
	console.error(`screenshot.mjs: ${msg}`);
	process.exit(1);
}
function usage(msg) {
	console.error(`screenshot.mjs: ${msg}\nusage: node test/screenshot.mjs --glb FILE --width W --height H --out OUT.png [--exposure STOPS] [--chromium PATH] [--timeout SECONDS] [--info INFO.json]`);
	process.exit(2);
}

function parseArgs(argv) {
	const o = { exposure: null, chromium: process.env.CHROMIUM || '/usr/bin/chromium', timeout: 60 };
	for (let i = 0; i < argv.length; i++) {
		const a = argv[i];
		const val = () => {
			if (i + 1 >= argv.length) usage(`${a} needs a value`);
			return argv[++i];
		};
		if (a === '--glb') o.glb = val();
		else if (a === '--width') o.width = val();
		else if (a === '--height') o.height = val();
		else if (a === '--out') o.out = val();
		else if (a === '--exposure') o.exposure = val();
		else if (a === '--chromium') o.chromium = val();
		else if (a === '--timeout') o.timeout = val();
		else if (a === '--info') o.info = val();
		else if (a === '--ui') o.ui = true;
		else if (a === '--lookat') o.lookat = val();
		else if (a === '--glossy') o.glossy = val();
		else if (a === '--mask') o.mask = val();
		else usage(`unknown argument ${a}`);
	}
	if (!o.glb) usage('--glb is required');
	if (!o.out) usage('--out is required');
	for (const k of ['width', 'height']) {
		const n = Number(o[k]);
		if (o[k] === undefined) usage(`--${k} is required`);
		if (!Number.isInteger(n) || n < 1 || n > 8192) usage(`--${k} ${o[k]} is not a size in pixels (1..8192)`);
		o[k] = n;
	}
	if (o.exposure !== null && !Number.isFinite(Number(o.exposure))) usage(`--exposure ${o.exposure} is not a number`);
	o.timeout = Number(o.timeout);
	if (!(o.timeout > 0)) usage('--timeout takes a positive number of seconds');
	return o;
}

function pngSize(buf) {
	const sig = '89504e470d0a1a0a';
	if (buf.length < 24 || buf.subarray(0, 8).toString('hex') !== sig) return null;
	return { width: buf.readUInt32BE(16), height: buf.readUInt32BE(20) };
}

async function main() {
	const o = parseArgs(process.argv.slice(2));
	const model = resolve(o.glb);
	try {
		if (!statSync(model).isFile()) die(`${o.glb} is not a file`);
	} catch {
		die(`${o.glb} does not exist`);
	}
	try {
		statSync(o.chromium);
	} catch {
		die(`no Chromium at ${o.chromium} (apt-get install -y chromium, or pass --chromium PATH)`);
	}
	for (const f of ['index.html', 'viewer.js', 'vendor/three/build/three.module.js']) {
		try {
			statSync(join(viewerRoot, f));
		} catch {
			die(`${join(viewerRoot, f)} is missing${f.startsWith('vendor') ? ' (run npm run vendor)' : ''}`);
		}
	}

	const server = await startServer(viewerRoot, dirname(model));
	const port = server.address().port;
	const q = new URLSearchParams({ file: `/model/${basename(model)}`, ui: o.ui ? '1' : '0' });
	if (o.exposure !== null) q.set('exposure', String(Number(o.exposure)));
	for (const k of ['lookat', 'glossy', 'mask']) if (o[k] !== undefined) q.set(k, o[k]);
	const url = `http://127.0.0.1:${port}/index.html?${q}`;

	const userDataDir = mkdtempSync(join(tmpdir(), 'trilux-viewer-chromium-'));
	const consoleLines = [];
	const errors = [];
	let context;
	let failure = null;
	try {
		context = await chromium.launchPersistentContext(userDataDir, {
			executablePath: o.chromium,
			headless: true,
			args: CHROMIUM_ARGS,
			viewport: { width: o.width, height: o.height },
			deviceScaleFactor: 1,
			timeout: 60_000,
		});
		const page = context.pages()[0] ?? (await context.newPage());
		page.on('console', (m) => {
			const line = `[console.${m.type()}] ${m.text()}`;
			consoleLines.push(line);
			if (m.type() === 'error') errors.push(line);
		});
		page.on('pageerror', (e) => {
			const line = `[pageerror] ${e.message}`;
			consoleLines.push(line);
			errors.push(line);
		});
		page.on('requestfailed', (r) => {
			const line = `[requestfailed] ${r.url()} ${r.failure()?.errorText ?? ''}`;
			consoleLines.push(line);
			errors.push(line);
		});
		await page.goto(url, { waitUntil: 'load', timeout: o.timeout * 1000 });
		try {
			await page.waitForFunction(() => window.viewerReady === true || typeof window.viewerError === 'string',
				null, { timeout: o.timeout * 1000, polling: 100 });
		} catch {
			failure = `the viewer was not ready after ${o.timeout} s`;
		}
		const state = await page.evaluate(() => ({
			ready: window.viewerReady === true, error: window.viewerError, info: window.viewerInfo,
			gl: (() => {
				const gl = window.viewer?.renderer?.getContext();
				if (!gl) return null;
				const ext = gl.getExtension('WEBGL_debug_renderer_info');
				return gl.getParameter(ext ? ext.UNMASKED_RENDERER_WEBGL : gl.RENDERER);
			})(),
		})).catch((e) => ({ ready: false, error: `page evaluation failed: ${e.message}` }));
		if (state.error) failure = `viewer error: ${state.error}`;
		if (!failure && !state.ready) failure = 'the viewer did not become ready';
		if (failure) {
			for (const l of consoleLines) console.error(l);
		} else {
			for (const l of errors) console.error(l);
			const png = await page.screenshot({ type: 'png', animations: 'disabled', caret: 'hide' });
			const size = pngSize(png);
			if (!size || size.width !== o.width || size.height !== o.height) {
				failure = `the screenshot is ${size ? `${size.width}×${size.height}` : 'not a PNG'}, not ${o.width}×${o.height}`;
			} else {
				writeFileSync(o.out, png);
				const info = state.info || {};
				if (o.info) writeFileSync(o.info, JSON.stringify({ ...info, webgl: state.gl }, null, 2) + '\n');
				console.log(`${o.out}: ${o.width}×${o.height}, ${info.triangles ?? '?'} triangles, view from ${info.camera ?? '?'}, WebGL: ${state.gl}`);
			}
		}
	} catch (e) {
		failure = `${e && e.message ? e.message.split('\n')[0] : e}`;
		for (const l of consoleLines) console.error(l);
	} finally {
		if (context) await context.close().catch(() => {});
		server.close();
		rmSync(userDataDir, { recursive: true, force: true });
	}
	if (failure) die(failure);
}

main().catch((e) => die(e && e.message ? e.message : String(e)));
