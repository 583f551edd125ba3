// SPDX-License-Identifier: LGPL-2.1-or-later
// The C++ side of the differential tests: runs tests/web/export_vectors (built by meson; its
// path in PFAP_EXPORT_VECTORS, set by tests/web/meson.build) and parses what it writes.
import { execFileSync } from 'node:child_process';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const sourceRoot =
  process.env.PFAP_SOURCE_ROOT ?? path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');

function exporter() {
  const exe = process.env.PFAP_EXPORT_VECTORS;
  if (!exe) {
    throw new Error('PFAP_EXPORT_VECTORS is not set: run these tests with `meson test -C build --suite web`');
  }
  return exe;
}

/**
 * What export_vectors writes in `mode` (see its header), parsed.
 * @param {string[]} args
 * @param {Uint8Array} [input] its stdin
 */
export function exportVectors(args, input) {
  const out = execFileSync(exporter(), args, { input, maxBuffer: 1 << 30, encoding: 'utf8' });
  return JSON.parse(out);
}

export function fromHex(hex) {
  const out = new Uint8Array(hex.length / 2);
  for (let i = 0; i < out.length; ++i) out[i] = parseInt(hex.substr(2 * i, 2), 16);
  return out;
}

export function toHex(bytes) {
  return Buffer.from(bytes).toString('hex');
}

// A seeded generator (mulberry32), so that JS-side random inputs are the same on every run.
export function random(seed) {
  let a = seed >>> 0;
  const next = () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
  return {
    next,
    int: (lo, hi) => lo + Math.floor(next() * (hi - lo + 1)),
    chance: (p) => next() < p,
  };
}
