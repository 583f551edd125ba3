// SPDX-License-Identifier: LGPL-2.1-or-later
#include "dtw.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

namespace pfap::align {
namespace {

// Finite for any input, so that every cell of the band has a finite cost and a step.
float distance(std::span<const float> x, std::span<const float> y) {
  float s = 0;
  for (size_t d = 0; d < x.size(); ++d) s += (x[d] - y[d]) * (x[d] - y[d]);
  const float r = std::sqrt(s);
  return std::isfinite(r) ? r : 1e6f;
}

}  // namespace

float from_silence(std::span<const float> x) {
  float sum = 0;
  for (size_t k = 0; k < Features::kMfccs; ++k) sum += x[k] * x[k];
  const float level = x[Features::kMfccs] + kLevelWeight;
  const float r = std::sqrt(sum + level * level);
  return std::isfinite(r) ? r : 1e6f;  // as distance()
}

namespace {

enum Step : uint8_t { kDiagonal, kUp, kLeft };  // from (i-1, j-1), (i-1, j), (i, j-1)

// The first and last frame of `f` within kLoudRangeDb of its loudest (the level dimension):
// where its speech begins and ends. The whole when none is.
constexpr float kLoudRangeDb = 30;
std::pair<size_t, size_t> loud_span(const Features& f) {
  constexpr float kLoud = -kLoudRangeDb / kLevelRangeDb * kLevelWeight;
  auto loud = [&](size_t k) { return f.data[k * Features::kDims + Features::kMfccs] >= kLoud; };
  size_t first = 0, last = f.n_frames - 1;
  while (first < last && !loud(first)) ++first;
  while (last > first && !loud(last)) --last;
  return first < last ? std::pair{first, last} : std::pair{size_t{0}, f.n_frames - 1};
}

}  // namespace

Warp warp(const Features& a, const Features& b, size_t max_cells, const std::vector<bool>* rest) {
  const size_t n = a.n_frames, m = b.n_frames;
  // Row i covers columns [lo[i], hi[i]) about the line through the loud spans' ends (the
  // diagonal when both are loud throughout): silence before or after the speech, seconds of it
  // in a recording and none in the synthesis, does not take the speech out of the band.
  const auto [a0, a1] = loud_span(a);
  const auto [b0, b1] = loud_span(b);
  const double slope = a1 > a0 ? static_cast<double>(b1 - b0) / static_cast<double>(a1 - a0)
                               : static_cast<double>(m) / static_cast<double>(n);
  size_t radius = std::max(n, m) / 2 + 1;
  if (n * (2 * radius + 1) > max_cells) radius = std::max<size_t>(max_cells / n / 2, 1);
  // Neighbouring rows' bands must touch.
  radius = std::max({radius, (m + n - 1) / n, static_cast<size_t>(std::ceil(slope))});
  std::vector<size_t> lo(n), hi(n);
  for (size_t i = 0; i < n; ++i) {
    const double line =
        static_cast<double>(b0) + (static_cast<double>(i) - static_cast<double>(a0)) * slope;
    const auto c = static_cast<size_t>(std::clamp(line, 0.0, static_cast<double>(m - 1)));
    lo[i] = c > radius ? c - radius : 0;
    hi[i] = std::min(m, c + radius + 1);
  }
  lo[0] = 0;
  hi[n - 1] = m;

  // Each frame of `b`'s cost where `a` may hold a pause.
  const bool pauses = rest != nullptr && rest->size() == n;
  std::vector<float> silence(pauses ? m : 0);
  for (size_t j = 0; j < silence.size(); ++j) silence[j] = from_silence(b.frame(j));

  constexpr float kInf = std::numeric_limits<float>::infinity();
  std::vector<std::vector<uint8_t>> steps(n);
  std::vector<float> prev(m, kInf), cur(m, kInf);
  for (size_t i = 0; i < n; ++i) {
    steps[i].resize(hi[i] - lo[i]);
    std::fill(cur.begin(), cur.end(), kInf);
    for (size_t j = lo[i]; j < hi[i]; ++j) {
      const float d = distance(a.frame(i), b.frame(j));
      float best = kInf;
      Step step = kDiagonal;
      if (i == 0 && j == 0) {
        best = 0;
      } else {
        if (i > 0 && j > 0 && prev[j - 1] < best) best = prev[j - 1], step = kDiagonal;
        if (i > 0 && prev[j] < best) best = prev[j], step = kUp;
        if (j > 0 && cur[j - 1] < best) best = cur[j - 1], step = kLeft;
      }
      cur[j] = best + d;
      if (pauses && (*rest)[i] && j > lo[i] && cur[j - 1] + silence[j] < cur[j]) {
        cur[j] = cur[j - 1] + silence[j];
        steps[i][j - lo[i]] = kLeft;
      }
      steps[i][j - lo[i]] = step;
    }
    std::swap(prev, cur);
  }

  Warp w;
  w.first.assign(n, 0);
  w.last.assign(n, 0);
  double path_cost = 0;
  size_t path_length = 0;
  size_t i = n - 1, j = m - 1;
  w.last[i] = j;
  for (;;) {
    w.first[i] = j;
    ++path_length;
    if (i == 0 && j == 0) {
      path_cost += distance(a.frame(i), b.frame(j));
      break;
    }
    // Along the first row or column only one step leads back to (0, 0), whatever was stored.
    const Step step = i == 0                    ? kLeft
                      : j == 0                  ? kUp
                      : j >= lo[i] && j < hi[i] ? static_cast<Step>(steps[i][j - lo[i]])
                                                : kUp;
    // What the search counted: a pause held on a `rest` frame at its distance from silence.
    const float d = distance(a.frame(i), b.frame(j));
    path_cost += pauses && (*rest)[i] && step == kLeft ? std::min(d, silence[j]) : d;
    if (step == kLeft) {
      --j;
    } else {
      if (step == kDiagonal) --j;
      --i;
      w.last[i] = j;
    }
  }

  // What the path saves over a linear warp (one sequence stretched evenly onto the other),
  // along the same number of steps: the same words gain much, unrelated sounds little.
  double linear_cost = 0;
  for (size_t k = 0; k < path_length; ++k) {
    const size_t pi = path_length > 1 ? k * (n - 1) / (path_length - 1) : 0;
    const size_t pj = path_length > 1 ? k * (m - 1) / (path_length - 1) : 0;
    linear_cost += distance(a.frame(pi), b.frame(pj));
  }
  w.relative_cost = linear_cost > 0 ? path_cost / linear_cost : 0;
  return w;
}

}  // namespace pfap::align
