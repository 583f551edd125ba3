// SPDX-License-Identifier: LGPL-2.1-or-later
// The package as a page and a TypeScript user get it: every module imports only relative
// paths with their extensions (a browser loads them from a served directory, no bundler) and
// uses no Node-only API; index.d.ts declares every export; `npm pack` ships src/ and
// package.json, and nothing of the tests; the tarball installs, and `import 'pfap'` works.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { test } from 'node:test';
import { fileURLToPath } from 'node:url';

import * as pfap from '../src/index.js';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const sources = readdirSync(path.join(root, 'src')).filter((f) => f.endsWith('.js'));

test('modules import only relative paths, and no Node API', () => {
  for (const file of sources) {
    const text = readFileSync(path.join(root, 'src', file), 'utf8');
    for (const [, specifier] of text.matchAll(/^(?:import|export)[^'"]*from\s+'([^']+)'/gm)) {
      assert.match(specifier, /^\.\/[a-z_]+\.js$/, `${file} imports ${specifier}`);
    }
    assert.doesNotMatch(text, /\b(require\(|process\.|Buffer\.|node:)/, `${file} uses Node`);
  }
});

test('index.d.ts declares every export of index.js', () => {
  const dts = readFileSync(path.join(root, 'src', 'index.d.ts'), 'utf8');
  for (const name of Object.keys(pfap)) {
    assert.match(dts, new RegExp(`export declare (const|function|class) ${name}\\b`), name);
  }
});

test('index.d.ts type-checks, and a page written against it too (tsc --strict)', () => {
  const tsc = path.join(root, 'node_modules', 'typescript', 'bin', 'tsc');
  const args = ['--noEmit', '--strict', '--target', 'es2020', '--module', 'es2020', '--moduleResolution', 'node', '--lib', 'es2020,dom'];
  try {
    execFileSync(process.execPath, [tsc, ...args, path.join(root, 'test', 'types.ts')], { encoding: 'utf8' });
  } catch (e) {
    assert.fail(`tsc: ${e.stdout}${e.message}`);
  }
});

test('npm pack ships the modules, their types and the README', () => {
  const [pack] = JSON.parse(execFileSync('npm', ['pack', '--dry-run', '--json'], { cwd: root, encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] }));
  const files = pack.files.map((f) => f.path).sort();
  assert.deepEqual(files, ['README.md', 'package.json', 'src/index.d.ts', ...sources.map((f) => `src/${f}`)].sort());
});

// The README's "Example" section: its first js block, and the text block it says it prints.
function readmeExample(readme) {
  const section = readme.split(/^## /m).find((s) => s.startsWith('Example\n'));
  assert.ok(section, 'no "## Example" section in README.md');
  const code = section.match(/```js\n([\s\S]*?)```/);
  const output = section.match(/```text\n([\s\S]*?)```/);
  assert.ok(code && output, 'the Example section has no js block, or no text block of its output');
  return { code: code[1], output: output[1] };
}

test('the README names every export', () => {
  const readme = readFileSync(path.join(root, 'README.md'), 'utf8');
  for (const name of Object.keys(pfap)) assert.match(readme, new RegExp(`\`(new )?${name}\\b`), name);
});

test('the tarball installs into a project, and import \'pfap\' gives the package', () => {
  const dir = mkdtempSync(path.join(tmpdir(), 'pfap-pack-'));
  try {
    const quiet = { cwd: dir, encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] };
    const [pack] = JSON.parse(execFileSync('npm', ['pack', root, '--json'], quiet));
    writeFileSync(path.join(dir, 'package.json'), '{"name": "user", "version": "1.0.0", "type": "module"}');
    // No dependencies to fetch: the install needs no network.
    execFileSync('npm', ['install', '--offline', '--no-audit', '--no-fund', `./${pack.filename}`], quiet);
    writeFileSync(path.join(dir, 'use.js'), "import { decodePayload } from 'pfap';\n" +
      'console.log(JSON.stringify(decodePayload(new Uint8Array([0x00, 7, 5, 0, 6]))));\n');
    const out = JSON.parse(execFileSync(process.execPath, ['use.js'], quiet));
    assert.deepStrictEqual(out, { ok: true, packet: { complete: false, coverage: 0, recovery: [], phonemes: [
      { symbol: 7, duration: 80, f0: 0, stress: false, wordBegin: true, endOfText: false, faps: [] }] } });
    // The README as installed, and its example run there as it says, printing what it says.
    const example = readmeExample(readFileSync(path.join(dir, 'node_modules', 'pfap', 'README.md'), 'utf8'));
    writeFileSync(path.join(dir, 'example.mjs'), example.code);
    assert.equal(execFileSync(process.execPath, ['example.mjs'], quiet), example.output);
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});

test('findPhoneme and findSymbol take the alphabet object, and say so when given its name', () => {
  const arpabet = pfap.findAlphabet(pfap.ARPABET_ALPHABET);
  assert.deepEqual(pfap.findPhoneme(arpabet, 16), { name: 'HH', viseme: pfap.Viseme.KG });
  assert.equal(pfap.findSymbol(arpabet, 'HH'), 16);
  for (const [call, name] of [[() => pfap.findPhoneme(pfap.ARPABET_ALPHABET, 16), 'findPhoneme'],
    [() => pfap.findSymbol(pfap.ARPABET_ALPHABET, 'HH'), 'findSymbol']]) {
    assert.throws(call, { name: 'TypeError', message: `${name}: alphabet must be a PhonemeAlphabet, as findAlphabet(name) returns it, not the name 'x-pfap-arpabet'` });
  }
  assert.throws(() => pfap.findPhoneme(null, 16), { name: 'TypeError', message: /^findPhoneme: alphabet must be a PhonemeAlphabet.* not null$/ });
});
