// SPDX-License-Identifier: LGPL-2.1-or-later
// The viseme detector's example page (viseme-detector.html): any audio source of an
// AudioContext through the detector's AudioWorklet, the face drawn from its visemes.
import { AnimationFrames, Animator, OCULUS_VISEME_TABLE, VISEME_LOOKAHEAD_MS, renderFace } from '../src/index.js';

/** The Animator's longest phoneme: a viseme lasts until the next one replaces it. */
const HOLD_MS = 4095;
/** The detector's frame: a run from frame k is known once the frame and the lookahead after it have come. */
const FRAME_MS = 10;

/**
 * Drives the face on `canvas` from `source` (an AudioNode of `context`): the detector's
 * visemes go to an Animator as phonemes of the Oculus viseme alphabet; with `monitor` the
 * sound plays, delayed by a frame, the detector's lookahead and one render quantum so that
 * each viseme is known before its sound is heard, and the face is drawn at the time heard
 * (getOutputTimestamp), not the time rendered (currentTime, ahead by the output's latency).
 * The result's `output` is what the page plays; its `onFrame`, if set, is called at each
 * frame drawn with the frame's time and the stream time drawn (ms), as the browser test
 * measures lip sync (web/test/viseme-detector.browser.js, docs/align.md "In Chromium").
 * @returns {Promise<{node: AudioWorkletNode, animator: Animator, delayMs: number,
 *   output: AudioNode, onFrame: ((now: number, ms: number) => void) | null}>}
 */
export async function drive(canvas, context, source, options = {}) {
  const modelUrl = options.modelUrl ?? new URL('../../align/viseme_model.txt', import.meta.url);
  await context.audioWorklet.addModule(new URL('../src/viseme_worklet.js', import.meta.url));
  const modelText = await (await fetch(modelUrl)).text();
  const node = new AudioWorkletNode(context, 'pfap-viseme-detector', { processorOptions: { modelText } });
  const delayMs = FRAME_MS + VISEME_LOOKAHEAD_MS + (128 / context.sampleRate) * 1000;
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
      animator.apply({ kind: 'phoneme', phoneme: { symbol: data.viseme, duration: HOLD_MS }, faps: [] }, data.frame * FRAME_MS * 1e6);
    }
  };
  const face = { node, animator, delayMs, output: out, onFrame: null };
  const ctx = canvas.getContext('2d');
  const frames = new AnimationFrames();
  const frame = (now) => {
    // The stream's time heard while this frame shows: the context's time at the output less the
    // delay, from the first audio.
    const { contextTime, performanceTime } = context.getOutputTimestamp();
    const shown = frames.drawTime(now);
    const heard = performanceTime > 0 ? contextTime + (shown - performanceTime) / 1000 : context.currentTime;
    const ms = Math.max(0, startTime === null ? 0 : (heard - startTime) * 1000 - delayMs);
    renderFace(ctx, animator.pose(ms * 1e6), { overlay: animator.describe(ms * 1e6) });
    face.onFrame?.(now, ms);
    requestAnimationFrame(frame);
  };
  frame(performance.now());
  return face;
}
