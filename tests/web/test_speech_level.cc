// SPDX-License-Identifier: LGPL-2.1-or-later
// tools/speech_level.h: the level's one-byte code and pfap-broadcast's level message, which
// web/test/clock.test.js decodes (decodeLevelMessage) from the same bytes.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "speech_level.h"

TEST(SpeechLevel, CodesAreSixteenAnOctaveOfOnePlusTheLevel) {
  const std::vector<int64_t> levels = {-5, 0, 1, 1023, 32767, int64_t{1} << 40};
  EXPECT_EQ(level_codes(levels), (std::vector<uint8_t>{0, 0, 16, 160, 240, 255}));
}

TEST(SpeechLevel, TheMessageIsItsHeaderThenOneCodeAMillisecond) {
  const std::vector<int64_t> levels = {0, 1, 1023, 32767};
  // As web/test/clock.test.js's LEVEL_MESSAGE.
  const std::vector<uint8_t> expected = {1,    0,    0,    4,    0x11, 0x22, 0x33, 0x44,
                                         0xff, 0xff, 0xff, 0xf0, 0,    16,   160,  240};
  EXPECT_EQ(level_message(0x11223344, 0xfffffff0, levels), expected);
  EXPECT_EQ(expected.size(), kLevelHeaderSize + levels.size());
  EXPECT_EQ(expected[0], kLevelMessageType);
}

TEST(SpeechLevel, AFullMessageCountsItsFiftyLevels) {
  const std::vector<int64_t> levels(SpeechLevel::kLevelsPerMessage, 100);
  const std::vector<uint8_t> message = level_message(1, 2, levels);
  ASSERT_EQ(message.size(), kLevelHeaderSize + 50);
  EXPECT_EQ(message[2], 0);
  EXPECT_EQ(message[3], 50);
  EXPECT_EQ(message.back(), 107);  // round(16 × log2(101))
}

TEST(SpeechLevel, TheEnvelopeIsTheSameCodesInBase64) {
  EXPECT_EQ(encode_levels(std::vector<int64_t>{0, 1, 1023, 32767}), "ABCg8A==");
}
