// SPDX-License-Identifier: LGPL-2.1-or-later
// What the viseme detector's browser test (viseme-detector.browser.js) and its benchmark
// (../bench/viseme-worklet.browser.js) share: the repository's root served as the example
// page's text says (python3 -m http.server, on 127.0.0.1), and 16-bit mono WAV files. Both run
// in a network namespace with only lo (tests/web/pfap-web-browser.sh); Chromium is
// janus.js's launchChromium.
import { spawn } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { stop } from './janus.js';

export const sourceRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');

/**
 * Serves the repository's root on a free port of 127.0.0.1 (an AudioWorklet needs a secure
 * context: loopback is one). Resolves to {url, stop}.
 */
export function serveSourceRoot() {
  const server = spawn('python3', ['-u', '-m', 'http.server', '--bind', '127.0.0.1', '--directory', sourceRoot, '0'], {
    stdio: ['ignore', 'pipe', 'pipe'],
  });
  let log = '';
  server.stderr.on('data', (d) => { log += d; });
  return new Promise((resolve, reject) => {
    server.on('exit', (code) => reject(new Error(`python3 -m http.server exited (${code}): ${log}`)));
    server.stdout.on('data', (d) => {
      log += d;
      const m = /port (\d+)/.exec(log);
      if (m) resolve({ url: `http://127.0.0.1:${m[1]}`, stop: () => stop(server) });
    });
  });
}

/** A 16-bit mono PCM WAV file: {rate, samples (Int16Array)}. */
export function readWav(file) {
  const b = readFileSync(file);
  let at = 12;
  while (b.toString('latin1', at, at + 4) !== 'data') at += 8 + b.readUInt32LE(at + 4);
  const n = b.readUInt32LE(at + 4) / 2;
  return { rate: b.readUInt32LE(24), samples: Int16Array.from({ length: n }, (_, i) => b.readInt16LE(at + 8 + 2 * i)) };
}

/** Writes `samples` (Int16Array) as a 16-bit mono PCM WAV file. */
export function writeWav(file, { rate, samples }) {
  const b = Buffer.alloc(44 + samples.length * 2);
  b.write('RIFF', 0, 'latin1');
  b.writeUInt32LE(36 + samples.length * 2, 4);
  b.write('WAVEfmt ', 8, 'latin1');
  b.writeUInt32LE(16, 16);
  b.writeUInt16LE(1, 20);
  b.writeUInt16LE(1, 22);
  b.writeUInt32LE(rate, 24);
  b.writeUInt32LE(rate * 2, 28);
  b.writeUInt16LE(2, 32);
  b.writeUInt16LE(16, 34);
  b.write('data', 36, 'latin1');
  b.writeUInt32LE(samples.length * 2, 40);
  samples.forEach((s, i) => b.writeInt16LE(s, 44 + 2 * i));
  writeFileSync(file, b);
}
