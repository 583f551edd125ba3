// SPDX-License-Identifier: LGPL-2.1-or-later
// The viseme detector's example page (viseme-detector.html): any audio source of an
// AudioContext through the detector's AudioWorklet, the face drawn from its visemes.
import { Animator, OCULUS_VISEME_TABLE, VISEME_LOOKAHEAD_MS, renderFace } from '../src/index.js';

/** The Animator's longest phoneme: a viseme lasts until the next one replaces it. */
const HOLD_MS = 4095;

/**
 * Drives the face on `canvas` from `source` (an AudioNode of `context`): the detector's
 * visemes go to an Animator as phonemes of the Oculus viseme alphabet; with `monitor` the
 * sound plays, delayed by the detector's lookahead and one render quantum so that the face
 * keeps up with it.
 * @returns {Promise<{node: AudioWorkletNode, animator: Animator, delayMs: number}>}
 */
export async function drive(canvas, context, source, options = {}) {
  const modelUrl = options.modelUrl ?? new URL('../../align/viseme_model.txt', import.meta.url);
  await context.audioWorklet.addModule(new URL('../src/viseme_worklet.js', import.meta.url));
  const modelText = await (await fetch(modelUrl)).text();
  const node = new AudioWorkletNode(context, 'pfap-viseme-detector', { processorOptions: { modelText } });
  const delayMs = VISEME_LOOKAHEAD_MS + (128 / context.sampleRate) * 1000;
  const delay = context.createDelay(1);
  delay.delayTime.value = delayMs / 1000;
  const out = context.createGain();
  out.gain.value = options.monitor === false ? 0 : 1;  // the worklet runs only when pulled
  source.connect(node).connect(delay).connect(out).connect(context.destination);

  const animator = new Animator(OCULUS_VISEME_TABLE);
  let startTime = null;
  node.port.onmessage = ({ data }) => {
    if (data.type === 'start') startTime = data.time;
    if (data.type === 'viseme') {
      animator.apply({ kind: 'phoneme', phoneme: { symbol: data.viseme, duration: HOLD_MS }, faps: [] }, data.frame * 10e6);
    }
  };
  const ctx = canvas.getContext('2d');
  const frame = () => {
    // The stream's time now sounding: the context's time less the delay, from the first audio.
    const ms = startTime === null ? 0 : (context.currentTime - startTime) * 1000 - delayMs;
    renderFace(ctx, animator.pose(Math.max(0, ms) * 1e6), { overlay: animator.describe(Math.max(0, ms) * 1e6) });
    requestAnimationFrame(frame);
  };
  frame();
  return { node, animator, delayMs };
}
