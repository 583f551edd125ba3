// SPDX-License-Identifier: LGPL-2.1-or-later
// 16-bit mono PCM WAV files, as tools/pfap-viseme-data reads and writes them, for the viseme
// detector's tests and benchmark.
import { readFileSync, writeFileSync } from 'node:fs';

/** A 16-bit mono PCM WAV file: {rate, samples (Int16Array)}. */
export function readWav(file) {
  const b = readFileSync(file);
  let at = 12;
  while (b.toString('latin1', at, at + 4) !== 'data') at += 8 + b.readUInt32LE(at + 4);
  const n = b.readUInt32LE(at + 4) / 2;
  return { rate: b.readUInt32LE(24), samples: Int16Array.from({ length: n }, (_, i) => b.readInt16LE(at + 8 + 2 * i)) };
}

/** Writes `samples` (Int16Array) as a 16-bit mono PCM WAV file. */
export function writeWav(file, rate, samples) {
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
