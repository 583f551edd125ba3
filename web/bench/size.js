// SPDX-License-Identifier: LGPL-2.1-or-later
// The package's size as a page loads it: each module of src/ as is and minified (terser, a dev
// dependency), and all of them gzipped. Run: node bench/size.js (docs/performance.md)
import { readFileSync, readdirSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { gzipSync } from 'node:zlib';
import { minify } from 'terser';

const src = path.join(path.dirname(fileURLToPath(import.meta.url)), '..', 'src');
const files = readdirSync(src).filter((f) => f.endsWith('.js')).sort();
let raw = '';
let min = '';
for (const f of files) {
  const text = readFileSync(path.join(src, f), 'utf8');
  const out = (await minify(text, { module: true, compress: true, mangle: true })).code;
  console.log(`${f}: ${text.length} bytes, minified ${out.length}`);
  raw += text;
  min += out;
}
const gz = (s) => gzipSync(Buffer.from(s), { level: 9 }).length;
console.log(`all ${files.length} modules: ${raw.length} bytes (gzip ${gz(raw)}), minified ${min.length} (gzip ${gz(min)})`);
