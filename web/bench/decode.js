// SPDX-License-Identifier: LGPL-2.1-or-later
// Decode speed in Node: decodePayload on the packet of bench_payload's BM_DecodeValidate (a
// full 1388-byte payload as speech gives it: dynamic recovery over 4 packets with 3 entries,
// then phonemes of which one in four carries 2 FAPs), and on a small packet of one phoneme
// with 2 FAPs. Prints payload bytes/s and descriptors/s, best of 5 runs of about 1 s of CPU time each.
// Run: node bench/decode.js (docs/performance.md)
import { decodePayload, encodePayload } from '../src/index.js';

function randomFap(i) {
  return { index: 3 + (i * 7) % 72, amplitude: ((i * 7919) % 5059201) - 2529600, transition: (i * 131) % 16384, curve: 1 + (i % 3) };
}

function typicalPacket() {
  const packet = { complete: false, coverage: 4, recovery: [0, 1, 2].map(randomFap), phonemes: [] };
  let size = 1 + 6 * 3;
  for (let i = 0; ; ++i) {
    const faps = i % 4 === 0 ? [randomFap(2 * i + 3), randomFap(2 * i + 4)] : [];
    if (size + 4 + 6 * faps.length > 1388) break;
    size += 4 + 6 * faps.length;
    packet.phonemes.push({ symbol: i % 256, duration: (i * 37) % 401, f0: 2 * ((i * 13) % 256), stress: i % 3 === 0, wordBegin: i % 5 === 0, endOfText: false, faps });
  }
  return packet;
}

function measure(name, packet) {
  const bytes = encodePayload(packet);
  const descriptors = 1 + packet.recovery.length + packet.phonemes.reduce((n, p) => n + 1 + p.faps.length, 0);
  let best = Infinity;
  let sink = 0;
  for (let run = 0; run < 5; ++run) {
    let n = 0;
    // CPU time, as google-benchmark's figures: the machine may be shared.
    const start = process.cpuUsage();
    let elapsed = 0;
    while (elapsed < 1e9) {
      for (let k = 0; k < 100; ++k) sink += decodePayload(bytes).ok ? 1 : 0;
      n += 100;
      const used = process.cpuUsage(start);
      elapsed = (used.user + used.system) * 1e3;
    }
    best = Math.min(best, elapsed / n);
  }
  if (sink === 0) throw new Error('nothing decoded');
  console.log(
    `${name}: ${bytes.length} bytes, ${descriptors} descriptors: ${best.toFixed(0)} ns per packet, ` +
      `${((bytes.length / best) * 1e3).toFixed(1)} MB/s, ${((descriptors / best) * 1e3).toFixed(1)} M descriptors/s`,
  );
}

measure('typical (bench_payload)', typicalPacket());
measure('small', { complete: false, coverage: 0, recovery: [], phonemes: [{ symbol: 7, duration: 80, f0: 0, stress: false, wordBegin: true, endOfText: false, faps: [randomFap(1), randomFap(2)] }] });
