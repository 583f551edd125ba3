// SPDX-License-Identifier: LGPL-2.1-or-later
#include <gtest/gtest.h>

#include <vector>

#include "pfap/model.h"

namespace pfap {
namespace {

TEST(F0Code, RoundsToTheNearestTwoHzStepAndSaturates) {
  const struct {
    unsigned hz;
    uint8_t code;
  } cases[] = {{0, 0},     {1, 1},     {2, 1},     {3, 2},     {120, 60},     {121, 61},
               {508, 254}, {509, 255}, {510, 255}, {511, 255}, {100000, 255}, {~0u, 255}};
  for (const auto& c : cases) EXPECT_EQ(f0_code(c.hz), c.code) << c.hz;
}

TEST(ExpressionWeight, IntensityOver63ClampedTo0To1) {
  const struct {
    double amplitude, weight;
  } cases[] = {{0, 0},  {63, 1}, {31.5, 0.5},         {21, 1.0 / 3},
               {-1, 0}, {64, 1}, {-kMaxAmplitude, 0}, {kMaxAmplitude, 1}};
  for (const auto& c : cases)
    EXPECT_DOUBLE_EQ(expression_weight(c.amplitude), c.weight) << c.amplitude;
}

TEST(Validity, FapFieldsAtAndPastTheirLimits) {
  const Fap good{kMinFapIndex, kMaxAmplitude, kMaxTransitionMs, Curve::kSpline};
  EXPECT_TRUE(is_valid(good));
  Fap f = good;
  f.index = kMaxFapIndex;
  f.amplitude = -kMaxAmplitude;
  EXPECT_TRUE(is_valid(f));
  f = good, f.index = 2;
  EXPECT_FALSE(is_valid(f));
  f = good, f.index = 75;
  EXPECT_FALSE(is_valid(f));
  f = good, f.amplitude = kMaxAmplitude + 1;
  EXPECT_FALSE(is_valid(f));
  f = good, f.amplitude = -kMaxAmplitude - 1;
  EXPECT_FALSE(is_valid(f));
  f = good, f.transition_ms = kMaxTransitionMs + 1;
  EXPECT_FALSE(is_valid(f));
  f = good, f.curve = static_cast<Curve>(0);
  EXPECT_FALSE(is_valid(f));
}

TEST(Validity, PhonemeDurationLimit) {
  EXPECT_TRUE(is_valid(Phoneme{.duration_ms = kMaxPhonemeDurationMs}));
  EXPECT_FALSE(is_valid(Phoneme{.duration_ms = kMaxPhonemeDurationMs + 1}));
}

TEST(SplitLongPhoneme, ShortPhonemeComesBackUnchanged) {
  const Phoneme p{.symbol = 9,
                  .duration_ms = 0,
                  .f0 = 50,
                  .stress = true,
                  .word_begin = true,
                  .end_of_text = true};
  std::vector<Phoneme> out;
  split_long_phoneme(p, 4095, out);
  Phoneme expected = p;
  expected.duration_ms = 4095;
  EXPECT_EQ(out, std::vector<Phoneme>{expected});
}

TEST(SplitLongPhoneme, PiecesAddUpAndFlagsGoToTheRightEnds) {
  const Phoneme p{.symbol = 9, .f0 = 50, .stress = true, .word_begin = true, .end_of_text = true};
  std::vector<Phoneme> out;
  split_long_phoneme(p, 2 * 4095 + 10, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0], (Phoneme{9, 4095, 50, true, true, false}));
  EXPECT_EQ(out[1], (Phoneme{9, 4095, 50, false, false, false}));
  EXPECT_EQ(out[2], (Phoneme{9, 10, 50, false, false, true}));
}

TEST(SplitLongPhoneme, ExactMultipleLeavesNoEmptyPiece) {
  std::vector<Phoneme> out;
  split_long_phoneme(Phoneme{}, 2 * 4095, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].duration_ms, 4095);
}

}  // namespace
}  // namespace pfap
