// SPDX-License-Identifier: LGPL-2.1-or-later
// What the align/ and pfapalign tests share: texts spoken by espeak-ng with known phoneme
// times, the check that phonemes tile the audio they were given, and resampling.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "speech.h"

namespace pfap::align::testing {

// `text` parsed as pfaptts parses it; a test text has no bad bookmark.
inline tts::Utterance utterance(const std::string& text) {
  std::vector<tts::BadBookmark> bad;
  tts::Utterance u = tts::parse_utterance(text, bad);
  EXPECT_TRUE(bad.empty());
  return u;
}

// `text` spoken by espeak-ng with `voice`: the samples and each phoneme's time.
inline tts::Speech say(const std::string& text, const tts::VoiceSettings& voice) {
  tts::Speech s;
  std::string error;
  EXPECT_TRUE(tts::speak(utterance(text), voice, s, error)) << error;
  return s;
}

// `in` at rate `from` resampled to `to` by linear interpolation: enough for speech whose
// energy is well under 8 kHz.
inline std::vector<int16_t> resample(const std::vector<int16_t>& in, unsigned from,
                                     unsigned to) {
  std::vector<int16_t> out(in.size() * to / from);
  for (size_t i = 0; i < out.size(); ++i) {
    const double x = static_cast<double>(i) * from / to;
    const size_t k = static_cast<size_t>(x);
    const double t = x - static_cast<double>(k);
    const double b = k + 1 < in.size() ? in[k + 1] : in[k];
    out[i] = static_cast<int16_t>(std::lround(in[k] * (1 - t) + b * t));
  }
  return out;
}

// The phonemes tile the audio (contiguous from 0 to its end) and their durations add up to
// its length on the ms grid.
inline void expect_tiles(const std::vector<tts::SpokenPhoneme>& phonemes, size_t n_samples,
                         unsigned rate) {
  ASSERT_FALSE(phonemes.empty());
  size_t next = 0;
  uint64_t ms = 0;
  for (const tts::SpokenPhoneme& p : phonemes) {
    EXPECT_EQ(p.start, next);
    next = p.start + p.n_samples;
    ms += p.event.phoneme.duration_ms;
  }
  EXPECT_EQ(next, n_samples);
  EXPECT_EQ(ms, (static_cast<uint64_t>(n_samples) * 1000 + rate / 2) / rate);
}

}  // namespace pfap::align::testing
