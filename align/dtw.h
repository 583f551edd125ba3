// SPDX-License-Identifier: LGPL-2.1-or-later
// Dynamic time warping of two feature sequences: which frames of one match which of the other.
#pragma once

#include <cstddef>
#include <vector>

#include "mfcc.h"

namespace pfap::align {

struct Warp {
  // For each frame i of `a`, the first and last frame of `b` the path matches it with
  // (first[i] <= last[i] <= first[i + 1]).
  std::vector<size_t> first;
  std::vector<size_t> last;
  // The summed distance between matched frames along the path over that along a linear warp
  // of as many steps: well under 1 for the same words, near 1 for unrelated sounds. What
  // tells a text that does not match its audio.
  double relative_cost = 0;
};

// The path of least summed Euclidean distance from (0, 0) to (a.n_frames - 1,
// b.n_frames - 1) with steps (1, 0), (0, 1) and (1, 1), searched within a band about the
// diagonal wide enough for one sequence to run twice as fast as the other in places; the band
// narrows for long inputs so that the search stays within max_cells cells (memory: one byte
// each).
Warp warp(const Features& a, const Features& b, size_t max_cells = size_t{64} << 20);

}  // namespace pfap::align
