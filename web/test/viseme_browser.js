// SPDX-License-Identifier: LGPL-2.1-or-later
// What the viseme detector's browser test (viseme-detector.browser.js) and its benchmark
// (../bench/viseme-worklet.browser.js) share: the repository's root served as the example
// page's text says (python3 -m http.server, on 127.0.0.1). Both run
// in a network namespace with only lo (tests/web/pfap-web-browser.sh); Chromium is
// janus.js's launchChromium.
import { spawn } from 'node:child_process';
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
