// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap/fap_state.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <functional>

namespace pfap {

[[gnu::always_inline]] inline FapState::Track FapState::transition(const Fap& fap, int64_t start_ns,
                                                                   int32_t from, int32_t held) {
  // A triangle is an excursion: the FAP keeps holding what it held before.
  return Track{.from = from,
               .target = fap.amplitude,
               .settled = fap.curve == Curve::kTriangle ? held : fap.amplitude,
               .start_ns = start_ns,
               .duration_ns = int64_t{fap.transition_ms} * kNsPerMs,
               .curve = fap.curve};
}

[[gnu::always_inline]] inline void FapState::start_transition(const Fap& fap, int64_t start_ns) {
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
  tracks_[fap.index] = transition(fap, start_ns, from, track.settled);
}

void FapState::apply(const Fap& fap, int64_t start_ns) {
  assert(is_valid(fap));
  start_transition(fap, start_ns);
}

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

bool FapState::apply_complete(std::span<const Fap> entries, int64_t time_ns) {
  // The entries come from decode_payload or read_markup, which check every field.
  const auto ascending = [](const Fap& a, const Fap& b) { return a.index < b.index; };
  if (std::adjacent_find(entries.begin(), entries.end(), std::not_fn(ascending)) != entries.end()) {
    return apply_complete_any_order(entries, time_ns);
  }
  // Each FAP once, in index order, as RecoverySender lists them: one pass over the FAPs
  // resets those left out and starts those listed from a reset track, comparing each
  // settled value as it is replaced.
  bool changed = false;
  int next = kMinFapIndex;  // the FAPs below it are done
  const auto reset_up_to = [&](int end) {
    for (; next < end; ++next) {
      changed |= tracks_[next].settled != 0;
      tracks_[next] = Track{};
    }
  };
  for (const Fap& entry : entries) {
    reset_up_to(entry.index);
    // A reset track holds 0 at rest (or, before its start, has 0 to come from).
    Track& track = tracks_[entry.index];
    const int32_t before = track.settled;
    track = transition(entry, time_ns, 0, 0);
    changed |= track.settled != before;
    next = entry.index + 1;
  }
  reset_up_to(kMaxFapIndex + 1);
  return changed;
}

bool FapState::apply_complete_any_order(std::span<const Fap> entries, int64_t time_ns) {
  // Only the settled values are compared, so only they are kept, not the whole state.
  std::array<int32_t, kFapCount> before;
  for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) before[f] = tracks_[f].settled;
  reset();
  for (const Fap& entry : entries) start_transition(entry, time_ns);
  for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) {
    if (tracks_[f].settled != before[f]) return true;
  }
  return false;
}

}  // namespace pfap
