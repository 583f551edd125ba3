// The package as a page and a TypeScript user get it: every module imports only relative
// paths with their extensions (a browser loads them from a served directory, no bundler) and
// uses no Node-only API; index.d.ts declares every export; `npm pack` ships src/ and
// package.json, and nothing of the tests.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync, readdirSync } from 'node:fs';
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

test('npm pack ships the modules and their types', () => {
  const [pack] = JSON.parse(execFileSync('npm', ['pack', '--dry-run', '--json'], { cwd: root, encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] }));
  const files = pack.files.map((f) => f.path).sort();
  assert.deepEqual(files, ['package.json', 'src/index.d.ts', ...sources.map((f) => `src/${f}`)].sort());
});
