// SPDX-License-Identifier: LGPL-2.1-or-later
// place_bookmark: the MPEG-4 rule, table-driven over one two-sentence text.
#include <gtest/gtest.h>

#include <string>

#include "placement.h"

namespace pfap::tts {
namespace {

// "Hello big world. How are you?" with phonemes numbered as a TTS would give them:
//   Hello 0..3, big 4..6, world 7..10, pause 11, How 12..13, are 14, you 15..16, pause 17.
const std::u32string kText = U"Hello big world. How are you?";
const Word kWords[] = {
    {0, 0, 0, 3}, {6, 0, 4, 6}, {10, 0, 7, 10}, {17, 1, 12, 13}, {21, 1, 14, 14}, {25, 1, 15, 16},
};

TEST(Placement, MpegRule) {
  struct Case {
    const char* where;
    size_t position;
    size_t phoneme;
  };
  const Case cases[] = {
      {"before the first word", 0, 0},
      {"between words: the next word's first phoneme", 6, 4},
      {"inside a word: the next word's first phoneme", 2, 4},
      {"before the full stop: no word after in the sentence, the last of world", 15, 10},
      {"right after the full stop: the next sentence's first word", 16, 12},
      {"after the full stop and the space", 17, 12},
      {"in the second sentence", 21, 14},
      {"before the question mark: the last phoneme of you", 28, 16},
      {"at the end of the text: the last phoneme of you", 29, 16},
      {"past the end", 40, 16},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.where);
    EXPECT_EQ(place_bookmark(kWords, kText, c.position), c.phoneme);
  }
}

TEST(Placement, OpeningQuoteOfTheNextSentence) {
  const std::u32string text = U"Stop. \"Go on.\"";
  const Word words[] = {{0, 0, 0, 2}, {7, 1, 4, 5}, {10, 1, 6, 7}};
  EXPECT_EQ(place_bookmark(words, text, 6), 4u);  // before the quote: Go
  EXPECT_EQ(place_bookmark(words, text, 4), 2u);  // before the full stop: Stop
}

TEST(Placement, NoWords) { EXPECT_EQ(place_bookmark({}, U"...", 1), std::nullopt); }

}  // namespace
}  // namespace pfap::tts
