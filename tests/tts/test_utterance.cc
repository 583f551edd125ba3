// SPDX-License-Identifier: LGPL-2.1-or-later
// parse_utterance: text and bookmarks apart, positions in code points, bad bookmarks named
// where they are and left out.
#include <gtest/gtest.h>

#include <string>

#include "utterance.h"

namespace pfap::tts {
namespace {

std::string text_of(const Utterance& u) { return u.text_utf8(); }

TEST(Utterance, TheIssuesExample) {
  std::vector<BadBookmark> bad;
  const Utterance u =
      parse_utterance("Hello <FAP 2 1 40 0 0 500 1> world, <FAP 48 20000 800 3> how are you?", bad);
  EXPECT_TRUE(bad.empty());
  EXPECT_EQ(text_of(u), "Hello  world,  how are you?");
  ASSERT_EQ(u.bookmarks.size(), 2u);
  EXPECT_EQ(u.bookmarks[0].position, 6u);
  EXPECT_EQ(u.bookmarks[0].source_character, 6u);
  ASSERT_EQ(u.bookmarks[0].faps.size(), 1u);
  EXPECT_EQ(u.bookmarks[0].faps[0], (Fap{69, 40, 500, Curve::kLinear}));
  EXPECT_EQ(u.bookmarks[1].position, 14u);
  ASSERT_EQ(u.bookmarks[1].faps.size(), 1u);
  EXPECT_EQ(u.bookmarks[1].faps[0], (Fap{48, 20000, 800, Curve::kSpline}));
}

TEST(Utterance, PositionsCountCodePointsNotBytes) {
  std::vector<BadBookmark> bad;
  const Utterance u = parse_utterance("Café naïve <FAP 3 10 0 1>über", bad);
  EXPECT_TRUE(bad.empty());
  EXPECT_EQ(text_of(u), "Café naïve über");
  ASSERT_EQ(u.bookmarks.size(), 1u);
  EXPECT_EQ(u.bookmarks[0].position, 11u);
  EXPECT_EQ(u.text.substr(11, 4), U"über");
}

TEST(Utterance, OtherAngleBracketsAreText) {
  std::vector<BadBookmark> bad;
  const Utterance u = parse_utterance("a < b and c > d <FAP 3 1 0 1>", bad);
  EXPECT_TRUE(bad.empty());
  EXPECT_EQ(text_of(u), "a < b and c > d ");
  EXPECT_EQ(u.bookmarks.size(), 1u);
}

TEST(Utterance, BadBookmarksNameTheirCharacterAndAreLeftOut) {
  struct Case {
    std::string input;
    BookmarkStatus status;
    size_t character;  // from 0, in the input
    std::string text;
  };
  const Case cases[] = {
      {"Héllo <FAP 99 1 0 1> world", BookmarkStatus::kUnknownFap, 11, "Héllo  world"},
      {"Héllo <FAP 3 1 0 7> world", BookmarkStatus::kCurveOutOfRange, 17, "Héllo  world"},
      {"Hi <FAP 3 1 20000 1> there", BookmarkStatus::kTransitionOutOfRange, 12, "Hi  there"},
      {"Hi <FAP 2 9 10 0 0 0 1> there", BookmarkStatus::kExpressionOutOfRange, 10, "Hi  there"},
      {"Hi <FAP 3 x 0 1> there", BookmarkStatus::kBadNumber, 10, "Hi  there"},
      {"Hi <FAP 3 1 0 1 there <FAP 3 2 0 1>", BookmarkStatus::kUnterminated, 3, "Hi "},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.input);
    std::vector<BadBookmark> bad;
    const Utterance u = parse_utterance(c.input, bad);
    ASSERT_EQ(bad.size(), 1u);
    EXPECT_EQ(bad[0].status, c.status) << to_string(bad[0].status);
    EXPECT_EQ(bad[0].character, c.character);
    EXPECT_EQ(text_of(u), c.text);
  }
}

TEST(Utterance, FortyConsecutiveBookmarksAndNoMore) {
  std::string run;
  for (int i = 0; i < 40; ++i) run += "<FAP 3 " + std::to_string(i) + " 0 1> ";
  std::vector<BadBookmark> bad;
  Utterance u = parse_utterance("Go " + run + "now", bad);
  EXPECT_TRUE(bad.empty());
  EXPECT_EQ(u.bookmarks.size(), 40u);

  // A 41st in the same run is refused at its '<'; the 40 stay.
  const std::string input = "Go " + run + "<FAP 4 1 0 1> now";
  u = parse_utterance(input, bad);
  ASSERT_EQ(bad.size(), 1u);
  EXPECT_EQ(bad[0].status, BookmarkStatus::kTooManyBookmarks);
  EXPECT_EQ(bad[0].character, input.find("<FAP 4"));
  EXPECT_EQ(u.bookmarks.size(), 40u);

  // Text between runs starts a new run.
  bad.clear();
  u = parse_utterance("Go " + run + "on " + run + "now", bad);
  EXPECT_TRUE(bad.empty());
  EXPECT_EQ(u.bookmarks.size(), 80u);
}

}  // namespace
}  // namespace pfap::tts
