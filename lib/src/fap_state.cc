// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap/fap_state.h"

#include <cassert>
#include <cmath>

namespace pfap {

[[gnu::always_inline]] inline void FapState::start_transition(const Fap& fap, int64_t start_ns) {
  assert(is_valid(fap));
  // Whatever the track has reached at `start` covers all three starting amplitudes of the
  // draft: 0 before any bookmark, the settled value after one, the curve's value during one.
  // Before its start and at rest a track holds a whole value (amplitude()'s first two cases),
  // so only a running transition needs the curve and rounding.
  const Track& track = tracks_[fap.index];
  int32_t from = track.from;
  if (start_ns >= track.start_ns) {
    from = start_ns - track.start_ns >= track.duration_ns
               ? track.settled
               : static_cast<int32_t>(std::lround(amplitude(fap.index, start_ns)));
  }
  // A triangle is an excursion: the FAP keeps holding what it held before.
  const int32_t settled = fap.curve == Curve::kTriangle ? track.settled : fap.amplitude;
  tracks_[fap.index] = Track{.from = from,
                             .target = fap.amplitude,
                             .settled = settled,
                             .start_ns = start_ns,
                             .duration_ns = int64_t{fap.transition_ms} * kNsPerMs,
                             .curve = fap.curve};
}

void FapState::apply(const Fap& fap, int64_t start_ns) { start_transition(fap, start_ns); }

double FapState::amplitude(int index, int64_t time_ns) const {
  assert(index >= kMinFapIndex && index <= kMaxFapIndex);
  const Track& track = tracks_[index];
  if (time_ns < track.start_ns) return track.from;
  const int64_t elapsed_ns = time_ns - track.start_ns;
  // Comparing first keeps T = 0 (a jump) away from a division by zero.
  if (elapsed_ns >= track.duration_ns) return track.settled;
  const double u = static_cast<double>(elapsed_ns) / static_cast<double>(track.duration_ns);
  const double from = track.from, target = track.target;
  switch (track.curve) {
    case Curve::kTriangle:
      // Up to the target over the first half, back to the held value over the second.
      return u < 0.5 ? from + (target - from) * 2.0 * u
                     : target + (track.settled - target) * (2.0 * u - 1.0);
    case Curve::kSpline:
      return from + (target - from) * u * u * (3.0 - 2.0 * u);
    case Curve::kLinear:
      break;
  }
  return from + (target - from) * u;
}

void FapState::reset() { tracks_.fill(Track{}); }

void FapState::apply_complete(std::span<const Fap> entries, int64_t time_ns) {
  reset();
  for (const Fap& entry : entries) start_transition(entry, time_ns);
}

}  // namespace pfap
