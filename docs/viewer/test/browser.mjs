// What the viewer's Chromium scripts share: Chromium's flags and a static
// HTTP server (screenshot.mjs, interior.test.mjs).

import { createServer } from 'node:http';
import { createReadStream, statSync } from 'node:fs';
import { extname, resolve, sep } from 'node:path';

// What Chromium needs besides playwright's own defaults.
export const CHROMIUM_ARGS = [
	'--headless',
	'--no-sandbox',
	'--no-first-run',
	'--disable-background-networking',
	'--disable-component-update',
	'--disable-sync',
	'--disable-quic',
	// WebGL without a GPU: ANGLE on SwiftShader. Headless Chromium 156 picks it
	// by itself, but explicitly so that a machine with a GPU renders the same
	// pixels, and --enable-unsafe-swiftshader since Chromium 139 no longer
	// falls back to SwiftShader for WebGL without it (outside headless mode).
	'--use-angle=swiftshader',
	'--enable-unsafe-swiftshader',
	'--ignore-gpu-blocklist',
];

const MIME = {
	'.html': 'text/html; charset=utf-8', '.js': 'text/javascript; charset=utf-8', '.mjs': 'text/javascript; charset=utf-8',
	'.json': 'application/json', '.css': 'text/css', '.glb': 'model/gltf-binary', '.gltf': 'model/gltf+json',
	'.bin': 'application/octet-stream', '.png': 'image/png', '.jpg': 'image/jpeg', '.jpeg': 'image/jpeg',
	'.ktx2': 'image/ktx2', '.webp': 'image/webp',
};

// Serves `root` at / and `modelDir` at /model/, nothing outside them.
export function startServer(root, modelDir) {
	const server = createServer((req, res) => {
		let path;
		try {
			path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
		} catch {
			res.writeHead(400).end();
			return;
		}
		let base = root;
		if (path.startsWith('/model/')) {
			base = modelDir;
			path = path.slice('/model'.length);
		}
		if (path.endsWith('/')) path += 'index.html';
		const file = resolve(base, '.' + path);
		if (file !== base && !file.startsWith(base + sep)) {
			res.writeHead(403).end();
			return;
		}
		let st;
		try {
			st = statSync(file);
		} catch {
			st = null;
		}
		if (!st || !st.isFile()) {
			res.writeHead(404, { 'content-type': 'text/plain' }).end('not found');
			return;
		}
		res.writeHead(200, {
			'content-type': MIME[extname(file).toLowerCase()] || 'application/octet-stream',
			'content-length': st.size,
			'cache-control': 'no-store',
		});
		if (req.method === 'HEAD') res.end();
		else createReadStream(file).pipe(res);
	});
	return new Promise((ok, fail) => {
		server.once('error', fail);
		server.listen(0, '127.0.0.1', () => ok(server));
	});
}

