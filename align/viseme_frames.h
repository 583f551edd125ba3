// SPDX-License-Identifier: LGPL-2.1-or-later
// Phonemes judged as a face shows them: the MPEG-4 viseme of each 10 ms frame, and the share
// of frames on which two phoneme sequences show the same viseme (docs/align.md, "Without the
// text"). Confusions inside one viseme class (p b m, t d, ...) do not count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "pfap/phoneme_table.h"

namespace pfap::align {

inline constexpr double kVisemeFrameSeconds = 0.010;

// A phoneme by its start in seconds and its x-pfap-arpabet symbol.
struct TimedSymbol {
  double start;
  uint8_t symbol;
};

// The viseme shown at the middle of each 10 ms frame of `seconds`: that of the last phoneme
// of `phonemes` (in order of start) that starts at or before it; a pause before the first.
std::vector<Viseme> viseme_frames(std::span<const TimedSymbol> phonemes, double seconds);

// The share of frames, 0..1, where `a` and `b` show the same viseme (over the shorter); 0
// when either is empty.
double viseme_agreement(std::span<const Viseme> a, std::span<const Viseme> b);

}  // namespace pfap::align
