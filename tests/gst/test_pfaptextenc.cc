// SPDX-License-Identifier: LGPL-2.1-or-later
// pfaptextenc: x-pfap buffers in, .pfap text lines out, checked as exact strings and read
// back with pfap::TextReader, the reader pfaptextparse uses.
#include <gst/check/gstharness.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "element_harness.h"
#include "pfap/markup.h"
#include "pfap/markup_event.h"
#include "pfap/text.h"
#include "pfap_buffers.h"

namespace {

using pfap::Curve;
using pfap::Fap;
using pfap::MarkupEvent;
using pfap::Phoneme;
using pfap::testing::markup_buffer;
using pfap::testing::phoneme_buffer;

constexpr GstClockTime kMs = GST_MSECOND;
constexpr GstClockTime kNone = GST_CLOCK_TIME_NONE;

Phoneme phoneme(uint8_t symbol, uint16_t duration_ms) { return {symbol, duration_ms, 60}; }

MarkupEvent state_event(PfapEventKind kind, std::vector<Fap> faps) {
  MarkupEvent event;
  event.kind = kind;
  event.faps = std::move(faps);
  return event;
}

// Reads `lines` (each ending in '\n') as pfaptextparse does; a line that does not read fails.
std::vector<pfap::TextEvent> read_back(const std::vector<std::string>& lines) {
  pfap::TextReader reader;
  std::vector<pfap::TextEvent> events;
  for (const std::string& line : lines) {
    EXPECT_TRUE(line.ends_with('\n')) << line;
    pfap::TextEvent event;
    bool has_event = false;
    const pfap::TextResult result =
        reader.read_line(std::string_view(line).substr(0, line.size() - 1), event, has_event);
    EXPECT_TRUE(result.ok()) << pfap::to_string(result.status) << " at " << result.column
                             << " in: " << line;
    EXPECT_TRUE(has_event) << line;
    events.push_back(event);
  }
  return events;
}

class PfapTextEncTest : public ::testing::Test, public pfap::testing::ElementHarness {
 protected:
  PfapTextEncTest() : ElementHarness("pfaptextenc") {
    gst_harness_set_src_caps_str(h_, PFAP_MARKUP_CAPS);
  }

  void push(GstBuffer* buffer) { ASSERT_EQ(gst_harness_push(h_, buffer), GST_FLOW_OK); }
  void push(const Phoneme& p, GstClockTime pts, std::vector<Fap> faps = {}) {
    push(phoneme_buffer(p, faps, pts, false));
  }
  void push_event(GstEvent* event) { ASSERT_TRUE(gst_harness_push_event(h_, event)); }

  // A TIME segment of `start`, `offset` and `base`.
  void push_segment(GstClockTime start, GstClockTime offset, GstClockTime base) {
    GstSegment segment;
    gst_segment_init(&segment, GST_FORMAT_TIME);
    segment.start = start;
    segment.offset = offset;
    segment.base = base;
    push_event(gst_event_new_segment(&segment));
  }

  void flush() {
    push_event(gst_event_new_flush_start());
    push_event(gst_event_new_flush_stop(TRUE));
    push_segment(0, 0, 0);  // a flush drops the segment
  }

  // Every line output so far, each from one buffer.
  std::vector<std::string> pull_lines() {
    std::vector<std::string> lines;
    while (GstBuffer* buffer = gst_harness_try_pull(h_)) {
      GstMapInfo map;
      EXPECT_TRUE(gst_buffer_map(buffer, &map, GST_MAP_READ));
      lines.emplace_back(reinterpret_cast<const char*>(map.data), map.size);
      gst_buffer_unmap(buffer, &map);
      gst_buffer_unref(buffer);
    }
    return lines;
  }

