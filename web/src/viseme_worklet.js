// SPDX-License-Identifier: LGPL-2.1-or-later
// The viseme detector (viseme_detector.js) in an AudioWorklet: add this module to an
// AudioContext's audioWorklet, make an AudioWorkletNode 'pfap-viseme-detector' with
// processorOptions {modelText} (the text of align/viseme_model.txt), and connect any source
// to it (an <audio> element's, a MediaStream's: a WebRTC call's remote speaker, a
// microphone). Its input is mixed to mono; it passes the audio through unchanged. On its port
// it posts, as the detector settles them:
//   {type: 'start', time}: the context's time (currentTime, s) of the node's first audio;
//   {type: 'viseme', viseme, frame}: the viseme shown from 10 ms frame `frame` of the stream
//     (frame 0 at the node's first audio, frame k 10k ms of the context's time after it: a
//     render quantum without input after the first is silence) until the next such message;
//   {type: 'runs', runs: [{start, frames, viseme}...]}: the runs that ended.
// Post 'finish' to it for the last ones. The processor's class is exported too, for the
// benchmark that times it (web/bench/viseme_worklet_timed.js). docs/align.md, "A viseme detector".
import { VisemeDetector, parseVisemeModel } from './viseme_detector.js';

export class VisemeDetectorProcessor extends AudioWorkletProcessor {
  constructor(options) {
    super();
    const { modelText, ...settings } = options.processorOptions;
    // sampleRate: the AudioWorkletGlobalScope's, the context's rate.
    this.detector = new VisemeDetector(sampleRate, { ...settings, model: parseVisemeModel(modelText) });
    this.shownFrom = -1;
    this.port.onmessage = (e) => {
      if (e.data === 'finish') this.report(this.detector.finish());
    };
  }

  report(runs) {
    if (runs.length > 0) this.port.postMessage({ type: 'runs', runs });
    const open = this.detector.open;
    if (open.frames > 0 && open.start !== this.shownFrom) {
      this.shownFrom = open.start;
      this.port.postMessage({ type: 'viseme', viseme: open.viseme, frame: open.start });
    }
  }

  process(inputs, outputs) {
    const input = inputs[0];
    if ((input === undefined || input.length === 0) && this.shownFrom !== -1) {
      // A source that stops, or is not yet playing, gives no input: without this, the frames
      // after it would fall behind the context's time (once 40 ms at the example's start).
      this.silence ??= new Float32Array(outputs[0]?.[0]?.length ?? 128);
      this.report(this.detector.push(this.silence));
    }
    if (input !== undefined && input.length > 0) {
      if (this.shownFrom === -1) {
        this.shownFrom = -2;
        this.port.postMessage({ type: 'start', time: currentTime });
      }
      const mono = new Float32Array(input[0].length);
      for (const channel of input) for (let i = 0; i < mono.length; i++) mono[i] += channel[i] / input.length;
      this.report(this.detector.push(mono));
      const output = outputs[0];
      for (let c = 0; c < output.length; c++) output[c].set(input[Math.min(c, input.length - 1)]);
    }
    return true;
  }
}

registerProcessor('pfap-viseme-detector', VisemeDetectorProcessor);
