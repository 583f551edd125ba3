// SPDX-License-Identifier: LGPL-2.1-or-later
// segment_f0 on signals of known pitch: a voice-like pulse train and silence.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <vector>

#include "f0.h"

namespace pfap::tts {
namespace {

constexpr unsigned kRate = 22050;

// `seconds` of a sum of the first 10 harmonics of `hz`, falling in amplitude like a voice.
void append_voice(std::vector<int16_t>& out, double hz, double seconds) {
  const size_t n = static_cast<size_t>(seconds * kRate);
  const size_t offset = out.size();
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(offset + i) / kRate;
    double v = 0;
    for (int h = 1; h <= 10; ++h) v += std::sin(2 * M_PI * hz * h * t) / h;
    out.push_back(static_cast<int16_t>(4000 * v));
  }
}

TEST(F0, KnownPitchesAndSilence) {
  std::vector<int16_t> samples;
  append_voice(samples, 110, 0.3);
  samples.resize(samples.size() + kRate / 5, 0);  // 200 ms of silence
  append_voice(samples, 220, 0.3);
  const size_t a = static_cast<size_t>(0.3 * kRate), b = a + kRate / 5;
  const std::vector<size_t> bounds = {0, a, b, samples.size()};
  const std::vector<double> f0 = segment_f0(samples, kRate, bounds);
  ASSERT_EQ(f0.size(), 3u);
  std::printf("measured: 110 Hz as %.2f, silence as %.2f, 220 Hz as %.2f\n", f0[0], f0[1], f0[2]);
  EXPECT_NEAR(f0[0], 110, 2);
  EXPECT_EQ(f0[1], 0);
  EXPECT_NEAR(f0[2], 220, 3);
}

TEST(F0, SegmentsShorterThanAHopMayHaveNoEstimate) {
  std::vector<int16_t> samples;
  append_voice(samples, 150, 0.2);
  const std::vector<size_t> bounds = {0, 2000, 2050, samples.size()};
  const std::vector<double> f0 = segment_f0(samples, kRate, bounds);
  ASSERT_EQ(f0.size(), 3u);
  EXPECT_NEAR(f0[2], 150, 2);
  EXPECT_TRUE(f0[1] == 0 || std::abs(f0[1] - 150) < 2);
}

}  // namespace
}  // namespace pfap::tts
