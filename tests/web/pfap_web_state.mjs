// SPDX-License-Identifier: LGPL-2.1-or-later
// The FAP state each load-generator session ends with (tests/web/pfap_web_load.py), decoded by
// the project's own receiver (web/src/, bit-exact with libpfap) rather than a third decoder.
// Reads one JSON array on stdin, a session each: its data-channel messages (whole PFAP RTP
// packets) in arrival order, base64. Writes one JSON array: per session the settled values of
// FAPs 3..74 (as the server's "done" message lists them), whether the receiver holds the whole
// state, and its counters.
//
//   node pfap_web_state.mjs < sessions.json      (PFAP_SOURCE_ROOT: the source tree)
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const root = process.env.PFAP_SOURCE_ROOT ?? fileURLToPath(new URL('../..', import.meta.url));
const { PfapReceiver } = await import(pathToFileURL(join(root, 'web', 'src', 'index.js')).href);

const MIN_FAP_INDEX = 3;
const MAX_FAP_INDEX = 74;
const warnings = [];
const out = JSON.parse(readFileSync(0, 'utf8')).map((messages) => {
  const receiver = new PfapReceiver({ onWarning: (w) => warnings.push(w) });
  for (const m of messages) receiver.receive(new Uint8Array(Buffer.from(m, 'base64')));
  const state = receiver.recovery.state;
  const settled = [];
  for (let i = MIN_FAP_INDEX; i <= MAX_FAP_INDEX; ++i) settled.push(state.settled(i));
  return { settled, stateWhole: receiver.stateWhole, stats: receiver.stats };
});
for (const w of warnings.slice(0, 10)) console.error(`pfap_web_state: ${w}`);
process.stdout.write(JSON.stringify(out));
