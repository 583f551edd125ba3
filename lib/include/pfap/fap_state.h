// SPDX-License-Identifier: LGPL-2.1-or-later
// The amplitude of every FAP over time at a receiver (draft section 5).
//
// A bookmark's FAP starts from the amplitude actually reached at its start time (0 before
// any bookmark, the previous settled value once its transition is over, the value on the
// curve while it runs), rounded to a whole FAP unit, and moves to its target over T:
//   C=1 linear:   v(t) = s + (a - s) * u                 u = (t - start) / T in [0, 1]
//   C=2 triangle: v(t) = s + (a - s) * 2u                 for u < 1/2, then
//                 v(t) = a + (p - a) * (2u - 1)           back to p, what the FAP held before
//   C=3 spline:   v(t) = s + (a - s) * u^2 * (3 - 2u)     cubic Hermite, zero slope at ends
// The settled value is a for C=1 and C=3, p for C=2: a triangle is an excursion that leaves
// what the FAP holds unchanged, so settled values depend only on the order of bookmarks,
// never on their timing. T = 0 jumps at once (a triangle with T = 0 leaves no trace).
// docs/format.md has the reasons.
#pragma once

#include <array>
#include <cassert>
#include <cstdint>
#include <span>

#include "pfap/model.h"

namespace pfap {

class FapState {
 public:
  // Starts the transition of `fap` at `start_ns`. Bookmarks for one FAP must come in
  // non-decreasing start order.
  void apply(const Fap& fap, int64_t start_ns);
  // The amplitude of FAP `index` at `time_ns`, for times at or after the start of the last
  // bookmark applied to it (earlier times give that bookmark's starting amplitude).
  double amplitude(int index, int64_t time_ns) const;
  // What FAP `index` holds once its transition is over (a triangle's p).
  int32_t settled(int index) const {
    assert(index >= kMinFapIndex && index <= kMaxFapIndex);
    return tracks_[index].settled;
  }
  // Whether FAP `index` has no transition running at `time_ns`.
  bool at_rest(int index, int64_t time_ns) const {
    assert(index >= kMinFapIndex && index <= kMaxFapIndex);
    const Track& track = tracks_[index];
    return time_ns - track.start_ns >= track.duration_ns;
  }
  // The recovery entry that brings a receiver to this FAP's settled value from `time_ns` on:
  // the target and the time left (rounded up) of a linear or spline transition still
  // running, else the settled value at once. A running triangle's excursion is left out:
  // recovery restores state, and the triangle's state is the value it returns to.
  // Inline, with the accessors above: a complete state takes one entry per FAP.
  Fap recovery_entry(int index, int64_t time_ns) const {
    const Track& track = tracks_[index];
    const auto fap_index = static_cast<uint8_t>(index);
    if (at_rest(index, time_ns) || track.curve == Curve::kTriangle) {
      return {fap_index, track.settled, 0, Curve::kLinear};
    }
    // Before the start the whole transition is still to come.
    const int64_t left_ns =
        track.start_ns + track.duration_ns - (time_ns > track.start_ns ? time_ns : track.start_ns);
    const auto left_ms = static_cast<uint16_t>((left_ns + kNsPerMs - 1) / kNsPerMs);
    return {fap_index, track.target, left_ms, track.curve};
  }
  // Every FAP back to 0 with no transition running, as after construction.
  void reset();
  // Takes a complete state (C=1) at `time_ns`: every FAP not among `entries` is 0, so the
  // state is reset, then each entry applied. Returns whether any settled value changed.
  bool apply_complete(std::span<const Fap> entries, int64_t time_ns);

 private:
  struct Track {
    int32_t from = 0;  // amplitude when the transition started
    int32_t target = 0;
    int32_t settled = 0;  // held once the transition is over: the target, or for a
                          // triangle what the FAP held before it
    int64_t start_ns = 0;
    int64_t duration_ns = 0;
    Curve curve = Curve::kLinear;
  };
  // The track of `fap` started at `start_ns` from amplitude `from`, where the FAP held `held`.
  static Track transition(const Fap& fap, int64_t start_ns, int32_t from, int32_t held);
  // apply() without its check: apply_complete's entries come checked by their decoder.
  void start_transition(const Fap& fap, int64_t start_ns);
  // apply_complete() for entries out of index order or with a FAP twice (the draft forbids
  // neither): reset, then each entry in turn.
  bool apply_complete_any_order(std::span<const Fap> entries, int64_t time_ns);

  std::array<Track, kFapCount> tracks_{};
};

}  // namespace pfap
