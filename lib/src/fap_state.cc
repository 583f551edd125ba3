#include "pfap/fap_state.h"

#include <cassert>
#include <cmath>

namespace pfap {
namespace {

// How far along the way from the start amplitude to the target the curve is at progress
// u in [0, 1]: 0 is the start amplitude, 1 the target.
double curve_share(Curve curve, double u) {
  switch (curve) {
    case Curve::kTriangle:
      return 1.0 - std::abs(2.0 * u - 1.0);
    case Curve::kSpline:
      return u * u * (3.0 - 2.0 * u);
    case Curve::kLinear:
      break;
  }
  return u;
}

}  // namespace

void FapState::apply(const Fap& fap, int64_t start_ns) {
  assert(is_valid(fap));
  // Whatever the track has reached at `start` covers all three starting amplitudes of the
  // draft: 0 before any bookmark, the settled value after one, the curve's value during one.
  const auto from = static_cast<int32_t>(std::lround(amplitude(fap.index, start_ns)));
  tracks_[fap.index] = Track{.from = from,
                             .target = fap.amplitude,
                             .start_ns = start_ns,
                             .duration_ns = int64_t{fap.transition_ms} * kNsPerMs,
                             .curve = fap.curve};
}

double FapState::amplitude(int index, int64_t time_ns) const {
  assert(index >= kMinFapIndex && index <= kMaxFapIndex);
  const Track& track = tracks_[index];
  if (time_ns < track.start_ns) return track.from;
  const int64_t elapsed_ns = time_ns - track.start_ns;
  // Comparing first keeps T = 0 (a jump) away from a division by zero.
  const double u = elapsed_ns >= track.duration_ns
                       ? 1.0
                       : static_cast<double>(elapsed_ns) / static_cast<double>(track.duration_ns);
  const double way = static_cast<double>(track.target) - track.from;
  return track.from + way * curve_share(track.curve, u);
}

int32_t FapState::settled(int index) const {
  assert(index >= kMinFapIndex && index <= kMaxFapIndex);
  const Track& track = tracks_[index];
  return track.curve == Curve::kTriangle ? track.from : track.target;
}

void FapState::reset() { tracks_.fill(Track{}); }

}  // namespace pfap
