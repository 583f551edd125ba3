// SPDX-License-Identifier: LGPL-2.1-or-later
// pfapalign's sample times without GStreamer: align/ counts samples from the first sample a
// stream kept; the element's buffers and texts carry times in ns. These turn one into the
// other, with GStreamer's rounding (gst_util_uint64_scale down, _round to the nearest).
#pragma once

#include <cstddef>
#include <cstdint>

#include "speech.h"

namespace pfap::align {

// The time in ns of sample `sample` at `rate` Hz, counted from `first` (ns): rounded down.
uint64_t sample_time(uint64_t first, uint64_t sample, unsigned rate);

// The sample a time `position` (ns) falls on, counted from `first`: rounded to the nearest,
// halves up; 0 at or before `first`.
uint64_t sample_at(uint64_t first, uint64_t position, unsigned rate);

// A phoneme's PTS and duration in ns.
struct PhonemeTime {
  uint64_t pts = 0;
  uint64_t duration = 0;
};

// The time of `phoneme`, whose start counts from sample `from` of the audio from `first`: from
// its first sample's time to its end's, so that phonemes that tile the samples tile the time.
PhonemeTime phoneme_time(const tts::SpokenPhoneme& phoneme, uint64_t from, uint64_t first,
                         unsigned rate);

}  // namespace pfap::align
