// SPDX-License-Identifier: LGPL-2.1-or-later
#include "viseme_frames.h"

#include <algorithm>
#include <cmath>

namespace pfap::align {

std::vector<Viseme> viseme_frames(std::span<const TimedSymbol> phonemes, double seconds) {
  static const PhonemeAlphabet& arpabet = *find_alphabet(kArpabetAlphabet);
  const auto n = static_cast<size_t>(std::max(0.0, std::floor(seconds / kVisemeFrameSeconds)));
  std::vector<Viseme> out(n, Viseme::kNone);
  size_t k = 0;
  for (size_t f = 0; f < n; ++f) {
    const double middle = (static_cast<double>(f) + 0.5) * kVisemeFrameSeconds;
    while (k < phonemes.size() && phonemes[k].start <= middle) ++k;
    if (k == 0) continue;
    const PhonemeInfo* info = find_phoneme(arpabet, phonemes[k - 1].symbol);
    out[f] = info != nullptr ? info->viseme : Viseme::kNone;
  }
  return out;
}

double viseme_agreement(std::span<const Viseme> a, std::span<const Viseme> b) {
  const size_t n = std::min(a.size(), b.size());
  if (n == 0) return 0;
  size_t same = 0;
  for (size_t f = 0; f < n; ++f) same += a[f] == b[f] ? 1 : 0;
  return static_cast<double>(same) / static_cast<double>(n);
}

}  // namespace pfap::align
