// SPDX-License-Identifier: LGPL-2.1-or-later
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "pfap/bookmark.h"
#include "random_markup.h"

namespace pfap {
namespace {

Fap fap(int index, int32_t amplitude, int transition_ms, int curve) {
  return Fap{static_cast<uint8_t>(index), amplitude, static_cast<uint16_t>(transition_ms),
             static_cast<Curve>(curve)};
}

// Sentinels that parse_bookmark and parse_bookmarks must keep on error.
const std::vector<Fap> kBefore = {fap(50, 7, 8, 2)};

struct ErrorCase {
  std::string_view text;
  size_t position;
  size_t pos = 0;  // where parse_bookmark starts
};

// Checks the status and position and that `pos` and `out` are untouched.
void expect_bookmark_error(BookmarkStatus status, std::initializer_list<ErrorCase> cases) {
  for (const ErrorCase& c : cases) {
    SCOPED_TRACE(::testing::Message() << '"' << c.text << "\" from " << c.pos);
    std::vector<Fap> out = kBefore;
    size_t pos = c.pos;
    const BookmarkResult result = parse_bookmark(c.text, pos, out);
    EXPECT_EQ(result.status, status) << to_string(result.status);
    EXPECT_EQ(result.position, c.position);
    EXPECT_EQ(pos, c.pos);
    EXPECT_EQ(out, kBefore);
  }
}

// Parses one bookmark that must take the whole text.
std::vector<Fap> parse_one(std::string_view text) {
  std::vector<Fap> out;
  size_t pos = 0;
  const BookmarkResult result = parse_bookmark(text, pos, out);
  EXPECT_TRUE(result.ok()) << '"' << text << "\": " << to_string(result.status) << " at "
                           << result.position;
  EXPECT_EQ(pos, text.size()) << text;
  return out;
}

TEST(ParseBookmark, DraftExampleExpressionEqualsItsTransformedForm) {
  const std::vector<Fap> expected = {fap(69, 40, 2000, 3), fap(70, 30, 2000, 3)};
  EXPECT_EQ(parse_one("<FAP 2 1 40 2 30 2000 3>"), expected);

  std::vector<Fap> transformed;
  EXPECT_TRUE(parse_bookmarks("<FAP 69 40 2000 3><FAP 70 30 2000 3>", transformed).ok());
  EXPECT_EQ(transformed, expected);
}

TEST(ParseBookmark, SingleAmplitudeFormsGiveOneFap) {
  EXPECT_EQ(parse_one("<FAP 3 -120 500 2>"), std::vector{fap(3, -120, 500, 2)});
  EXPECT_EQ(parse_one("<FAP 68 5 0 1>"), std::vector{fap(68, 5, 0, 1)});
  EXPECT_EQ(parse_one("<FAP 74 0 16383 3>"), std::vector{fap(74, 0, 16383, 3)});
}

TEST(ParseBookmark, AcceptsWhiteSpaceVariants) {
  const std::vector<Fap> expected = {fap(3, 1, 2, 1)};
  for (std::string_view text :
       {"<FAP 3 1 2 1>", "< FAP 3 1 2 1>", "<\r\n\tFAP 3 1 2 1>", "<FAP\t3\t1\t2\t1>",
        "<FAP\r\n3\n1  \t 2\r1>", "<FAP 3 1 2 1 >", "<FAP 3 1 2 1\n\t>"}) {
    EXPECT_EQ(parse_one(text), expected) << text;
  }
}

TEST(ParseBookmark, AcceptsSignsAndLeadingZeros) {
  EXPECT_EQ(parse_one("<FAP +3 +10 +2 +1>"), std::vector{fap(3, 10, 2, 1)});
  EXPECT_EQ(parse_one("<FAP 003 -0 00 01>"), std::vector{fap(3, 0, 0, 1)});
}

TEST(ParseBookmark, FieldExtremesAreAccepted) {
  EXPECT_EQ(parse_one("<FAP 48 2529600 16383 3>"), std::vector{fap(48, 2529600, 16383, 3)});
  EXPECT_EQ(parse_one("<FAP 48 -2529600 0 1>"), std::vector{fap(48, -2529600, 0, 1)});
  EXPECT_EQ(parse_one("<FAP 2 6 -2529600 1 2529600 16383 3>"),
            (std::vector{fap(74, -2529600, 16383, 3), fap(69, 2529600, 16383, 3)}));
}

TEST(ParseBookmark, NeutralExpressionWithZeroAmplitudeLeavesItsSlotEmpty) {
  EXPECT_EQ(parse_one("<FAP 2 1 40 0 0 500 1>"), std::vector{fap(69, 40, 500, 1)});
  EXPECT_EQ(parse_one("<FAP 2 0 0 4 -10 500 1>"), std::vector{fap(72, -10, 500, 1)});
  EXPECT_EQ(parse_one("<FAP 2 0 0 0 0 500 1>"), std::vector<Fap>{});
}

TEST(ParseBookmark, SameExpressionTwiceGivesTwoFapsInOrder) {
  EXPECT_EQ(parse_one("<FAP 2 3 10 3 20 100 2>"),
            (std::vector{fap(71, 10, 100, 2), fap(71, 20, 100, 2)}));
}

TEST(ParseBookmark, AppendsAndStopsAfterTheClosingBracket) {
  const std::string_view text = "xx<FAP 3 1 2 1><FAP 4 5 6 3>yy";
  std::vector<Fap> out = kBefore;
  size_t pos = 2;
  ASSERT_TRUE(parse_bookmark(text, pos, out).ok());
  EXPECT_EQ(pos, 15u);
  ASSERT_TRUE(parse_bookmark(text, pos, out).ok());
  EXPECT_EQ(pos, 28u);
  EXPECT_EQ(out, (std::vector{kBefore[0], fap(3, 1, 2, 1), fap(4, 5, 6, 3)}));
}

TEST(ParseBookmarkError, NotABookmarkAtTheStartPosition) {
  expect_bookmark_error(BookmarkStatus::kNotABookmark, {
                                                           {"", 0},
                                                           {" <FAP 3 1 2 1>", 0},
                                                           {"FAP 3 1 2 1>", 0},
                                                           {"<fap 3 1 2 1>", 0},
                                                           {"<FAQ 3 1 2 1>", 0},
                                                           {"<F AP 3 1 2 1>", 0},
                                                           {"<FA", 0},
                                                           {"<", 0},
                                                           {"ab<FAX 3 1 2 1>", 2, 2},
                                                           {"<FAP", 7, 7},  // start past the end
                                                       });
}

TEST(ParseBookmarkError, UnterminatedAtTheLessThanSign) {
  expect_bookmark_error(BookmarkStatus::kUnterminated,
                        {
                            {"<FAP", 0},
                            {"<FAP 3 1 2 1", 0},
                            {"<FAP 3 1 2 1<FAP 4 1 2 1>", 0},
                            {"<FAP x", 0},  // checked before the fields
                            {"ab< FAP 3 1 2 1 <", 2, 2},
                        });
}

TEST(ParseBookmarkError, BadNumberAtTheFieldOrAtTheBracketWhenFieldsAreMissing) {
  expect_bookmark_error(BookmarkStatus::kBadNumber,
                        {
                            {"<FAP3 1 2 1>", 4},  // no separator after FAP
                            {"<FAPX 3 1 2 1>", 4},
                            {"<FAP 3 x 2 1>", 7},
                            {"<FAP 3 1.5 2 1>", 7},
                            {"<FAP 3 - 2 1>", 7},
                            {"<FAP 3 +-1 2 1>", 7},
                            {"<FAP 3 1- 2 1>", 7},
                            {"<FAP 3 0x10 2 1>", 7},
                            {"<FAP 3 1 2 1x>", 11},
                            {"<FAP three 1 2 1>", 5},
                            {"<FAP>", 4},         // no fields
                            {"<FAP 3 1 2>", 10},  // too few
                            {"<FAP 2 1 40 2 30 2000>", 21},
                            {"<FAP 3 1 2 1 1>", 13},  // too many
                            {"<FAP 2 1 40 2 30 2000 3 3>", 24},
                            {"ab<FAP 3 1 2 z>", 13, 2},
                        });
}

TEST(ParseBookmarkError, UnknownFapAtTheFapNumber) {
  expect_bookmark_error(BookmarkStatus::kUnknownFap,
                        {
                            {"<FAP 0 1 2 1>", 5},
                            {"<FAP 1 1 2 1>", 5},
                            {"<FAP 75 1 2 1>", 5},
                            {"<FAP -3 1 2 1>", 5},
                            {"<FAP 99999999999999999999999 1 2 1>", 5},
                            {"<FAP 99 x 2 1>", 5},  // the leftmost bad field is the one reported
                        });
}

TEST(ParseBookmarkError, ExpressionOutOfRangeAtTheExpression) {
  expect_bookmark_error(BookmarkStatus::kExpressionOutOfRange,
                        {
                            {"<FAP 2 7 40 1 30 500 1>", 7},
                            {"<FAP 2 -1 40 1 30 500 1>", 7},
                            {"<FAP 2 1 40 9 30 500 1>", 12},
                            {"<FAP 2 0 5 1 30 500 1>", 7},  // neutral with a non-zero amplitude
                            {"<FAP 2 1 40 0 -5 500 1>", 12},
                        });
}

TEST(ParseBookmarkError, AmplitudeOutOfRangeAtTheAmplitude) {
  expect_bookmark_error(
      BookmarkStatus::kAmplitudeOutOfRange,
      {
          {"<FAP 3 2529601 2 1>", 7},
          {"<FAP 3 -2529601 2 1>", 7},
          {"<FAP 3 99999999999999999999999 2 1>", 7},  // huge numbers saturate, never overflow
          {"<FAP 3 -99999999999999999999999 2 1>", 7},
          {"<FAP 2 1 40 2 2529601 500 1>", 14},
          {"<FAP 2 0 2529601 1 30 500 1>", 9},  // range before the neutral rule
      });
}

TEST(ParseBookmarkError, TransitionOutOfRangeAtTheTransitionAndNeverClamped) {
  expect_bookmark_error(BookmarkStatus::kTransitionOutOfRange,
                        {
                            {"<FAP 3 1 16384 1>", 9},
                            {"<FAP 3 1 -1 1>", 9},
                            {"<FAP 3 1 99999999999999999999 1>", 9},
                            {"<FAP 2 1 40 2 30 16384 3>", 17},
                        });
}

TEST(ParseBookmarkError, CurveOutOfRangeAtTheCurve) {
  expect_bookmark_error(
      BookmarkStatus::kCurveOutOfRange,
      {
          {"<FAP 3 1 2 0>", 11},
          {"<FAP 3 1 2 4>", 11},
          {"<FAP 3 1 2 -1>", 11},
          {"<FAP 2 1 40 2 30 2000 4>", 22},  // late error: the first slot must not be kept
      });
}

// A run of `count` bookmarks "<FAP 3 i 0 1>" separated by `separator`.
std::string run_of(int count, std::string_view separator, std::vector<size_t>* starts = nullptr) {
  std::string text;
  for (int i = 0; i < count; ++i) {
    if (i > 0) text += separator;
    if (starts) starts->push_back(text.size());
    text += "<FAP 3 " + std::to_string(i) + " 0 1>";
  }
  return text;
}

TEST(ParseBookmarks, EmptyOrWhiteSpaceOnlyGivesNoFaps) {
  for (std::string_view text : {"", " ", "\r\n\t "}) {
    std::vector<Fap> out = kBefore;
    EXPECT_TRUE(parse_bookmarks(text, out).ok());
    EXPECT_EQ(out, kBefore);
  }
}

TEST(ParseBookmarks, WhiteSpaceAroundAndBetweenBookmarksIsIgnored) {
  std::vector<Fap> out = kBefore;
  ASSERT_TRUE(
      parse_bookmarks("\n <FAP 3 1 2 1>\t\r\n<FAP 2 1 40 2 30 2000 3><FAP 4 5 6 3> ", out).ok());
  EXPECT_EQ(out, (std::vector{kBefore[0], fap(3, 1, 2, 1), fap(69, 40, 2000, 3),
                              fap(70, 30, 2000, 3), fap(4, 5, 6, 3)}));
}

TEST(ParseBookmarks, FortyBookmarksAreAcceptedTheFortyFirstIsTooMany) {
  std::vector<Fap> out;
  ASSERT_TRUE(parse_bookmarks(run_of(kMaxBookmarksPerPhoneme, " ") + " ", out).ok());
  EXPECT_EQ(out.size(), size_t{kMaxBookmarksPerPhoneme});

  std::vector<size_t> starts;
  const std::string text = run_of(kMaxBookmarksPerPhoneme + 1, "\n", &starts);
  out = kBefore;
  const BookmarkResult result = parse_bookmarks(text, out);
  EXPECT_EQ(result.status, BookmarkStatus::kTooManyBookmarks);
  EXPECT_EQ(result.position, starts.back());
  EXPECT_EQ(out, kBefore);
}

TEST(ParseBookmarks, BookmarksWithoutFapsCountTowardsTheLimit) {
  std::string text;
  for (int i = 0; i < kMaxBookmarksPerPhoneme; ++i) text += "<FAP 2 0 0 0 0 1 1>";
  std::vector<Fap> out;
  ASSERT_TRUE(parse_bookmarks(text, out).ok());
  EXPECT_TRUE(out.empty());

  const size_t extra = text.size();
  text += "<FAP 3 1 2 1>";
  const BookmarkResult result = parse_bookmarks(text, out);
  EXPECT_EQ(result.status, BookmarkStatus::kTooManyBookmarks);
  EXPECT_EQ(result.position, extra);
}

TEST(ParseBookmarks, MalformedFortyFirstReportsItsOwnError) {
  std::string text = run_of(kMaxBookmarksPerPhoneme, "");
  const size_t extra = text.size();
  text += "<FAP 3 1 2 9>";
  std::vector<Fap> out;
  const BookmarkResult result = parse_bookmarks(text, out);
  EXPECT_EQ(result.status, BookmarkStatus::kCurveOutOfRange);
  EXPECT_EQ(result.position, extra + 11);
}

TEST(ParseBookmarks, ErrorsInARunHaveTheirPositionInTheWholeText) {
  struct Case {
    std::string_view text;
    BookmarkStatus status;
    size_t position;
  };
  const Case cases[] = {
      {"hello", BookmarkStatus::kUnexpectedText, 0},
      {"<FAP 3 1 2 1> x <FAP 4 1 2 1>", BookmarkStatus::kUnexpectedText, 14},
      {"<FAP 3 1 2 1>>", BookmarkStatus::kUnexpectedText, 13},
      {"<FAP 3 1 2 1> <FAQ 4 1 2 1>", BookmarkStatus::kUnexpectedText, 14},
      {"<FAP 3 1 2 1>\v", BookmarkStatus::kUnexpectedText, 13},  // only SP, HT, CR, LF
      {"<FAP 3 1 2 1> <FAP 4 1 2 1", BookmarkStatus::kUnterminated, 14},
      {"<FAP 3 1 2 1 <FAP 4 1 2 1>", BookmarkStatus::kUnterminated, 0},
      {"<FAP 3 1 2 1>\n<FAP 4 x 2 1>", BookmarkStatus::kBadNumber, 21},
      {"<FAP 3 1 2 1> <FAP 4 1 2>", BookmarkStatus::kBadNumber, 24},
      {"<FAP 3 1 2 1> <FAP 1 1 2 1>", BookmarkStatus::kUnknownFap, 19},
      {"<FAP 3 1 2 1> <FAP 2 8 1 1 1 2 1>", BookmarkStatus::kExpressionOutOfRange, 21},
      {"<FAP 3 1 2 1> <FAP 4 -2529601 2 1>", BookmarkStatus::kAmplitudeOutOfRange, 21},
      {"<FAP 3 1 2 1> <FAP 4 1 16384 1>", BookmarkStatus::kTransitionOutOfRange, 23},
      {"<FAP 3 1 2 1> <FAP 4 1 2 0>", BookmarkStatus::kCurveOutOfRange, 25},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    std::vector<Fap> out = kBefore;
    const BookmarkResult result = parse_bookmarks(c.text, out);
    EXPECT_EQ(result.status, c.status) << to_string(result.status);
    EXPECT_EQ(result.position, c.position);
    EXPECT_EQ(out, kBefore);
  }
}

TEST(FormatBookmarks, OneTransformedBookmarkPerFapAppended) {
  std::string out = "x";
  format_bookmarks(std::vector{fap(69, 40, 2000, 3), fap(3, -2529600, 16383, 1)}, out);
  EXPECT_EQ(out, "x<FAP 69 40 2000 3><FAP 3 -2529600 16383 1>");

  format_bookmarks({}, out);
  EXPECT_EQ(out, "x<FAP 69 40 2000 3><FAP 3 -2529600 16383 1>");
}

TEST(FormatBookmarks, RoundTripsSeededRandomFaps) {
  for (uint32_t seed = 1; seed <= 500; ++seed) {
    SCOPED_TRACE(seed);
    testing::RandomMarkup random(seed);
    std::vector<Fap> faps(static_cast<size_t>(random.uniform(0, kMaxBookmarksPerPhoneme)));
    for (Fap& f : faps) f = random.fap();

    std::string text;
    format_bookmarks(faps, text);
    std::vector<Fap> parsed;
    const BookmarkResult result = parse_bookmarks(text, parsed);
    ASSERT_TRUE(result.ok()) << to_string(result.status) << " at " << result.position << " in "
                             << text;
    EXPECT_EQ(parsed, faps);
  }
}

TEST(BookmarkStatusText, EveryStatusHasItsOwnLowercasePhrase) {
  EXPECT_STREQ(to_string(BookmarkStatus::kUnterminated), "unterminated bookmark");
  std::set<std::string> phrases;
  for (int s = 0; s <= static_cast<int>(BookmarkStatus::kUnexpectedText); ++s) {
    const std::string phrase = to_string(static_cast<BookmarkStatus>(s));
    EXPECT_FALSE(phrase.empty());
    for (char c : phrase) EXPECT_FALSE(c >= 'A' && c <= 'Z') << phrase;
    EXPECT_TRUE(phrases.insert(phrase).second) << phrase;
  }
}

}  // namespace
}  // namespace pfap
