// SPDX-License-Identifier: LGPL-2.1-or-later
// An AudioWorklet that taps the audio the page plays: the RMS of each millisecond, with the
// AudioContext time of its first sample, posted to the page every 10 ms (live.js finds it in
// the level the server sent, to know which running time it hears, and finds the speech onsets
// in it for the lip-sync measurement).
class Tap extends AudioWorkletProcessor {
  constructor() {
    super();
    this.block = Math.round(sampleRate / 1000);
    this.sum = 0;
    this.count = 0;
    this.start = 0;
    this.out = [];
  }

  process(inputs) {
    const channel = inputs[0]?.[0];
    if (channel) {
      for (let i = 0; i < channel.length; ++i) {
        if (this.count === 0) this.start = currentTime + i / sampleRate;
        this.sum += channel[i] * channel[i];
        if (++this.count === this.block) {
          this.out.push(this.start, Math.sqrt(this.sum / this.count));
          this.sum = 0;
          this.count = 0;
        }
      }
      if (this.out.length >= 20) {
        this.port.postMessage(this.out);
        this.out = [];
      }
    }
    return true;
  }
}

registerProcessor('pfap-tap', Tap);
