// SPDX-License-Identifier: LGPL-2.1-or-later
// A seeded session as a TTS engine gives it, for recovery tests and benchmarks: sentences of
// 6..14 contiguous phonemes of 40..100 ms with pauses of 100..300 ms between them (about 11
// phonemes per second of stream time). Before a phoneme, with probability `fap_chance`, 1..3
// FAPs of every kind: linear, triangle and spline curves, transitions of 0..1500 ms,
// amplitudes of both signs, on the indexes 3..12 and the expressions 69..74 only, so that
// later FAPs start from where earlier ones left their FAP.
//
// Each phoneme carries its number in symbol (low 8 bits) and f0 (high 8 bits), so a receiver
// can tell which phoneme it got whatever was lost. lossless_states() is what a receiver that
// lost none of it holds after each phoneme.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "pfap/fap_state.h"
#include "pfap/model.h"
#include "random_markup.h"

namespace pfap::testing {

struct SpeechPhoneme {
  Phoneme phoneme;  // end_of_text on the last phoneme of each sentence
  bool sentence_start = false;
  std::vector<Fap> faps;
  int64_t start_ns = 0;
};

inline int number_of(const Phoneme& p) { return p.symbol + 256 * p.f0; }

inline std::vector<SpeechPhoneme> speech_session(uint32_t seed, int n_phonemes, double fap_chance,
                                                 int64_t start_ns = 0) {
  RandomMarkup random(seed);
  std::vector<SpeechPhoneme> out;
  int64_t t = start_ns;
  bool sentence_start = true;
  int in_sentence = 0;
  int sentence_length = random.uniform(6, 14);
  for (int i = 0; i < n_phonemes; ++i) {
    SpeechPhoneme p;
    p.phoneme.symbol = static_cast<uint8_t>(i & 0xff);
    p.phoneme.f0 = static_cast<uint8_t>(i >> 8);
    p.phoneme.duration_ms = static_cast<uint16_t>(random.uniform(40, 100));
    p.phoneme.stress = random.chance(0.3);
    p.phoneme.word_begin = random.chance(0.3);
    p.phoneme.end_of_text = ++in_sentence >= sentence_length || i + 1 == n_phonemes;
    if (random.chance(fap_chance)) {
      for (int k = random.uniform(1, 3); k > 0; --k) {
        Fap f;
        f.index = static_cast<uint8_t>(random.chance(0.25) ? random.uniform(69, 74)
                                                           : random.uniform(3, 12));
        f.amplitude = random.uniform(-2000, 2000);
        f.transition_ms = static_cast<uint16_t>(random.chance(0.2) ? 0 : random.uniform(1, 1500));
        f.curve = static_cast<Curve>(random.uniform(1, 3));
        p.faps.push_back(f);
      }
    }
    p.sentence_start = sentence_start;
    p.start_ns = t;
    out.push_back(p);
    t += p.phoneme.duration_ms * kNsPerMs;
    sentence_start = p.phoneme.end_of_text;
    if (sentence_start) {
      in_sentence = 0;
      sentence_length = random.uniform(6, 14);
      t += int64_t{random.uniform(100, 300)} * kNsPerMs;
    }
  }
  return out;
}

// A FAP state's settled values by FAP index: what receivers are compared by, as they depend
// only on the order of bookmarks, not on their times.
using Settled = std::array<int32_t, kFapCount>;

inline Settled settled_of(const FapState& state) {
  Settled s{};
  for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) s[f] = state.settled(f);
  return s;
}

// What a receiver that lost nothing holds after each phoneme: the sender's FAPs applied in
// order.
inline std::vector<Settled> lossless_states(const std::vector<SpeechPhoneme>& session) {
  FapState state;
  std::vector<Settled> out;
  for (const SpeechPhoneme& p : session) {
    for (const Fap& f : p.faps) state.apply(f, p.start_ns);
    out.push_back(settled_of(state));
  }
  return out;
}

}  // namespace pfap::testing