  // The next warning posted as "message | debug", or "" when there is none.
  std::string pop_warning() {
    GstMessage* message = gst_bus_pop_filtered(bus_, GST_MESSAGE_WARNING);
    if (message == nullptr) return {};
    GError* error = nullptr;
    gchar* debug = nullptr;
    gst_message_parse_warning(message, &error, &debug);
    std::string text = std::string(error->message) + " | " + (debug ? debug : "");
    g_error_free(error);
    g_free(debug);
    gst_message_unref(message);
    return text;
  }

};

TEST_F(PfapTextEncTest, OutputCapsAreUtf8Text) {
  push(phoneme(1, 10), 0);
  GstCaps* caps = gst_pad_get_current_caps(h_->sinkpad);
  ASSERT_NE(caps, nullptr);
  GstCaps* expected = gst_caps_from_string("text/x-raw, format=(string)utf8");
  EXPECT_TRUE(gst_caps_is_equal(caps, expected)) << gst_caps_to_string(caps);
  gst_caps_unref(expected);
  gst_caps_unref(caps);
}

TEST_F(PfapTextEncTest, PhonemeLinesHaveSymbolDurationF0InHzAndFlagsInOrderSWE) {
  const std::vector<Phoneme> phonemes = {
      {.symbol = 0, .duration_ms = 0, .f0 = 0},
      {.symbol = 255, .duration_ms = 4095, .f0 = 255, .stress = true},
      {.symbol = 7, .duration_ms = 80, .f0 = 60, .word_begin = true},
      {.symbol = 8, .duration_ms = 90, .f0 = 61, .end_of_text = true},
      {.symbol = 9, .duration_ms = 100, .f0 = 1, .stress = true, .word_begin = true},
      {.symbol = 10, .duration_ms = 110, .f0 = 2, .stress = true, .end_of_text = true},
      {.symbol = 11, .duration_ms = 120, .f0 = 3, .word_begin = true, .end_of_text = true},
      {.symbol = 12,
       .duration_ms = 130,
       .f0 = 4,
       .stress = true,
       .word_begin = true,
       .end_of_text = true},
  };
  GstClockTime pts = 0;
  for (const Phoneme& p : phonemes) {
    push(phoneme_buffer(p, {}, pts, true));  // sentence start is implied by the format
    pts += p.duration_ms * kMs;
  }
  const std::vector<std::string> lines = pull_lines();
  EXPECT_EQ(lines, (std::vector<std::string>{
                       "0 0 0 0 -\n",
                       "0 255 4095 510 S\n",
                       "4095 7 80 120 W\n",
                       "4175 8 90 122 E\n",
                       "4265 9 100 2 SW\n",
                       "4365 10 110 4 SE\n",
                       "4475 11 120 6 WE\n",
                       "4595 12 130 8 SWE\n",
                   }));
  const std::vector<pfap::TextEvent> read = read_back(lines);
  ASSERT_EQ(read.size(), phonemes.size());
  for (size_t i = 0; i < read.size(); ++i) EXPECT_EQ(read[i].event.phoneme, phonemes[i]) << i;
}

TEST_F(PfapTextEncTest, BookmarksAreWrittenOnePerFapFrom3To74IncludingExpressions) {
  const std::vector<Fap> faps = {
      {.index = 3, .amplitude = 100, .transition_ms = 0, .curve = Curve::kLinear},
      {.index = 68, .amplitude = -2529600, .transition_ms = 16383, .curve = Curve::kTriangle},
      {.index = 69, .amplitude = 40, .transition_ms = 200, .curve = Curve::kSpline},  // joy
      {.index = 74, .amplitude = 2529600, .transition_ms = 1, .curve = Curve::kLinear},
  };
  push(phoneme(42, 100), 0, faps);
  const std::vector<std::string> lines = pull_lines();
  ASSERT_EQ(lines, (std::vector<std::string>{"0 42 100 120 - <FAP 3 100 0 1><FAP 68 -2529600 "
                                             "16383 2><FAP 69 40 200 3><FAP 74 2529600 1 1>\n"}));
  EXPECT_EQ(read_back(lines).at(0).event.faps, faps);
}

TEST_F(PfapTextEncTest, StateEventsNameTheirKindWithOrWithoutFaps) {
  const std::vector<Fap> faps = {{.index = 19, .amplitude = -7, .transition_ms = 30},
                                 {.index = 70, .amplitude = 5, .transition_ms = 0}};
  push(markup_buffer(state_event(PFAP_EVENT_RECOVERED, faps), 0));
  push(markup_buffer(state_event(PFAP_EVENT_RECOVERED, {}), 10 * kMs));
  push(markup_buffer(state_event(PFAP_EVENT_COMPLETE, faps), 20 * kMs));
  push(markup_buffer(state_event(PFAP_EVENT_COMPLETE, {}), 30 * kMs));
  const std::vector<std::string> lines = pull_lines();
  EXPECT_EQ(lines, (std::vector<std::string>{
                       "0 state recovered <FAP 19 -7 30 1><FAP 70 5 0 1>\n",
                       "10 state recovered\n",
                       "20 state complete <FAP 19 -7 30 1><FAP 70 5 0 1>\n",
                       "30 state complete\n",
                   }));
  const std::vector<pfap::TextEvent> read = read_back(lines);
  ASSERT_EQ(read.size(), 4u);
  EXPECT_EQ(read[0].event, state_event(PFAP_EVENT_RECOVERED, faps));
  EXPECT_EQ(read[1].event, state_event(PFAP_EVENT_RECOVERED, {}));
  EXPECT_EQ(read[2].event, state_event(PFAP_EVENT_COMPLETE, faps));
  EXPECT_EQ(read[3].event, state_event(PFAP_EVENT_COMPLETE, {}));
}

// A file's times come back as they were: the first event at 5 s is written at 5000.
TEST_F(PfapTextEncTest, TimesAreStreamTimesSoAFirstEventAt5SIsWrittenAt5000) {
  push(phoneme(1, 100), 5 * GST_SECOND);
  push(phoneme(2, 100), 5 * GST_SECOND + 100 * kMs);
  push(markup_buffer(state_event(PFAP_EVENT_COMPLETE, {}), 7 * GST_SECOND));
  EXPECT_EQ(pull_lines(), (std::vector<std::string>{"5000 1 100 120 -\n", "5100 2 100 120 -\n",
                                                    "7000 state complete\n"}));
}

TEST_F(PfapTextEncTest, TimesAreTheFirstSegmentsStreamTimesAndANewSegmentGoesOnInRunningTime) {
  push_segment(10 * GST_SECOND, 2 * GST_SECOND, 3 * GST_SECOND);
  push(phoneme(1, 500), 12500 * kMs);      // stream time 2.5 s, running time 3.5 s
  push(phoneme(2, 100), 13 * GST_SECOND);  // 3 s, 4 s
  push_segment(0, 0, 5 * GST_SECOND);
  push(phoneme(3, 100), 250 * kMs);  // running time 5.25 s: 1.25 s after the first
  EXPECT_EQ(pull_lines(), (std::vector<std::string>{"2500 1 500 120 -\n", "3000 2 100 120 -\n",
                                                    "4250 3 100 120 -\n"}));
}

TEST_F(PfapTextEncTest, TimesRoundToTheNearestMs) {
  const GstClockTime start = 700'000;  // 0.7 ms
  for (GstClockTime offset : {GstClockTime{0}, GstClockTime{299'999}, GstClockTime{800'000},
                              GstClockTime{1'799'999}, GstClockTime{2'300'000}}) {
    push(phoneme(1, 0), start + offset);
  }
  EXPECT_EQ(pull_lines(),
            (std::vector<std::string>{"1 1 0 120 -\n", "1 1 0 120 -\n", "2 1 0 120 -\n",
                                      "2 1 0 120 -\n", "3 1 0 120 -\n"}));
}

TEST_F(PfapTextEncTest, EventWithoutPtsStartsWhereThePreviousEnded) {
  push(phoneme(1, 100), GST_SECOND);
  push(phoneme(2, 80), kNone);
  push(markup_buffer(state_event(PFAP_EVENT_RECOVERED, {}), kNone));
  push(phoneme(3, 40), kNone);
  push(phoneme(4, 10), GST_SECOND + 500 * kMs);
  EXPECT_EQ(pull_lines(), (std::vector<std::string>{"1000 1 100 120 -\n", "1100 2 80 120 -\n",
                                                    "1180 state recovered\n", "1180 3 40 120 -\n",
                                                    "1500 4 10 120 -\n"}));
}

TEST_F(PfapTextEncTest, FirstEventWithoutPtsIsWhereTheSegmentBegins) {
  push_segment(GST_SECOND, 0, 2 * GST_SECOND);
  push(phoneme(1, 100), kNone);                   // running time 2 s
  push(phoneme(2, 100), GST_SECOND + 500 * kMs);  // 2.5 s
  EXPECT_EQ(pull_lines(), (std::vector<std::string>{"0 1 100 120 -\n", "500 2 100 120 -\n"}));
}

TEST_F(PfapTextEncTest, OutputBuffersKeepTheInputPtsDurationAndDiscont) {
  push(phoneme(1, 100), 3 * GST_SECOND);
  GstBuffer* in = markup_buffer(state_event(PFAP_EVENT_COMPLETE, {}), kNone);
  GST_BUFFER_FLAG_SET(in, GST_BUFFER_FLAG_DISCONT);
  push(in);

  GstBuffer* out = gst_harness_pull(h_);
  EXPECT_EQ(GST_BUFFER_PTS(out), 3 * GST_SECOND);
  EXPECT_EQ(GST_BUFFER_DURATION(out), 100 * kMs);
  EXPECT_FALSE(GST_BUFFER_IS_DISCONT(out));
  gst_buffer_unref(out);
  out = gst_harness_pull(h_);
  EXPECT_EQ(GST_BUFFER_PTS(out), kNone);
  EXPECT_EQ(GST_BUFFER_DURATION(out), kNone);
  EXPECT_TRUE(GST_BUFFER_IS_DISCONT(out));
  gst_buffer_unref(out);
}

TEST_F(PfapTextEncTest, EarlierEventIsWrittenAtThePreviousTimeWithAWarning) {
  push(phoneme(1, 100), GST_SECOND);
  push(phoneme(2, 100), GST_SECOND + 200 * kMs);
  EXPECT_EQ(pop_warning(), "");
  push(phoneme(3, 100), GST_SECOND + 100 * kMs);
  EXPECT_NE(pop_warning().find("earlier than the one before"), std::string::npos);
  push(phoneme(4, 100), GST_SECOND + 150 * kMs);  // still before the 200 ms written last
  EXPECT_NE(pop_warning(), "");
  push(phoneme(5, 100), GST_SECOND + 300 * kMs);
  EXPECT_EQ(pop_warning(), "");

  const std::vector<std::string> lines = pull_lines();
  EXPECT_EQ(lines, (std::vector<std::string>{"1000 1 100 120 -\n", "1200 2 100 120 -\n",
                                             "1200 3 100 120 -\n", "1200 4 100 120 -\n",
                                             "1300 5 100 120 -\n"}));
  EXPECT_EQ(read_back(lines).size(), 5u);
}

TEST_F(PfapTextEncTest, EarlierEventsAreWarnedAboutAtThe1st2nd4th8thAndAllCounted) {
  // 2000 events in reverse time order: 1999 go back, 11 warnings (the 1st to the 1024th).
  for (int i = 1999; i >= 0; --i) push(phoneme(1, 10), static_cast<GstClockTime>(i) * 10 * kMs);
  EXPECT_EQ(pull_lines().size(), 2000u);
  size_t warnings = 0;
  while (!pop_warning().empty()) ++warnings;
  EXPECT_EQ(warnings, 11u);
  EXPECT_EQ(stat("earlier"), 1999u);
  EXPECT_EQ(stat("events"), 2000u);
}

TEST_F(PfapTextEncTest, MalformedBuffersAreWarnedAboutAtThe1st2nd4th8thAndAllCounted) {
  for (int i = 0; i < 20; ++i) {
    GstBuffer* bad = gst_buffer_new_allocate(nullptr, 3, nullptr);
    gst_buffer_memset(bad, 0, 0xff, 3);
    push(bad);
  }
  size_t warnings = 0;
  while (!pop_warning().empty()) ++warnings;
  EXPECT_EQ(warnings, 5u);
  EXPECT_EQ(stat("malformed"), 20u);
  EXPECT_EQ(stat("events"), 0u);
}

TEST_F(PfapTextEncTest, MalformedBufferIsDroppedWithAWarningAndTheNextWritten) {
  GstBuffer* bad = gst_buffer_new_allocate(nullptr, 3, nullptr);
  gst_buffer_memset(bad, 0, 0xff, 3);
  GST_BUFFER_PTS(bad) = GST_SECOND;
  push(bad);
  EXPECT_EQ(pull_lines(), std::vector<std::string>{});
  EXPECT_NE(pop_warning().find("malformed"), std::string::npos);

  push(phoneme(1, 100), 2 * GST_SECOND);
  EXPECT_EQ(pull_lines(), std::vector<std::string>{"2000 1 100 120 -\n"});
  EXPECT_EQ(pop_warning(), "");
}

TEST_F(PfapTextEncTest, NonTimeSegmentIsAnError) {
  GstSegment segment;
  gst_segment_init(&segment, GST_FORMAT_BYTES);
  gst_harness_push_event(h_, gst_event_new_segment(&segment));
  GstMessage* message = gst_bus_pop_filtered(bus_, GST_MESSAGE_ERROR);
  ASSERT_NE(message, nullptr);
  GError* error = nullptr;
  gst_message_parse_error(message, &error, nullptr);
  EXPECT_TRUE(g_error_matches(error, GST_STREAM_ERROR, GST_STREAM_ERROR_FORMAT));
  g_error_free(error);
  gst_message_unref(message);
}

TEST_F(PfapTextEncTest, UncertainEventEndsWithACommentReadersSkip) {
  MarkupEvent event;
  event.phoneme = phoneme(9, 70);
  event.uncertain = true;
  event.faps = {{.index = 5, .amplitude = 1, .transition_ms = 2}};
  push(markup_buffer(event, 0));
  const std::vector<std::string> lines = pull_lines();
  EXPECT_EQ(lines, std::vector<std::string>{"0 9 70 120 - <FAP 5 1 2 1> # uncertain\n"});
  event.uncertain = false;
  event.sentence_start = true;  // the first phoneme
  EXPECT_EQ(read_back(lines).at(0).event, event);
}

// After a flush the next segment is the first again: a seek to 5 s writes from 5000, and an
// earlier time than before the flush is no fault.
TEST_F(PfapTextEncTest, FlushTakesTheTimesFromTheNextSegment) {
  push(phoneme(1, 100), GST_SECOND);
  push(phoneme(2, 100), 8 * GST_SECOND);
  flush();
  push(phoneme(3, 100), 5 * GST_SECOND);
  push(phoneme(4, 100), 5 * GST_SECOND + 100 * kMs);
  EXPECT_EQ(pull_lines(), (std::vector<std::string>{"1000 1 100 120 -\n", "8000 2 100 120 -\n",
                                                    "5000 3 100 120 -\n", "5100 4 100 120 -\n"}));
  EXPECT_EQ(pop_warning(), "");
}

TEST_F(PfapTextEncTest, ReadyToPausedTakesTheTimesFromTheNextSegment) {
  push(phoneme(1, 100), GST_SECOND);
  push(phoneme(2, 100), 8 * GST_SECOND);
  ASSERT_EQ(gst_element_set_state(h_->element, GST_STATE_READY), GST_STATE_CHANGE_SUCCESS);
  ASSERT_EQ(gst_element_set_state(h_->element, GST_STATE_PLAYING), GST_STATE_CHANGE_SUCCESS);
  push(phoneme(3, 100), 5 * GST_SECOND);
  EXPECT_EQ(pull_lines(), (std::vector<std::string>{"1000 1 100 120 -\n", "8000 2 100 120 -\n",
                                                    "5000 3 100 120 -\n"}));
  EXPECT_EQ(pop_warning(), "");
}

TEST_F(PfapTextEncTest, LinesReadBackAsTheSameEventsWithSentencesFromEndOfText) {
  const Phoneme a{.symbol = 1, .duration_ms = 100, .f0 = 60, .word_begin = true};
  const Phoneme b{.symbol = 2, .duration_ms = 80, .f0 = 61, .end_of_text = true};
  const Phoneme c{.symbol = 3, .duration_ms = 90, .f0 = 62, .stress = true};
  const std::vector<Fap> faps = {{.index = 31, .amplitude = 80, .transition_ms = 120}};
  push(phoneme_buffer(a, faps, 40 * kMs, true));
  push(phoneme_buffer(b, {}, 140 * kMs, false));
  push(markup_buffer(state_event(PFAP_EVENT_RECOVERED, faps), 220 * kMs));
  push(phoneme_buffer(c, {}, 300 * kMs, true));

  const std::vector<pfap::TextEvent> read = read_back(pull_lines());
  ASSERT_EQ(read.size(), 4u);
  EXPECT_EQ(read[0], (pfap::TextEvent{40, {PFAP_EVENT_PHONEME, a, true, false, faps}}));
  EXPECT_EQ(read[1], (pfap::TextEvent{140, {PFAP_EVENT_PHONEME, b, false, false, {}}}));
  EXPECT_EQ(read[2], (pfap::TextEvent{220, state_event(PFAP_EVENT_RECOVERED, faps)}));
  EXPECT_EQ(read[3], (pfap::TextEvent{300, {PFAP_EVENT_PHONEME, c, true, false, {}}}));
}

}  // namespace
