// SPDX-License-Identifier: LGPL-2.1-or-later
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "pfap/text.h"
#include "random_markup.h"

namespace pfap {
namespace {

Fap fap(int index, int32_t amplitude, int transition_ms, int curve) {
  return Fap{static_cast<uint8_t>(index), amplitude, static_cast<uint16_t>(transition_ms),
             static_cast<Curve>(curve)};
}

TextEvent phoneme_event(int64_t time_ms, int symbol, int duration_ms, unsigned f0_hz,
                        std::string_view flags = "", std::vector<Fap> faps = {}) {
  TextEvent e;
  e.time_ms = time_ms;
  e.event.phoneme.symbol = static_cast<uint8_t>(symbol);
  e.event.phoneme.duration_ms = static_cast<uint16_t>(duration_ms);
  e.event.phoneme.f0 = f0_code(f0_hz);
  e.event.phoneme.stress = flags.find('S') != std::string_view::npos;
  e.event.phoneme.word_begin = flags.find('W') != std::string_view::npos;
  e.event.phoneme.end_of_text = flags.find('E') != std::string_view::npos;
  e.event.faps = std::move(faps);
  return e;
}

TextEvent state_event(int64_t time_ms, PfapEventKind kind, std::vector<Fap> faps = {}) {
  TextEvent e;
  e.time_ms = time_ms;
  e.event.kind = kind;
  e.event.faps = std::move(faps);
  return e;
}

// The event of one line read at the start of a stream (sentence_start cleared so that
// expectations need not repeat it).
TextEvent read_one(std::string_view line) {
  TextReader reader;
  TextEvent out;
  bool has_event = false;
  const TextResult result = reader.read_line(line, out, has_event);
  EXPECT_TRUE(result.ok()) << '"' << line << "\": " << to_string(result.status) << " at "
                           << result.column;
  EXPECT_TRUE(has_event) << line;
  out.event.sentence_start = false;
  return out;
}

std::string format(const TextEvent& event) {
  std::string line;
  format_text_line(event, line);
  return line;
}

const TextEvent kSentinel = phoneme_event(7, 8, 9, 10, "SWE", {fap(50, 7, 8, 2)});

struct ErrorCase {
  std::string_view line;
  TextStatus status;
  size_t column;
  BookmarkStatus bookmark = BookmarkStatus::kOk;
};

// Each line, read at the start of a stream, fails as expected and leaves `out` alone.
void expect_errors(std::initializer_list<ErrorCase> cases) {
  for (const ErrorCase& c : cases) {
    SCOPED_TRACE(::testing::Message() << '"' << c.line << '"');
    TextReader reader;
    TextEvent out = kSentinel;
    bool has_event = true;
    const TextResult result = reader.read_line(c.line, out, has_event);
    EXPECT_EQ(result.status, c.status) << to_string(result.status);
    EXPECT_EQ(result.column, c.column);
    EXPECT_EQ(result.bookmark, c.bookmark) << to_string(result.bookmark);
    EXPECT_FALSE(has_event);
    EXPECT_EQ(out, kSentinel);
  }
}

TEST(ReadLine, SkipsAByteOrderMarkOnlyAtTheStartOfTheFirstLine) {
  constexpr std::string_view kBom = "\xEF\xBB\xBF";
  TextReader reader;
  TextEvent out;
  bool has_event = false;
  ASSERT_TRUE(reader.read_line(std::string(kBom) + "120 17 85 200 SW", out, has_event).ok());
  ASSERT_TRUE(has_event);
  EXPECT_EQ(out.time_ms, 120);
  EXPECT_EQ(out.event.phoneme.symbol, 17);

  // Later lines: a byte order mark is a bad time, at column 0 of the line as given.
  const TextResult later = reader.read_line(std::string(kBom) + "200 17 85 200 -", out, has_event);
  EXPECT_EQ(later.status, TextStatus::kBadTime);
  EXPECT_EQ(later.column, 0u);

  // A comment line first takes the mark too; errors after it count its bytes.
  TextReader commented;
  ASSERT_TRUE(commented.read_line(std::string(kBom) + "# a session", out, has_event).ok());
  EXPECT_FALSE(has_event);
  TextReader bad;
  const TextResult result = bad.read_line(std::string(kBom) + "12 x 85 200 -", out, has_event);
  EXPECT_EQ(result.status, TextStatus::kBadSymbol);
  EXPECT_EQ(result.column, kBom.size() + 3);

  // After reset() the next line is a first line again.
  reader.reset();
  EXPECT_TRUE(reader.read_line(std::string(kBom) + "0 1 10 0 -", out, has_event).ok());
}

TEST(CountTextEvents, CountsTheEventsOfWholeLinesOnly) {
  constexpr std::string_view kText = "# hello\n\n0 12 80 120 SW\n80 state complete\n100 1 2";
  EXPECT_EQ(count_text_events(kText, false), 2u) << "the cut last line is not read";
  EXPECT_EQ(count_text_events(kText, true), 0u) << "whole, its last line is missing fields";
  EXPECT_EQ(count_text_events("\xEF\xBB\xBF" "0 12 80 120 SW\r\n20 1 2 3 -", true), 2u);
}

TEST(CountTextEvents, IsZeroForOtherTextAndForCommentsOnly) {
  EXPECT_EQ(count_text_events("Hello world.\nHow are you?\n", true), 0u);
  EXPECT_EQ(count_text_events("1\n00:00:01,000 --> 00:00:02,000\nHi\n", true), 0u);  // SubRip
  EXPECT_EQ(count_text_events("v=0\no=- 0 0 IN IP4 127.0.0.1\n", true), 0u);         // SDP
  EXPECT_EQ(count_text_events("# only a comment\n\n", true), 0u);
  EXPECT_EQ(count_text_events("", true), 0u);
  EXPECT_EQ(count_text_events("20 1 2 3 -\n10 1 2 3 -\n", true), 0u) << "time goes back";
}

TEST(ReadLine, PhonemeFieldsGoToTheirPlaces) {
  TextReader reader;
  TextEvent out;
  bool has_event = false;
  ASSERT_TRUE(reader.read_line("120 17 85 200 SW", out, has_event).ok());
  ASSERT_TRUE(has_event);
  EXPECT_EQ(out.time_ms, 120);
  EXPECT_EQ(out.event.kind, PFAP_EVENT_PHONEME);
  EXPECT_EQ(out.event.phoneme, (Phoneme{17, 85, 100, true, true, false}));
  EXPECT_TRUE(out.event.sentence_start);
  EXPECT_FALSE(out.event.uncertain);
  EXPECT_TRUE(out.event.faps.empty());
}

TEST(ReadLine, EveryFieldTakesZeroAndItsMaximum) {
  EXPECT_EQ(read_one("0 0 0 0 -"), phoneme_event(0, 0, 0, 0));
  EXPECT_EQ(read_one("9223372032759 255 4095 510 -"), phoneme_event(9223372032759, 255, 4095, 510));
}

TEST(ReadLine, NumbersTakeASignAndLeadingZerosAsInBookmarks) {
  EXPECT_EQ(read_one("+5 +1 +2 +4 -"), phoneme_event(5, 1, 2, 4));
  EXPECT_EQ(read_one("-0 -0 -0 -0 -"), phoneme_event(0, 0, 0, 0));
  EXPECT_EQ(read_one("007 0255 04095 0510 -"), phoneme_event(7, 255, 4095, 510));
}

TEST(ReadLine, EveryFieldRefusesMaxPlusOneNonNumbersAndNegatives) {
  expect_errors({
      {"9223372032760 1 2 4 -", TextStatus::kBadTime, 0},
      {"99999999999999999999999999 1 2 4 -", TextStatus::kBadTime, 0},
      {"-1 1 2 4 -", TextStatus::kBadTime, 0},
      {"1.5 1 2 4 -", TextStatus::kBadTime, 0},
      {"1ms 1 2 4 -", TextStatus::kBadTime, 0},
      {"+ 1 2 4 -", TextStatus::kBadTime, 0},
      {"x 1 2 4 -", TextStatus::kBadTime, 0},
      {"0 256 2 4 -", TextStatus::kBadSymbol, 2},
      {"0 -1 2 4 -", TextStatus::kBadSymbol, 2},
      {"0 a 2 4 -", TextStatus::kBadSymbol, 2},
      {"0 0x1 2 4 -", TextStatus::kBadSymbol, 2},
      {"0 1 4096 4 -", TextStatus::kBadDuration, 4},
      {"0 1 -1 4 -", TextStatus::kBadDuration, 4},
      {"0 1 ms 4 -", TextStatus::kBadDuration, 4},
      {"0 1 2 511 -", TextStatus::kBadF0, 6},
      {"0 1 2 -2 -", TextStatus::kBadF0, 6},
      {"0 1 2 2Hz -", TextStatus::kBadF0, 6},
      {"0 1 2 99999999999999999999 -", TextStatus::kBadF0, 6},
  });
}

TEST(ReadLine, F0RoundsToTheNearestTwoHertzHalvesUp) {
  struct Case {
    std::string_view line;
    uint8_t code;
  };
  for (const Case& c : {Case{"0 1 2 0 -", 0}, Case{"0 1 2 1 -", 1}, Case{"0 1 2 2 -", 1},
                        Case{"0 1 2 3 -", 2}, Case{"0 1 2 509 -", 255}, Case{"0 1 2 510 -", 255}}) {
    EXPECT_EQ(read_one(c.line).event.phoneme.f0, c.code) << c.line;
  }
}

TEST(ReadLine, FlagsAreADashOrSWEInThatOrder) {
  struct Case {
    std::string_view flags;
    bool stress, word_begin, end_of_text;
  };
  for (const Case& c : {Case{"-", false, false, false}, Case{"S", true, false, false},
                        Case{"W", false, true, false}, Case{"E", false, false, true},
                        Case{"SW", true, true, false}, Case{"SE", true, false, true},
                        Case{"WE", false, true, true}, Case{"SWE", true, true, true}}) {
    const Phoneme p = read_one("0 1 2 4 " + std::string(c.flags)).event.phoneme;
    EXPECT_EQ(p.stress, c.stress) << c.flags;
    EXPECT_EQ(p.word_begin, c.word_begin) << c.flags;
    EXPECT_EQ(p.end_of_text, c.end_of_text) << c.flags;
  }
}

TEST(ReadLine, FlagsOutOfOrderRepeatedOrUnknownAreBadFlags) {
  expect_errors({
      {"0 1 2 4 WS", TextStatus::kBadFlags, 8},
      {"0 1 2 4 EW", TextStatus::kBadFlags, 8},
      {"0 1 2 4 ES", TextStatus::kBadFlags, 8},
      {"0 1 2 4 SS", TextStatus::kBadFlags, 8},
      {"0 1 2 4 SWEE", TextStatus::kBadFlags, 8},
      {"0 1 2 4 SWES", TextStatus::kBadFlags, 8},
      {"0 1 2 4 s", TextStatus::kBadFlags, 8},
      {"0 1 2 4 --", TextStatus::kBadFlags, 8},
      {"0 1 2 4 -S", TextStatus::kBadFlags, 8},
      {"0 1 2 4 S-", TextStatus::kBadFlags, 8},
      {"0 1 2 4 X", TextStatus::kBadFlags, 8},
      {"0 1 2 4 0", TextStatus::kBadFlags, 8},
      // A bookmark needs white space before it; glued on, it is part of the flags.
      {"0 1 2 4 S<FAP 3 1 2 1>", TextStatus::kBadFlags, 8},
  });
}

TEST(ReadLine, MissingFieldIsReportedWhereTheLineEnds) {
  expect_errors({
      {"5", TextStatus::kMissingField, 1},
      {"5 1", TextStatus::kMissingField, 3},
      {"5 1 2", TextStatus::kMissingField, 5},
      {"5 1 2 4", TextStatus::kMissingField, 7},
      {"5 1 2 4  \t", TextStatus::kMissingField, 10},
      {"5 1 2 4 # flags forgotten", TextStatus::kMissingField, 8},
      {"5 1 2 4\r", TextStatus::kMissingField, 7},
      {"5 state", TextStatus::kMissingField, 7},
      {"5 state #", TextStatus::kMissingField, 8},
  });
}

TEST(ReadLine, BlankAndCommentLinesGiveNoEvent) {
  for (std::string_view line :
       {"", " ", "\t \t", "\r", " \t\r", "#", "# a comment", "   # indented", "\t#\ttabbed",
        "# 0 1 2 4 - <FAP 3 1 2 1>", "# UTF-8: é ü ñ 日本", "# CRLF\r"}) {
    TextReader reader;
    TextEvent out = kSentinel;
    bool has_event = true;
    const TextResult result = reader.read_line(line, out, has_event);
    EXPECT_TRUE(result.ok()) << '"' << line << "\": " << to_string(result.status);
    EXPECT_FALSE(has_event) << line;
    EXPECT_EQ(out, kSentinel) << line;
  }
}

TEST(ReadLine, TrailingCommentEndsTheLineWhereverItStarts) {
  const TextEvent expected = phoneme_event(5, 1, 2, 4, "S", {fap(3, 1, 2, 1)});
  for (std::string_view line :
       {"5 1 2 4 S <FAP 3 1 2 1> # comment", "5 1 2 4 S <FAP 3 1 2 1># comment",
        "5 1 2 4 S <FAP 3 1 2 1>#<FAP 4 1 2 1>", "5 1 2 4 S <FAP 3 1 2 1>\t#"}) {
    EXPECT_EQ(read_one(line), expected) << line;
  }
  EXPECT_EQ(read_one("5 1 2 4 S# comment"), phoneme_event(5, 1, 2, 4, "S"));
  EXPECT_EQ(read_one("5 1 2 4 -#<FAP 3 1 2 1>"), phoneme_event(5, 1, 2, 4));
}

TEST(ReadLine, CommentInsideABookmarkCutsIt) {
  expect_errors(
      {{"5 1 2 4 - <FAP 3 1 # 2 1>", TextStatus::kBadBookmark, 10, BookmarkStatus::kUnterminated}});
}

TEST(ReadLine, CrlfLineEndReadsLikeLf) {
  for (std::string_view line : {"5 1 2 4 S <FAP 3 1 2 1>", "5 state complete <FAP 3 1 2 1>",
                                "5 1 2 4 SWE", "5 state recovered"}) {
    EXPECT_EQ(read_one(std::string(line) + "\r"), read_one(line)) << line;
  }
}

TEST(ReadLine, OnlyOneTrailingCrIsALineEnd) {
  expect_errors({
      {"5 1 2 4 -\r\r", TextStatus::kBadFlags, 8},
      {"5\r1 2 4 -", TextStatus::kBadTime, 0},
  });
}

TEST(ReadLine, TabsAndRunsOfWhiteSpaceSeparateFieldsLikeOneSpace) {
  const TextEvent expected = phoneme_event(5, 1, 2, 4, "W", {fap(3, 1, 2, 1), fap(4, 5, 6, 2)});
  for (std::string_view line :
       {"5 1 2 4 W <FAP 3 1 2 1><FAP 4 5 6 2>", "5\t1\t2\t4\tW\t<FAP 3 1 2 1>\t<FAP 4 5 6 2>",
        "  5   1 \t 2\t\t4  W   <FAP 3 1 2 1>   <FAP 4 5 6 2>  ",
        "\t5 1 2 4 W <FAP 3 1 2 1> <FAP 4 5 6 2>\t"}) {
    EXPECT_EQ(read_one(line), expected) << '"' << line << '"';
  }
}

TEST(ReadLine, ErrorColumnsCountLeadingWhiteSpace) {
  expect_errors({
      {"  x 1 2 4 -", TextStatus::kBadTime, 2},
      {"\t0\t\t256 2 4 -", TextStatus::kBadSymbol, 4},
      {"0 1  2   999 -", TextStatus::kBadF0, 9},
  });
}

TEST(ReadLine, BookmarkErrorsCarryTheirStatusAtTheLineColumn) {
  expect_errors({
      {"5 1 2 4 - <FAP 99 1 2 1>", TextStatus::kBadBookmark, 15, BookmarkStatus::kUnknownFap},
      {"5 1 2 4 -   <FAP 3 1 2 4>", TextStatus::kBadBookmark, 23, BookmarkStatus::kCurveOutOfRange},
      {"5 1 2 4 - <FAP 3 1 16384 1>", TextStatus::kBadBookmark, 19,
       BookmarkStatus::kTransitionOutOfRange},
      {"5 1 2 4 - <FAP 3 1 2 1><FAP 3 1 2", TextStatus::kBadBookmark, 23,
       BookmarkStatus::kUnterminated},
      {"5 1 2 4 - <FAP 2 7 1 0 0 2 1>", TextStatus::kBadBookmark, 17,
       BookmarkStatus::kExpressionOutOfRange},
      {"5 1 2 4 - extra", TextStatus::kBadBookmark, 10, BookmarkStatus::kUnexpectedText},
      {"5 1 2 4 - <FAP 3 1 2 1> x", TextStatus::kBadBookmark, 24, BookmarkStatus::kUnexpectedText},
      {"5 state complete <FAP 3 2529601 2 1>", TextStatus::kBadBookmark, 24,
       BookmarkStatus::kAmplitudeOutOfRange},
      {"5 state recovered <FAP 3 1 2 1> oops", TextStatus::kBadBookmark, 32,
       BookmarkStatus::kUnexpectedText},
      {"5 state recovered <FAP 3 1 2>", TextStatus::kBadBookmark, 28, BookmarkStatus::kBadNumber},
  });
}

std::string bookmarks(int count) {
  std::string text;
  for (int i = 0; i < count; ++i) text += "<FAP 3 1 2 1>";
  return text;
}

// 40 <FAP 2 ...> bookmarks give 80 FAPs, which the canonical form writes as 80 bookmarks:
// a line takes any number, so everything written reads back.
TEST(ReadLine, PhonemeTakesTheEightyBookmarksOfFortyExpressionPairs) {
  EXPECT_EQ(read_one("0 1 2 4 - " + bookmarks(80)).event.faps.size(), 80u);
}

TEST(ReadLine, StateListsMoreThanFortyBookmarks) {
  std::string line = "0 state complete ";
  std::vector<Fap> expected;
  for (int index = kMinFapIndex; index <= kMaxFapIndex; ++index) {
    line += "<FAP " + std::to_string(index) + " 9 0 1>";
    expected.push_back(fap(index, 9, 0, 1));
  }
  EXPECT_EQ(read_one(line).event.faps, expected);
}

TEST(ReadLine, ExpressionBookmarkGivesTwoFaps) {
  EXPECT_EQ(read_one("0 1 2 4 - <FAP 2 1 40 2 30 2000 3>").event.faps,
            (std::vector{fap(69, 40, 2000, 3), fap(70, 30, 2000, 3)}));
  EXPECT_EQ(read_one("0 state recovered <FAP 2 1 40 2 30 2000 3>").event.faps,
            (std::vector{fap(69, 40, 2000, 3), fap(70, 30, 2000, 3)}));
}

TEST(ReadLine, StateLinesOfBothKindsWithAndWithoutFaps) {
  EXPECT_EQ(read_one("10 state recovered"), state_event(10, PFAP_EVENT_RECOVERED));
  EXPECT_EQ(read_one("10 state complete"), state_event(10, PFAP_EVENT_COMPLETE));
  EXPECT_EQ(read_one("10 state recovered <FAP 3 -5 100 2>"),
            state_event(10, PFAP_EVENT_RECOVERED, {fap(3, -5, 100, 2)}));
  EXPECT_EQ(read_one("10 state complete <FAP 3 -5 100 2> <FAP 74 1 0 3>"),
            state_event(10, PFAP_EVENT_COMPLETE, {fap(3, -5, 100, 2), fap(74, 1, 0, 3)}));
}

TEST(ReadLine, StateKindAndKeywordAreCaseSensitive) {
  expect_errors({
      {"10 state Complete", TextStatus::kBadStateKind, 9},
      {"10 state done <FAP 3 1 2 1>", TextStatus::kBadStateKind, 9},
      {"10 state <FAP 3 1 2 1>", TextStatus::kBadStateKind, 9},
      {"10 State complete", TextStatus::kBadSymbol, 3},
      {"10 states complete", TextStatus::kBadSymbol, 3},
  });
}

// Reads lines in order into one reader; each is expected to succeed or fail as given.
struct StreamLine {
  std::string_view line;
  TextStatus status = TextStatus::kOk;
  bool sentence_start = false;  // for phoneme lines that succeed
};

void expect_stream(std::initializer_list<StreamLine> lines) {
  TextReader reader;
  for (const StreamLine& l : lines) {
    SCOPED_TRACE(::testing::Message() << '"' << l.line << '"');
    TextEvent out;
    bool has_event = false;
    const TextResult result = reader.read_line(l.line, out, has_event);
    EXPECT_EQ(result.status, l.status) << to_string(result.status);
    if (has_event && out.event.kind == PFAP_EVENT_PHONEME) {
      EXPECT_EQ(out.event.sentence_start, l.sentence_start);
    }
    if (has_event && out.event.kind != PFAP_EVENT_PHONEME) {
      EXPECT_FALSE(out.event.sentence_start);
    }
  }
}

TEST(TextReader, EqualTimesAndGapsAreAllowedEarlierIsRefused) {
  expect_stream({
      {"100 1 2 4 -", TextStatus::kOk, true},
      {"100 1 2 4 -"},
      {"5000 1 2 4 -"},
      {"4999 1 2 4 -", TextStatus::kTimeGoesBack},
      {"5000 1 2 4 -"},
  });
}

TEST(TextReader, StateLinesAreInTheTimeOrderToo) {
  expect_stream({
      {"100 state complete"},
      {"99 1 2 4 -", TextStatus::kTimeGoesBack},
      {"100 1 2 4 -", TextStatus::kOk, true},
      {"99 state recovered", TextStatus::kTimeGoesBack},
      {"150 state recovered"},
      {"149 1 2 4 -", TextStatus::kTimeGoesBack},
  });
}

TEST(TextReader, TimeGoesBackIsReportedAtTheTime) {
  TextReader reader;
  TextEvent out;
  bool has_event = false;
  ASSERT_TRUE(reader.read_line("100 1 2 4 -", out, has_event).ok());
  const TextResult result = reader.read_line("  99 1 2 4 -", out, has_event);
  EXPECT_EQ(result.status, TextStatus::kTimeGoesBack);
  EXPECT_EQ(result.column, 2u);
}

TEST(TextReader, SentenceStartsAtTheFirstPhonemeAndAfterEndOfText) {
  expect_stream({
      {"0 1 2 4 W", TextStatus::kOk, true},
      {"10 1 2 4 -"},
      {"20 1 2 4 E"},
      {"30 1 2 4 W", TextStatus::kOk, true},
      {"40 1 2 4 SWE"},
      {"50 1 2 4 SWE", TextStatus::kOk, true},
      {"60 1 2 4 -", TextStatus::kOk, true},
      {"70 1 2 4 -"},
  });
}

TEST(TextReader, StateLinesDoNotChangeSentenceStarts) {
  expect_stream({
      {"0 state complete <FAP 3 1 2 1>"},
      {"0 1 2 4 E", TextStatus::kOk, true},
      {"5 state recovered"},
      {"10 1 2 4 -", TextStatus::kOk, true},
      {"15 state complete"},
      {"20 1 2 4 -"},
  });
}

TEST(TextReader, ErrorLinesChangeNeitherTimeNorSentence) {
  expect_stream({
      {"0 1 2 4 -", TextStatus::kOk, true},
      {"100 1 2 4 E <FAP 1 1 2 1>", TextStatus::kBadBookmark},
      {"100 1 2 4 SWE WS", TextStatus::kBadBookmark},
      {"100 state complete <FAP", TextStatus::kBadBookmark},
      {"50 1 2 4 -"},  // the error lines' time 100 was not kept
  });
}

TEST(TextReader, BlankAndCommentLinesKeepTimeAndSentence) {
  expect_stream({
      {"100 1 2 4 E", TextStatus::kOk, true},
      {""},
      {"# 0 1 2 4 -"},
      {"99 1 2 4 -", TextStatus::kTimeGoesBack},
      {"100 1 2 4 -", TextStatus::kOk, true},
  });
}

TEST(TextReader, ResetReturnsToTheStreamStart) {
  TextReader reader;
  TextEvent out;
  bool has_event = false;
  ASSERT_TRUE(reader.read_line("500 1 2 4 -", out, has_event).ok());
  ASSERT_TRUE(reader.read_line("600 1 2 4 -", out, has_event).ok());
  ASSERT_FALSE(out.event.sentence_start);
  reader.reset();
  ASSERT_TRUE(reader.read_line("0 1 2 4 -", out, has_event).ok());
  EXPECT_EQ(out.time_ms, 0);
  EXPECT_TRUE(out.event.sentence_start);
}

TEST(TextStatus, EveryStatusHasItsOwnLowercasePhrase) {
  std::set<std::string> phrases;
  for (int i = 0; i <= static_cast<int>(TextStatus::kBadBookmark); ++i) {
    const std::string phrase = to_string(static_cast<TextStatus>(i));
    EXPECT_FALSE(phrase.empty());
    for (char c : phrase) EXPECT_FALSE(c >= 'A' && c <= 'Z') << phrase;
    EXPECT_TRUE(phrases.insert(phrase).second) << phrase;
  }
  EXPECT_STREQ(to_string(TextStatus::kOk), "ok");
}

TEST(FormatTextLine, WritesTheCanonicalLine) {
  struct Case {
    TextEvent event;
    std::string_view line;
  };
  const Case cases[] = {
      {phoneme_event(0, 0, 0, 0), "0 0 0 0 -"},
      {phoneme_event(120, 17, 85, 200, "SW"), "120 17 85 200 SW"},
      {phoneme_event(1, 2, 3, 5, "E"), "1 2 3 6 E"},  // odd Hz are written as 2 × code
      {phoneme_event(9223372032759, 255, 4095, 510, "SWE"), "9223372032759 255 4095 510 SWE"},
      {phoneme_event(5, 1, 2, 4, "W", {fap(3, -120, 500, 2)}), "5 1 2 4 W <FAP 3 -120 500 2>"},
      {phoneme_event(5, 1, 2, 4, "", {fap(69, 40, 2000, 3), fap(70, 30, 2000, 3)}),
       "5 1 2 4 - <FAP 69 40 2000 3><FAP 70 30 2000 3>"},
      {state_event(10, PFAP_EVENT_RECOVERED), "10 state recovered"},
      {state_event(10, PFAP_EVENT_COMPLETE), "10 state complete"},
      {state_event(10, PFAP_EVENT_RECOVERED, {fap(74, 2529600, 16383, 1)}),
       "10 state recovered <FAP 74 2529600 16383 1>"},
      {state_event(10, PFAP_EVENT_COMPLETE, {fap(3, -2529600, 0, 3), fap(4, 1, 2, 1)}),
       "10 state complete <FAP 3 -2529600 0 3><FAP 4 1 2 1>"},
  };
  for (const Case& c : cases) EXPECT_EQ(format(c.event), c.line);
}

TEST(FormatTextLine, IgnoresSentenceStartUncertainAndAStateEventsPhoneme) {
  TextEvent event = phoneme_event(5, 1, 2, 4);
  event.event.sentence_start = true;
  event.event.uncertain = true;
  EXPECT_EQ(format(event), "5 1 2 4 -");

  event.event.kind = PFAP_EVENT_COMPLETE;
  EXPECT_EQ(format(event), "5 state complete");
}

TEST(FormatTextLine, AppendsToWhatIsThere) {
  std::string out = "x";
  format_text_line(phoneme_event(5, 1, 2, 4), out);
  EXPECT_EQ(out, "x5 1 2 4 -");
}

TEST(FormatTextLine, NonCanonicalLinesComeBackCanonical) {
  struct Case {
    std::string_view line, canonical;
  };
  for (const Case& c :
       {Case{"007 +1  2\t3 SW <FAP 2 1 40 2 30 2000 3> # c",
             "7 1 2 4 SW <FAP 69 40 2000 3><FAP 70 30 2000 3>"},
        Case{" 5 1 2 4 -   < FAP +3 -0 02 1 >\r", "5 1 2 4 - <FAP 3 0 2 1>"},
        Case{"5 state complete\t<FAP 2 0 0 6 5 1 1>", "5 state complete <FAP 74 5 1 1>"},
        Case{"5 state recovered   ", "5 state recovered"}}) {
    EXPECT_EQ(format(read_one(c.line)), c.canonical) << c.line;
  }
}

TEST(RoundTrip, CanonicalLinesReadAndFormatToThemselves) {
  for (std::string_view line :
       {"0 0 0 0 -", "120 17 85 200 SW", "9223372032759 255 4095 510 SWE", "5 1 2 4 E",
        "5 1 2 4 SE <FAP 3 -120 500 2>", "5 1 2 4 WE <FAP 69 40 2000 3><FAP 70 30 2000 3>",
        "10 state recovered", "10 state complete", "10 state recovered <FAP 74 2529600 16383 1>",
        "10 state complete <FAP 3 -2529600 0 3><FAP 4 1 2 1>"}) {
    EXPECT_EQ(format(read_one(line)), line);
  }
}

// A random stream of valid events in time order, with the sentence starts a reader must
// find: the first phoneme and each one after end of text.
std::vector<TextEvent> random_stream(uint32_t seed, int count) {
  testing::RandomMarkup random(seed);
  std::vector<TextEvent> events;
  int64_t time_ms = random.chance(0.1) ? 9223372032759 - 1000000 : 0;
  bool starts_sentence = true;
  for (int i = 0; i < count; ++i) {
    TextEvent e;
    time_ms += random.chance(0.2) ? 0 : random.uniform(1, 5000);
    e.time_ms = time_ms;
    const int kind = random.uniform(0, 9);
    e.event.kind = kind == 0   ? PFAP_EVENT_RECOVERED
                   : kind == 1 ? PFAP_EVENT_COMPLETE
                               : PFAP_EVENT_PHONEME;
    // States may list every FAP; a phoneme at most the 40 bookmarks MPEG-4 allows.
    const int max_faps = e.event.kind == PFAP_EVENT_PHONEME ? kMaxBookmarksPerPhoneme : 80;
    const int faps = random.chance(0.3) ? 0 : random.uniform(1, max_faps);
    for (int j = 0; j < faps; ++j) e.event.faps.push_back(random.fap());
    if (e.event.kind == PFAP_EVENT_PHONEME) {
      e.event.phoneme = random.phoneme();
      e.event.phoneme.end_of_text = random.chance(0.2);
      e.event.sentence_start = starts_sentence;
      starts_sentence = e.event.phoneme.end_of_text;
    }
    events.push_back(std::move(e));
  }
  return events;
}

TEST(RoundTrip, ReadingFormattedRandomEventsGivesThemBack) {
  for (uint32_t seed = 1; seed <= 50; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    TextReader reader;
    for (const TextEvent& event : random_stream(seed, 200)) {
      const std::string line = format(event);
      TextEvent out;
      bool has_event = false;
      const TextResult result = reader.read_line(line, out, has_event);
      ASSERT_TRUE(result.ok()) << line << ": " << to_string(result.status) << " at "
                               << result.column;
      ASSERT_TRUE(has_event);
      ASSERT_EQ(out, event) << line;
    }
  }
}

TEST(RoundTrip, EveryPrefixOfALineIsReadWithinTheLine) {
  // Cut anywhere, a line reads as an event or fails at a column inside it; run under a
  // sanitizer this also shows nothing past the end is read.
  const std::string lines[] = {"120 17 85 200 SWE <FAP 2 1 40 2 30 2000 3> <FAP 3 1 2 1> # c",
                               "10 state complete <FAP 3 -2529600 0 3><FAP 4 1 2 1>\r"};
  for (const std::string& line : lines) {
    for (size_t size = 0; size <= line.size(); ++size) {
      // A heap copy of exactly `size` bytes, so that reading past it is a heap overflow (a short
      // std::string keeps its bytes inline, with a NUL after them).
      const std::vector<char> bytes(line.begin(), line.begin() + static_cast<long>(size));
      const std::string_view prefix(bytes.data(), bytes.size());
      TextReader reader;
      TextEvent out;
      bool has_event = false;
      const TextResult result = reader.read_line(prefix, out, has_event);
      EXPECT_LE(result.column, prefix.size()) << '"' << prefix << '"';
      EXPECT_EQ(has_event, result.ok() && prefix.find_first_not_of(" \t\r") < prefix.find('#'))
          << '"' << prefix << '"';
    }
  }
}

}  // namespace
}  // namespace pfap
