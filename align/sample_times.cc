// SPDX-License-Identifier: LGPL-2.1-or-later
#include "sample_times.h"

namespace pfap::align {

namespace {

constexpr uint64_t kSecond = 1'000'000'000;

}  // namespace

// Whole seconds apart, so that no product overflows: a remainder times kSecond or a rate fits.
uint64_t sample_time(uint64_t first, uint64_t sample, unsigned rate) {
  return first + sample / rate * kSecond + sample % rate * kSecond / rate;
}

uint64_t sample_at(uint64_t first, uint64_t position, unsigned rate) {
  if (position <= first) return 0;
  const uint64_t t = position - first;
  return t / kSecond * rate + (t % kSecond * rate + kSecond / 2) / kSecond;
}

PhonemeTime phoneme_time(const tts::SpokenPhoneme& phoneme, uint64_t from, uint64_t first,
                         unsigned rate) {
  const uint64_t start = sample_time(first, from + phoneme.start, rate);
  const uint64_t end = sample_time(first, from + phoneme.start + phoneme.n_samples, rate);
  return {start, end - start};
}

}  // namespace pfap::align
