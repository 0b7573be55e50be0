#!/usr/bin/env node
// Runs the Khronos glTF validator on each file: one line per file with its
// counts of errors, warnings, infos and hints, then each error and warning
// (code, message, JSON pointer). A .gltf's external resources (buffers,
// images) are loaded from beside it.
//
//   node test/validate.mjs [--infos] FILE...
//
// --infos also lists infos and hints. Exit status: 0 when no file has an
// error or a warning, 1 otherwise (or when a file cannot be read or parsed),
// 2 on a usage error.

import { readFile } from 'node:fs/promises';
import { basename, dirname, resolve } from 'node:path';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
const validator = require('gltf-validator');

const SEVERITY = ['error', 'warning', 'info', 'hint'];

function usage(msg) {
	if (msg) console.error(`validate.mjs: ${msg}`);
	console.error('usage: node test/validate.mjs [--infos] FILE.glb|FILE.gltf...');
	process.exit(2);
}

const args = process.argv.slice(2);
let listAll = false;
const files = [];
for (const a of args) {
	if (a === '--infos') listAll = true;
	else if (a === '-h' || a === '--help') usage();
	else if (a.startsWith('--')) usage(`unknown option ${a}`);
	else files.push(a);
}
if (files.length === 0) usage('no file given');

let bad = false;
for (const file of files) {
	const full = resolve(file);
	let bytes;
	try {
		bytes = new Uint8Array(await readFile(full));
	} catch (e) {
		console.log(`${file}: cannot read: ${e.message}`);
		bad = true;
		continue;
	}
	let report;
	try {
		report = await validator.validateBytes(bytes, {
			uri: basename(full),
			maxIssues: 0, // no limit
			externalResourceFunction: async (uri) => {
				const p = resolve(dirname(full), decodeURIComponent(uri));
				return new Uint8Array(await readFile(p));
			},
		});
	} catch (e) {
		console.log(`${file}: validator failed: ${e && e.message ? e.message : e}`);
		bad = true;
		continue;
	}
	const s = report.issues;
	const verdict = s.numErrors > 0 || s.numWarnings > 0 ? 'FAIL' : 'ok';
	console.log(`${file}: ${verdict}: ${s.numErrors} errors, ${s.numWarnings} warnings, ${s.numInfos} infos, ${s.numHints} hints` +
		(s.truncated ? ' (issue list truncated)' : ''));
	for (const m of s.messages) {
		if (!listAll && m.severity > 1) continue;
		console.log(`  ${SEVERITY[m.severity] ?? m.severity} ${m.code}: ${m.message}${m.pointer ? ` (${m.pointer})` : ''}`);
	}
	if (s.numErrors > 0 || s.numWarnings > 0) bad = true;
}
process.exit(bad ? 1 : 0);
