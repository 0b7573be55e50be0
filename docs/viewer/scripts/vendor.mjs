#!/usr/bin/env node
// Copies the parts of three.js that the viewer imports from node_modules/three
// into vendor/three/, keeping three's own directory layout so that no import
// needs rewriting: the only bare specifier in the copied files is 'three',
// which index.html's import map resolves to vendor/three/build/three.module.js.
//
//   node scripts/vendor.mjs           write vendor/ (removes stale files)
//   node scripts/vendor.mjs --check   exit 1 if vendor/ differs from what
//                                     the first form would write
//
// The file set is found by following the relative imports of the entry points
// below, so an upgrade of three that adds a dependency is picked up.

import { readFileSync, writeFileSync, mkdirSync, readdirSync, rmSync, existsSync, statSync } from 'node:fs';
import { dirname, join, posix, relative, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const src = join(root, 'node_modules', 'three');
const out = join(root, 'vendor', 'three');

// Paths inside the three package.
const ENTRIES = [
	'build/three.module.js',
	'examples/jsm/loaders/GLTFLoader.js',
	'examples/jsm/controls/OrbitControls.js',
	'examples/jsm/controls/PointerLockControls.js',
];
const EXTRA = ['LICENSE'];

function usage(msg) {
	console.error(`vendor.mjs: ${msg}\nusage: node scripts/vendor.mjs [--check]`);
	process.exit(2);
}

const args = process.argv.slice(2);
const check = args.includes('--check');
for (const a of args) if (a !== '--check') usage(`unknown argument ${a}`);

if (!existsSync(join(src, 'package.json'))) {
	console.error(`vendor.mjs: ${relative(process.cwd(), src) || src} is missing: run \`npm ci\` in docs/viewer first`);
	process.exit(1);
}
const pkg = JSON.parse(readFileSync(join(src, 'package.json'), 'utf8'));
const wanted = JSON.parse(readFileSync(join(root, 'package.json'), 'utf8')).dependencies.three;
if (pkg.version !== wanted) {
	console.error(`vendor.mjs: node_modules has three ${pkg.version}, package.json pins ${wanted}: run \`npm ci\``);
	process.exit(1);
}

// Static import/export specifiers ("from '...'" and bare "import '...'").
const IMPORT_RE = /(?:\bfrom\s*|\bimport\s*)(['"])([^'"]+)\1/g;

/** @type {Map<string, Buffer>} path inside vendor/three -> contents */
const files = new Map();
const queue = [...ENTRIES];
while (queue.length) {
	const rel = queue.shift();
	if (files.has(rel)) continue;
	const text = readFileSync(join(src, rel), 'utf8');
	files.set(rel, Buffer.from(text, 'utf8'));
	for (const m of text.matchAll(IMPORT_RE)) {
		const spec = m[2];
		if (spec === 'three') continue; // the import map's entry
		if (!spec.startsWith('./') && !spec.startsWith('../')) {
			// Only in comments (JSDoc examples such as 'three/addons/...'): a real
			// import of another bare specifier would fail in the browser.
			continue;
		}
		const target = posix.normalize(posix.join(posix.dirname(rel), spec));
		if (!existsSync(join(src, target))) {
			console.error(`vendor.mjs: ${rel} imports ${spec}, which three ${pkg.version} does not have`);
			process.exit(1);
		}
		queue.push(target);
	}
}
for (const rel of EXTRA) files.set(rel, readFileSync(join(src, rel)));

const manifest = {
	package: 'three',
	version: pkg.version,
	generatedBy: 'scripts/vendor.mjs',
	files: Object.fromEntries([...files.keys()].sort().map((k) => [k, files.get(k).length])),
};
files.set('VENDOR.json', Buffer.from(JSON.stringify(manifest, null, '\t') + '\n', 'utf8'));

function listTree(dir, base = '') {
	if (!existsSync(dir)) return [];
	const res = [];
	for (const name of readdirSync(dir)) {
		const p = join(dir, name);
		const r = base ? `${base}/${name}` : name;
		if (statSync(p).isDirectory()) res.push(...listTree(p, r));
		else res.push(r);
	}
	return res;
}

if (check) {
	const problems = [];
	const present = new Set(listTree(out));
	for (const [rel, buf] of files) {
		if (!present.has(rel)) problems.push(`missing  vendor/three/${rel}`);
		else if (!readFileSync(join(out, rel)).equals(buf)) problems.push(`differs  vendor/three/${rel}`);
	}
	for (const rel of present) if (!files.has(rel)) problems.push(`extra    vendor/three/${rel}`);
	if (problems.length) {
		for (const p of problems) console.error(p);
		console.error(`vendor.mjs --check: vendor/ does not match three ${pkg.version}: run \`npm run vendor\` in docs/viewer and commit`);
		process.exit(1);
	}
	console.log(`vendor.mjs --check: vendor/ matches three ${pkg.version} (${files.size} files)`);
	process.exit(0);
}

rmSync(out, { recursive: true, force: true });
let total = 0;
for (const [rel, buf] of [...files].sort()) {
	const p = join(out, rel);
	mkdirSync(dirname(p), { recursive: true });
	writeFileSync(p, buf);
	total += buf.length;
	console.log(`${String(buf.length).padStart(9)}  vendor/three/${rel}`);
}
console.log(`${String(total).padStart(9)}  total, three ${pkg.version}`);
