// SPDX-License-Identifier: LGPL-2.1-or-later
// piece_end and piece: an utterance cut at sentence ends, no piece over kMaxPieceCodePoints,
// bookmarks in the piece the MPEG-4 rule places them in.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pieces.h"

namespace pfap::tts {
namespace {

Utterance parse(const std::string& input) {
  std::vector<BadBookmark> bad;
  Utterance u = parse_utterance(input, bad);
  EXPECT_TRUE(bad.empty());
  return u;
}

// Every piece of `u` in order, as text; `bookmarks_at` gets "piece:position" per bookmark.
std::vector<std::string> pieces(const Utterance& u, std::vector<std::string>* bookmarks_at = nullptr) {
  std::vector<std::string> out;
  size_t next_bookmark = 0;
  size_t from = 0;
  do {
    const size_t end = piece_end(u.text, from);
    const Utterance p = piece(u, from, end, next_bookmark);
    if (bookmarks_at != nullptr) {
      for (const Bookmark& b : p.bookmarks) {
        bookmarks_at->push_back(std::to_string(out.size()) + ":" + std::to_string(b.position));
      }
    }
    out.push_back(p.text_utf8());
    from = end;
  } while (from < u.text.size());
  EXPECT_EQ(next_bookmark, u.bookmarks.size());
  return out;
}

TEST(Pieces, OneSentenceEach) {
  EXPECT_EQ(pieces(parse("Hello world. How are you? Fine! Thanks...")),
            (std::vector<std::string>{"Hello world. ", "How are you? ", "Fine! ", "Thanks..."}));
}

TEST(Pieces, ClosingQuotesStayWithTheirSentence) {
  EXPECT_EQ(pieces(parse("He said \"stop.\"  Then (he left.) Done")),
            (std::vector<std::string>{"He said \"stop.\"  ", "Then (he left.) ", "Done"}));
}

TEST(Pieces, NoSentenceEndInsideWordsOrNumbers) {
  EXPECT_EQ(pieces(parse("Pi is 3.14 and e.g.this is one.")),
            (std::vector<std::string>{"Pi is 3.14 and e.g.this is one."}));
}

TEST(Pieces, EmptyTextIsOnePiece) {
  EXPECT_EQ(pieces(parse("")), (std::vector<std::string>{""}));
  EXPECT_EQ(pieces(parse("<FAP 3 10 0 1>")), (std::vector<std::string>{""}));
}

TEST(Pieces, LongRunsAreCutAtWhiteSpaceWithinTheLimit) {
  std::string words;
  while (words.size() < 3 * kMaxPieceCodePoints) words += "word ";
  const std::vector<std::string> p = pieces(parse(words));
  ASSERT_GE(p.size(), 3u);
  std::string joined;
  for (const std::string& s : p) {
    EXPECT_LE(s.size(), kMaxPieceCodePoints);
    EXPECT_GT(s.size(), kMaxPieceCodePoints - 6);  // cut at the last space within the limit
    EXPECT_EQ(s.back(), ' ');
    joined += s;
  }
  EXPECT_EQ(joined, words);
}

TEST(Pieces, TextWithoutWhiteSpaceIsCutAtTheLimit) {
  const std::string letters(2 * kMaxPieceCodePoints + 7, 'x');
  const std::vector<std::string> p = pieces(parse(letters));
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[0].size(), kMaxPieceCodePoints);
  EXPECT_EQ(p[1].size(), kMaxPieceCodePoints);
  EXPECT_EQ(p[2].size(), 7u);
}

TEST(Pieces, LimitCountsCodePoints) {
  std::string text;
  for (size_t i = 0; i < kMaxPieceCodePoints + 1; ++i) text += "é";
  const Utterance u = parse(text);
  EXPECT_EQ(piece_end(u.text, 0), kMaxPieceCodePoints);
}

// The MPEG-4 rule (docs/tts.md): a bookmark after a full stop, with only white space before
// the next word, starts the next sentence; one before the full stop ends its own.
TEST(Pieces, BookmarksGoWhereTheRulePlacesThem) {
  std::vector<std::string> at;
  const std::vector<std::string> p = pieces(
      parse("<FAP 3 10 0 1>One two. <FAP 3 20 0 1>Three <FAP 3 30 0 1>four <FAP 3 40 0 1>. "
            "Five.<FAP 3 50 0 1> Six.  <FAP 3 60 0 1>"),
      &at);
  EXPECT_EQ(p, (std::vector<std::string>{"One two. ", "Three four . ", "Five. ", "Six.  "}));
  EXPECT_EQ(at, (std::vector<std::string>{"0:0", "1:0", "1:6", "1:11", "3:0", "3:6"}));
}

TEST(Pieces, EveryCodePointOnceAndInOrder) {
  const Utterance u = parse("A. B! C? D\u2026 E \"F.\" G");
  std::string joined;
  for (const std::string& s : pieces(u)) joined += s;
  EXPECT_EQ(joined, u.text_utf8());
}

}  // namespace
}  // namespace pfap::tts
