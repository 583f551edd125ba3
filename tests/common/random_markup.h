// SPDX-License-Identifier: LGPL-2.1-or-later
// Seeded random PFAP markup for round-trip and property tests.
#pragma once

#include <cstdint>
#include <random>

#include "pfap/model.h"

namespace pfap::testing {

class RandomMarkup {
 public:
  explicit RandomMarkup(uint32_t seed) : rng_(seed) {}

  int uniform(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  bool chance(double p) { return std::bernoulli_distribution(p)(rng_); }

  // Any valid FAP, the extremes of every field included.
  Fap fap() {
    Fap f;
    f.index = static_cast<uint8_t>(uniform(kMinFapIndex, kMaxFapIndex));
    f.amplitude = chance(0.1) ? (chance(0.5) ? kMaxAmplitude : -kMaxAmplitude)
                              : uniform(-kMaxAmplitude, kMaxAmplitude);
    f.transition_ms =
        static_cast<uint16_t>(chance(0.1) ? kMaxTransitionMs : uniform(0, kMaxTransitionMs));
    f.curve = static_cast<Curve>(uniform(1, 3));
    return f;
  }

  // Any valid phoneme; end of text is left to the caller.
  Phoneme phoneme() {
    Phoneme p;
    p.symbol = static_cast<uint8_t>(uniform(0, 255));
    p.duration_ms = static_cast<uint16_t>(chance(0.05) ? kMaxPhonemeDurationMs : uniform(0, 400));
    p.f0 = static_cast<uint8_t>(uniform(0, 255));
    p.stress = chance(0.3);
    p.word_begin = chance(0.3);
    return p;
  }

 private:
  std::mt19937 rng_;
};

}  // namespace pfap::testing
