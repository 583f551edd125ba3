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

// The distance of frame `x` from silence: MFCCs 0 (their mean), the level at its lowest.
float from_silence(std::span<const float> x);

// The path of least summed Euclidean distance from (0, 0) to (a.n_frames - 1,
// b.n_frames - 1) with steps (1, 0), (0, 1) and (1, 1), searched within a band about the
// diagonal wide enough for one sequence to run twice as fast as the other in places; the band
// narrows for long inputs so that the search stays within max_cells cells (memory: one byte
// each). Where `rest` (one flag per frame of `a`; ignored if not as many) is true, the path
// may stay on that frame of `a` over frames of `b` at their distance from silence instead: a
// pause in `b` that `a` lacks (at the ends of `a`'s words: pause_frames() in boundaries.h).
inline constexpr size_t kMaxWarpCells = size_t{64} << 20;
Warp warp(const Features& a, const Features& b, size_t max_cells = kMaxWarpCells,
          const std::vector<bool>* rest = nullptr);

}  // namespace pfap::align
