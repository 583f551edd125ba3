// SPDX-License-Identifier: LGPL-2.1-or-later
// The AudioWorklets of the viseme detector's browser benchmark (viseme-worklet.browser.js):
// the example's processor (src/viseme_worklet.js) and, beside it, one that only copies its
// input, each timed. AudioWorkletGlobalScope has no performance.now() in Chromium (156 here):
// Date.now() is read before and after each process(), whole milliseconds; each reading's
// error is spread evenly over a millisecond, so the sum over thousands of quanta is the time
// spent, to about a millisecond. When its input ends, a node posts {quanta, busyMs, slowestMs,
// first, last}: the quanta that had input, the time in process() over them, the longest one,
// and the context's time of the first and the last.
import { VisemeDetectorProcessor } from '../src/viseme_worklet.js';

class Copy extends AudioWorkletProcessor {
  process(inputs, outputs) {
    const input = inputs[0];
    if (input.length > 0) outputs[0].forEach((channel, c) => channel.set(input[Math.min(c, input.length - 1)]));
    return true;
  }
}

/** `Processor` with its process() timed while it has input. */
function timed(Processor) {
  return class extends Processor {
    constructor(options) {
      super(options);
      this.stats = { quanta: 0, busyMs: 0, slowestMs: 0, first: -1, last: -1 };
      this.reported = false;
    }

    process(inputs, outputs) {
      if (inputs[0].length === 0) {
        if (this.stats.quanta > 0 && !this.reported) this.port.postMessage({ type: 'stats', ...this.stats });
        this.reported = this.stats.quanta > 0;
        return super.process(inputs, outputs);
      }
      const start = Date.now();
      const more = super.process(inputs, outputs);
      const ms = Date.now() - start;
      const s = this.stats;
      s.quanta += 1;
      s.busyMs += ms;
      s.slowestMs = Math.max(s.slowestMs, ms);
      if (s.first < 0) s.first = currentTime;
      s.last = currentTime;
      return more;
    }
  };
}

registerProcessor('pfap-bench-viseme-detector', timed(VisemeDetectorProcessor));
registerProcessor('pfap-bench-copy', timed(Copy));
