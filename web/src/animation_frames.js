// SPDX-License-Identifier: LGPL-2.1-or-later
// The moment an animation frame shows (docs/web.md, "The moment a frame shows").

/** The display's frame interval is the median of this many of the last intervals between frames. */
const KEPT_INTERVALS = 31;
/** The display's frame interval until two frames have come: 60 Hz. */
const FIRST_INTERVAL_MS = 1000 / 60;

/**
 * Which moment each animation frame should draw. A frame drawn at `requestAnimationFrame` time
 * t stays until the next one, a display frame later. Drawn as the face is at t, a change shows
 * 0 to one frame late (+8 ms on average at 60 Hz); drawn as it is at the middle of its time on
 * show, t plus half the display's frame interval, a change shows within half a frame either
 * side. The interval is the median of the last frames' intervals, so that frames missed under
 * load do not move it.
 */
export class AnimationFrames {
  constructor() {
    /** @type {number | null} */
    this.last = null;
    this.intervals = new Float64Array(KEPT_INTERVALS);
    this.sorted = new Float64Array(KEPT_INTERVALS);  // kept: each frame sorts a view of it
    this.count = 0;
  }

  /**
   * The moment (ms, in `now`'s clock) that the frame drawn at `now` should show.
   * @param {number} now the frame's `requestAnimationFrame` time
   * @returns {number}
   */
  drawTime(now) {
    if (this.last !== null && now > this.last) {
      this.intervals[this.count % KEPT_INTERVALS] = now - this.last;
      ++this.count;
    }
    this.last = now;
    return now + this.intervalMs() / 2;
  }

  /**
   * The display's frame interval (ms): the median of the last intervals between frames.
   * @returns {number}
   */
  intervalMs() {
    const n = Math.min(this.count, KEPT_INTERVALS);
    if (n === 0) return FIRST_INTERVAL_MS;
    const sorted = this.sorted.subarray(0, n);
    sorted.set(this.intervals.subarray(0, n));
    sorted.sort();
    return sorted[n >> 1];
  }
}
