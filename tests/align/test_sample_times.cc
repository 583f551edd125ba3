// SPDX-License-Identifier: LGPL-2.1-or-later
// pfapalign's sample times: samples to ns and back, with GStreamer's rounding, checked against
// the exact 128-bit products.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "sample_times.h"

namespace {

__extension__ typedef unsigned __int128 Wide;

constexpr uint64_t kSecond = 1'000'000'000;
constexpr uint64_t kFirst = 3'000'000'017;

uint64_t exact_time(uint64_t first, uint64_t sample, unsigned rate) {
  return first + static_cast<uint64_t>(Wide{sample} * kSecond / rate);
}

uint64_t exact_sample(uint64_t first, uint64_t position, unsigned rate) {
  if (position <= first) return 0;
  return static_cast<uint64_t>((Wide{position - first} * rate + kSecond / 2) / kSecond);
}

TEST(SampleTimes, SampleTimesRoundDown) {
  struct Case {
    uint64_t sample;
    unsigned rate;
    uint64_t time;  // from kFirst
  };
  const std::vector<Case> cases = {
      {0, 16000, 0},           {1, 16000, 62'500}, {1, 22050, 45'351},
      {22050, 22050, kSecond}, {3, 44100, 68'027}, {48001, 48000, kSecond + 20'833},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(pfap::align::sample_time(kFirst, c.sample, c.rate), kFirst + c.time)
        << c.sample << " at " << c.rate;
  }
}

TEST(SampleTimes, SamplesAtATimeRoundToTheNearestHalvesUp) {
  EXPECT_EQ(pfap::align::sample_at(kFirst, 0, 16000), 0u);       // before the first sample
  EXPECT_EQ(pfap::align::sample_at(kFirst, kFirst, 16000), 0u);  // at it
  EXPECT_EQ(pfap::align::sample_at(kFirst, kFirst + 31'249, 16000), 0u);
  EXPECT_EQ(pfap::align::sample_at(kFirst, kFirst + 31'250, 16000), 1u);  // half a sample
  EXPECT_EQ(pfap::align::sample_at(kFirst, kFirst + 2 * kSecond + 62'500, 16000), 32001u);
}

// Over a day of audio at each rate, where a 64-bit product of ns and rate would overflow.
TEST(SampleTimes, AgreesWithTheExactProductsAtEveryRateAndLength) {
  for (const unsigned rate : {1u, 8000u, 11025u, 16000u, 22050u, 44100u, 48000u}) {
    for (uint64_t sample = 0; sample < 200'000'000'000ull; sample = sample * 3 + 7) {
      ASSERT_EQ(pfap::align::sample_time(kFirst, sample, rate), exact_time(kFirst, sample, rate))
          << sample << " at " << rate;
    }
    for (uint64_t t = 0; t < 400'000 * kSecond; t = t * 3 + 499'999'999) {
      ASSERT_EQ(pfap::align::sample_at(kFirst, kFirst + t, rate),
                exact_sample(kFirst, kFirst + t, rate))
          << t << " ns at " << rate;
    }
  }
}

// Phonemes that tile the samples tile the time: each PTS is the last one's end.
TEST(SampleTimes, PhonemesThatTileTheSamplesTileTheTime) {
  const unsigned rate = 22050;
  const uint64_t from = 12345;
  uint64_t end = pfap::align::sample_time(kFirst, from, rate);
  size_t start = 0;
  for (const size_t n : {1u, 7u, 441u, 2205u, 3u}) {
    pfap::tts::SpokenPhoneme p;
    p.start = start;
    p.n_samples = n;
    const pfap::align::PhonemeTime time = pfap::align::phoneme_time(p, from, kFirst, rate);
    EXPECT_EQ(time.pts, end);
    EXPECT_EQ(time.pts + time.duration, pfap::align::sample_time(kFirst, from + start + n, rate));
    end = time.pts + time.duration;
    start += n;
  }
}

}  // namespace
