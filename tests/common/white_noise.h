// SPDX-License-Identifier: LGPL-2.1-or-later
// White noise for tests of bad input: the same samples on every run (a seeded linear
// congruential generator), so that a test repeats exactly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pfap::testing {

// `n` samples uniform in [-amplitude, amplitude): 8000 is about -15 dBFS, loud noise; 32 about
// -65 dBFS, the hiss of a quiet room.
inline std::vector<int16_t> white_noise(size_t n, int amplitude = 8000, uint32_t seed = 1) {
  std::vector<int16_t> noise(n);
  for (int16_t& v : noise) {
    seed = seed * 1664525 + 1013904223;
    v = static_cast<int16_t>(static_cast<int>((seed >> 16) % (2 * amplitude)) - amplitude);
  }
  return noise;
}

}  // namespace pfap::testing
