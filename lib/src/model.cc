// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap/model.h"

#include <algorithm>

namespace pfap {

double expression_weight(double amplitude) {
  return std::clamp(amplitude / kMaxExpressionIntensity, 0.0, 1.0);
}

uint8_t f0_code(unsigned hz) { return static_cast<uint8_t>((std::min(hz, kMaxF0Hz) + 1) / 2); }

void split_long_phoneme(const Phoneme& phoneme, uint32_t duration_ms, std::vector<Phoneme>& out) {
  Phoneme piece = phoneme;
  piece.end_of_text = false;
  while (duration_ms > kMaxPhonemeDurationMs) {
    piece.duration_ms = kMaxPhonemeDurationMs;
    out.push_back(piece);
    duration_ms -= kMaxPhonemeDurationMs;
    piece.stress = false;
    piece.word_begin = false;
  }
  piece.duration_ms = static_cast<uint16_t>(duration_ms);
  piece.end_of_text = phoneme.end_of_text;
  out.push_back(piece);
}

}  // namespace pfap
