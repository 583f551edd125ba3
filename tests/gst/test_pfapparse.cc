// SPDX-License-Identifier: LGPL-2.1-or-later
// pfaptextparse: .pfap text in, one application/x-pfap buffer per event out.
#include <glib/gstdio.h>
#include <gst/check/gstharness.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <random>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "element_harness.h"
#include "pfap/markup.h"
#include "pfap/model.h"
#include "pfap_buffers.h"
#include "pipeline.h"
#include "temp_dir.h"

namespace {

using pfap::Curve;
using pfap::Fap;
using pfap::testing::Event;

constexpr GstClockTime kMs = GST_MSECOND;

// Phonemes over two sentences (E ends the first), a state, comments, a blank line and a
// "\r\n" line end.
constexpr std::string_view kText =
    "# hello\n"
    "0 12 80 120 SW <FAP 3 100 200 1>\n"
    "\n"
    "80 7 60 130 - # a comment after the fields\n"
    "140 9 100 110 E <FAP 4 -20 50 2> <FAP 5 7 0 3>\r\n"
    "240 state complete <FAP 3 0 0 1>\n"
    "240 12 40 100 W\n"
    "280 state recovered\n"
    "300 1 20 90 -\n";

bool contains(const std::string& text, std::string_view part) {
  return text.find(part) != std::string::npos;
}

GstBuffer* text_buffer(std::string_view text) {
  return gst_buffer_new_memdup(text.data(), text.size());
}

class Parser : public pfap::testing::ElementHarness {
 public:
  explicit Parser(bool skip_bad_lines = false) : ElementHarness("pfaptextparse") {
    g_object_set(h_->element, "skip-bad-lines", skip_bad_lines, nullptr);
    gst_harness_set_src_caps_str(h_, "text/x-raw, format=(string)utf8");
  }

  GstFlowReturn push(std::string_view text) { return gst_harness_push(h_, text_buffer(text)); }
  // `text` in chunks of the given sizes, the last one taking what is left.
  void push_chunks(std::string_view text, const std::vector<size_t>& sizes) {
    for (size_t size : sizes) {
      if (text.empty()) break;
      const size_t n = std::min(size, text.size());
      ASSERT_EQ(push(text.substr(0, n)), GST_FLOW_OK);
      text.remove_prefix(n);
    }
    if (!text.empty()) {
      ASSERT_EQ(push(text), GST_FLOW_OK);
    }
  }
  bool eos() { return gst_harness_push_event(h_, gst_event_new_eos()); }

  // Every event output so far.
  std::vector<Event> pull_all() {
    std::vector<Event> events;
    while (GstBuffer* buffer = gst_harness_try_pull(h_)) {
      events.push_back(pfap::testing::read_event(buffer));
      gst_buffer_unref(buffer);
    }
    return events;
  }
  // The types of the events output so far, in order.
  std::vector<GstEventType> pull_event_types() {
    std::vector<GstEventType> types;
    while (GstEvent* event = gst_harness_try_pull_event(h_)) {
      types.push_back(GST_EVENT_TYPE(event));
      gst_event_unref(event);
    }
    return types;
  }
  guint64 bad_lines() {
    guint64 n = 0;
    g_object_get(h_->element, "bad-lines", &n, nullptr);
    return n;
  }
};

std::vector<Event> parse(std::string_view text) {
  Parser p;
  EXPECT_EQ(p.push(text), GST_FLOW_OK);
  EXPECT_TRUE(p.eos());
  EXPECT_TRUE(p.errors().empty());
  return p.pull_all();
}

std::vector<GstClockTime> times(const std::vector<Event>& events) {
  std::vector<GstClockTime> out;
  for (const Event& e : events) out.push_back(e.pts);
  return out;
}

TEST(PfapParse, PhonemeLineBecomesOneBufferWithItsTimeDurationFlagsAndFaps) {
  const std::vector<Event> events = parse("250 12 80 120 SW <FAP 3 100 200 1> <FAP 48 -5 10 3>\n");
  ASSERT_EQ(events.size(), 1u);
  const Event& e = events[0];
  EXPECT_EQ(e.kind, PFAP_EVENT_PHONEME);
  EXPECT_EQ(e.phoneme.symbol, 12);
  EXPECT_EQ(e.phoneme.duration_ms, 80);
  EXPECT_EQ(e.phoneme.f0, 60);  // units of 2 Hz
  EXPECT_EQ(e.flags, PFAP_FLAG_STRESS | PFAP_FLAG_WORD_BEGIN | PFAP_FLAG_SENTENCE_START);
  EXPECT_EQ(e.faps,
            (std::vector<Fap>{{3, 100, 200, Curve::kLinear}, {48, -5, 10, Curve::kSpline}}));
  EXPECT_EQ(e.pts, 250 * kMs);
  EXPECT_EQ(e.duration, 80 * kMs);
  EXPECT_TRUE(e.discont);
}

TEST(PfapParse, StreamStartCapsAndOwnTimeSegmentFromZeroComeBeforeTheFirstBuffer) {
  Parser p;
  // Upstream's byte segment and times say nothing about the output times.
  GstSegment bytes;
  gst_segment_init(&bytes, GST_FORMAT_BYTES);
  bytes.start = 1000;
  ASSERT_TRUE(gst_harness_push_event(p.harness(), gst_event_new_segment(&bytes)));
  ASSERT_TRUE(gst_harness_push_event(p.harness(), gst_event_new_gap(5 * GST_SECOND, 0)));
  ASSERT_EQ(p.push("10 1 20 100 -\n"), GST_FLOW_OK);

  GstHarness* h = p.harness();
  GstCaps* caps = gst_pad_get_current_caps(h->sinkpad);
  ASSERT_NE(caps, nullptr);
  GstCaps* expected = gst_caps_from_string(PFAP_MARKUP_CAPS);
  EXPECT_TRUE(gst_caps_is_equal(caps, expected));
  gst_caps_unref(expected);
  gst_caps_unref(caps);

  GstEvent* start = gst_pad_get_sticky_event(h->sinkpad, GST_EVENT_STREAM_START, 0);
  ASSERT_NE(start, nullptr);
  GstStreamFlags flags;
  gst_event_parse_stream_flags(start, &flags);
  EXPECT_TRUE(flags & GST_STREAM_FLAG_SPARSE);
  gst_event_unref(start);

  std::vector<GstEventType> types = p.pull_event_types();
  EXPECT_EQ(types,
            (std::vector<GstEventType>{GST_EVENT_STREAM_START, GST_EVENT_CAPS, GST_EVENT_SEGMENT}));
  GstEvent* event = gst_pad_get_sticky_event(h->sinkpad, GST_EVENT_SEGMENT, 0);
  ASSERT_NE(event, nullptr);
  const GstSegment* segment = nullptr;
  gst_event_parse_segment(event, &segment);
  EXPECT_EQ(segment->format, GST_FORMAT_TIME);
  EXPECT_EQ(segment->start, 0u);
  EXPECT_EQ(segment->time, 0u);
  gst_event_unref(event);
  EXPECT_EQ(p.pull_all().size(), 1u);
}

TEST(PfapParse, SrcCapsQueryAnswersXPfap) {
  Parser p;
  GstPad* src = gst_element_get_static_pad(p.harness()->element, "src");
  GstCaps* caps = gst_pad_query_caps(src, nullptr);
  GstCaps* expected = gst_caps_from_string(PFAP_MARKUP_CAPS);
  EXPECT_TRUE(gst_caps_is_equal(caps, expected));
  gst_caps_unref(expected);
  gst_caps_unref(caps);
  gst_object_unref(src);
}

TEST(PfapParse, AlphabetPropertyBecomesACapsField) {
  GstHarness* h = gst_harness_new("pfaptextparse");
  g_object_set(h->element, "alphabet", "x-pfap-arpabet", nullptr);
  gst_harness_set_src_caps_str(h, "text/x-raw, format=(string)utf8");
  const char line[] = "0 20 60 120 W\n";
  GstBuffer* in = gst_buffer_new_memdup(line, sizeof line - 1);
  ASSERT_EQ(gst_harness_push(h, in), GST_FLOW_OK);
  gst_buffer_unref(gst_harness_pull(h));
  GstCaps* caps = gst_pad_get_current_caps(h->sinkpad);
  ASSERT_NE(caps, nullptr);
  EXPECT_STREQ(gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet"),
               "x-pfap-arpabet");
  gst_caps_unref(caps);
  gst_harness_teardown(h);
}

TEST(PfapParse, AnyChunkingGivesTheSameEvents) {
  const std::vector<Event> whole = parse(kText);
  ASSERT_EQ(whole.size(), 7u);

  Parser bytes;
  bytes.push_chunks(kText, std::vector<size_t>(kText.size(), 1));
  ASSERT_TRUE(bytes.eos());
  EXPECT_EQ(bytes.pull_all(), whole);

  std::mt19937 random(7);
  std::uniform_int_distribution<size_t> size(1, 40);
  for (int round = 0; round < 20; ++round) {
    std::vector<size_t> sizes(kText.size());
    for (size_t& s : sizes) s = size(random);
    Parser p;
    p.push_chunks(kText, sizes);
    ASSERT_TRUE(p.eos());
    EXPECT_EQ(p.pull_all(), whole) << "round " << round;
    EXPECT_TRUE(p.errors().empty());
  }
}

TEST(PfapParse, LastLineWithoutLineEndIsReadAtEos) {
  Parser p;
  ASSERT_EQ(p.push("0 1 20 100 -\n20 2 30 100 -"), GST_FLOW_OK);
  EXPECT_EQ(times(p.pull_all()), (std::vector<GstClockTime>{0}));
  ASSERT_TRUE(p.eos());
  const std::vector<Event> last = p.pull_all();
  ASSERT_EQ(last.size(), 1u);
  EXPECT_EQ(last[0].phoneme.symbol, 2);
  EXPECT_EQ(last[0].pts, 20 * kMs);
  EXPECT_EQ(p.pull_event_types().back(), GST_EVENT_EOS);
}

TEST(PfapParse, CommentsBlankLinesAndCrLfGiveOnlyTheEvents) {
  const std::vector<Event> events =
      parse("# only a comment\n\n   \t\n0 1 20 100 - # note\r\n\r\n#\n");
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].phoneme.symbol, 1);
}

TEST(PfapParse, OnlyCommentsStillSendCapsAndSegmentBeforeEos) {
  Parser p;
  ASSERT_EQ(p.push("# nothing\n"), GST_FLOW_OK);
  ASSERT_TRUE(p.eos());
  EXPECT_TRUE(p.pull_all().empty());
  EXPECT_EQ(p.pull_event_types(), (std::vector<GstEventType>{GST_EVENT_STREAM_START, GST_EVENT_CAPS,
                                                             GST_EVENT_SEGMENT, GST_EVENT_EOS}));
}

TEST(PfapParse, PtsIsTheLineTimeAndDurationThePhonemes) {
  const std::vector<Event> events = parse(kText);
  EXPECT_EQ(times(events), (std::vector<GstClockTime>{0, 80 * kMs, 140 * kMs, 240 * kMs, 240 * kMs,
                                                      280 * kMs, 300 * kMs}));
  std::vector<GstClockTime> durations;
  for (const Event& e : events) durations.push_back(e.duration);
  EXPECT_EQ(durations,
            (std::vector<GstClockTime>{80 * kMs, 60 * kMs, 100 * kMs, GST_CLOCK_TIME_NONE, 40 * kMs,
                                       GST_CLOCK_TIME_NONE, 20 * kMs}));
  // Only the first buffer of the stream.
  EXPECT_TRUE(events[0].discont);
  EXPECT_TRUE(
      std::none_of(events.begin() + 1, events.end(), [](const Event& e) { return e.discont; }));
}

TEST(PfapParse, SentenceStartsAtTheFirstPhonemeAndAfterEndOfText) {
  std::vector<bool> starts;
  for (const Event& e : parse(kText)) {
    if (e.kind == PFAP_EVENT_PHONEME) starts.push_back((e.flags & PFAP_FLAG_SENTENCE_START) != 0);
  }
  EXPECT_EQ(starts, (std::vector<bool>{true, false, false, true, false}));
}

TEST(PfapParse, StateLinesGiveStateEventsWithTheirFaps) {
  const std::vector<Event> events =
      parse("100 state complete <FAP 3 50 0 1> <FAP 70 7 20 2>\n200 state recovered\n");
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, PFAP_EVENT_COMPLETE);
  EXPECT_EQ(events[0].faps,
            (std::vector<Fap>{{3, 50, 0, Curve::kLinear}, {70, 7, 20, Curve::kTriangle}}));
  EXPECT_EQ(events[0].pts, 100 * kMs);
  EXPECT_EQ(events[1].kind, PFAP_EVENT_RECOVERED);
  EXPECT_TRUE(events[1].faps.empty());
  EXPECT_EQ(events[1].duration, GST_CLOCK_TIME_NONE);
}

TEST(PfapParse, BadLineIsAnErrorNamingLineColumnAndProblem) {
  Parser p;
  EXPECT_EQ(p.push("0 1 20 100 -\n# two\n40 2 5000 100 -\n60 3 20 100 -\n"), GST_FLOW_ERROR);
  const std::vector<std::string> errors = p.errors();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_TRUE(contains(errors[0], "line 3, column 6: bad duration")) << errors[0];
  EXPECT_EQ(p.pull_all().size(), 1u);  // the line before it
}

TEST(PfapParse, BadBookmarkErrorSaysWhatIsWrongWithTheBookmark) {
  Parser p;
  EXPECT_EQ(p.push("0 1 20 100 - <FAP 3 100 200 9>\n"), GST_FLOW_ERROR);
  const std::vector<std::string> errors = p.errors();
  ASSERT_EQ(errors.size(), 1u);
  // The bookmark's own status follows; its column is the bookmark parser's to choose.
  EXPECT_TRUE(contains(errors[0], "line 1, column ")) << errors[0];
  const size_t what = errors[0].find(": bad bookmark: ");
  ASSERT_NE(what, std::string::npos) << errors[0];
  EXPECT_GT(errors[0].size(), what + std::string_view(": bad bookmark: ").size());
}

TEST(PfapParse, TimeGoingBackIsABadLine) {
  Parser p;
  EXPECT_EQ(p.push("100 1 20 100 -\n50 2 20 100 -\n"), GST_FLOW_ERROR);
  const std::vector<std::string> errors = p.errors();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_TRUE(contains(errors[0], "line 2, column 1: time goes back")) << errors[0];
}

TEST(PfapParse, InvalidUtf8IsABadLine) {
  Parser p;
  EXPECT_EQ(p.push("0 1 20 100 - # caf\xc3\xa9\n20 2 20 100 - # \xff\xfe\n"), GST_FLOW_ERROR);
  const std::vector<std::string> errors = p.errors();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_TRUE(contains(errors[0], "line 2, column 17: not UTF-8")) << errors[0];
  EXPECT_EQ(p.pull_all().size(), 1u);
}

TEST(PfapParse, TimeBeyondWhatGstClockTimeHoldsIsABadLine) {
  Parser p;
  EXPECT_EQ(p.push("9000000000000000 1 20 100 -\n"), GST_FLOW_ERROR);
  const std::vector<std::string> errors = p.errors();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_TRUE(contains(errors[0], "line 1, column 1: bad time")) << errors[0];
  EXPECT_TRUE(p.pull_all().empty());
}

TEST(PfapParse, BadLastLineAtEosIsAnErrorAndTheEosIsNotPassedOn) {
  Parser p;
  ASSERT_EQ(p.push("0 1 20 100 -\n20 x"), GST_FLOW_OK);
  EXPECT_FALSE(p.eos());
  const std::vector<std::string> errors = p.errors();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_TRUE(contains(errors[0], "line 2, column 4: bad phoneme symbol")) << errors[0];
  const std::vector<GstEventType> types = p.pull_event_types();
  EXPECT_EQ(std::count(types.begin(), types.end(), GST_EVENT_EOS), 0);
}

TEST(PfapParse, SkipBadLinesWarnsAndReadsTheLinesAfter) {
  Parser p(true);
  p.push_chunks(
      "0 1 20 100 -\n"
      "20 2 20 100 Q\n"
      "\xff\n"
      "40 3 20 100 E\n"
      "30 4 20 100 -\n"  // before the last good line
      "60 5 20 100 -\n"
      "80 6",
      {5, 5, 5, 5, 5, 5, 5, 5, 5, 5});
  ASSERT_TRUE(p.eos());
  // Warned at the 1st, 2nd and 4th bad line; the 3rd ("line 5, column 1: time goes back") only
  // counted.
  const std::vector<std::string> warnings = p.warnings();
  ASSERT_EQ(warnings.size(), 3u);
  EXPECT_TRUE(contains(warnings[0], "line 2, column 13: bad flags")) << warnings[0];
  EXPECT_TRUE(contains(warnings[1], "line 3, column 1: not UTF-8")) << warnings[1];
  EXPECT_TRUE(contains(warnings[2], "line 7, column 5: missing field")) << warnings[2];
  EXPECT_EQ(p.bad_lines(), 4u);
  EXPECT_TRUE(p.errors().empty());

  const std::vector<Event> events = p.pull_all();
  std::vector<int> symbols;
  for (const Event& e : events) symbols.push_back(e.phoneme.symbol);
  EXPECT_EQ(symbols, (std::vector<int>{1, 3, 5}));
  // A skipped line changes nothing: the sentence after E still starts at 5.
  EXPECT_TRUE(events[2].flags & PFAP_FLAG_SENTENCE_START);
  EXPECT_EQ(p.pull_event_types().back(), GST_EVENT_EOS);
}

// The outside tester's 10 MB of random bytes gave 38,741 warnings. 1 MB of them (seeded): every
// bad line counted, warnings at the 1st, 2nd, 4th, ... only (about log2 of the count).
TEST(PfapParse, RandomBytesGiveFewWarningsAndCountEveryBadLine) {
  Parser p(true);
  std::mt19937 random(22);
  std::string bytes(1 << 20, '\0');
  for (char& c : bytes) c = static_cast<char>(random());
  for (size_t at = 0; at < bytes.size(); at += 4096) {
    ASSERT_EQ(p.push(std::string_view(bytes).substr(at, 4096)), GST_FLOW_OK);
  }
  ASSERT_TRUE(p.eos());
  const guint64 bad = p.bad_lines();
  EXPECT_GT(bad, 1000u);
  const std::vector<std::string> warnings = p.warnings();
  size_t expected = 0;
  for (guint64 n = 1; n <= bad; n *= 2) ++expected;
  EXPECT_EQ(warnings.size(), expected) << bad << " bad lines";
  EXPECT_TRUE(p.errors().empty());
}

TEST(PfapParse, OverLongLineIsAnError) {
  Parser p;
  const std::string line(64 * 1024 + 1, ' ');
  EXPECT_EQ(p.push("0 1 20 100 -\n"), GST_FLOW_OK);
  EXPECT_EQ(p.push(line), GST_FLOW_ERROR);
  const std::vector<std::string> errors = p.errors();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_TRUE(contains(errors[0], "line 2, column 65537: longer than 65536 bytes")) << errors[0];
}

TEST(PfapParse, LineOfExactlyTheLimitIsRead) {
  std::string line = "0 1 20 100 - #";
  line.resize(64 * 1024, 'x');
  EXPECT_EQ(parse(line + "\n").size(), 1u);
}

TEST(PfapParse, OverLongLineIsSkippedWithSkipBadLinesWithoutKeepingIt) {
  Parser p(true);
  ASSERT_EQ(p.push("0 1 20 100 -\n# "), GST_FLOW_OK);
  // A megabyte without a line end, in 4096-byte chunks.
  const std::string chunk(4096, 'x');
  for (int i = 0; i < 256; ++i) ASSERT_EQ(p.push(chunk), GST_FLOW_OK);
  ASSERT_EQ(p.push("x\n20 2 20 100 -\n"), GST_FLOW_OK);
  ASSERT_TRUE(p.eos());
  const std::vector<std::string> warnings = p.warnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(contains(warnings[0], "line 2, column 65537: longer than 65536 bytes"))
      << warnings[0];
  EXPECT_EQ(times(p.pull_all()), (std::vector<GstClockTime>{0, 20 * kMs}));
}

TEST(PfapParse, FlushDropsTheTailAndStartsAgainFromLineOne) {
  Parser p;
  ASSERT_EQ(p.push("0 1 20 100 -\n200 2 20 100 -\n300 3 2"), GST_FLOW_OK);
  EXPECT_EQ(p.pull_all().size(), 2u);
  ASSERT_TRUE(gst_harness_push_event(p.harness(), gst_event_new_flush_start()));
  ASSERT_TRUE(gst_harness_push_event(p.harness(), gst_event_new_flush_stop(TRUE)));
  GstSegment bytes;  // as a source sends after a flush
  gst_segment_init(&bytes, GST_FORMAT_BYTES);
  ASSERT_TRUE(gst_harness_push_event(p.harness(), gst_event_new_segment(&bytes)));
  p.pull_event_types();

  // Earlier than before the flush, and "300 3 2" does not prefix it.
  ASSERT_EQ(p.push("50 4 20 100 -\n"), GST_FLOW_OK);
  const std::vector<Event> events = p.pull_all();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].phoneme.symbol, 4);
  EXPECT_EQ(events[0].pts, 50 * kMs);
  EXPECT_TRUE(events[0].flags & PFAP_FLAG_SENTENCE_START);
  EXPECT_TRUE(events[0].discont);
  EXPECT_EQ(p.pull_event_types(), (std::vector<GstEventType>{GST_EVENT_SEGMENT}));

  EXPECT_EQ(p.push("oops\n"), GST_FLOW_ERROR);
  const std::vector<std::string> errors = p.errors();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_TRUE(contains(errors[0], "line 2, column 1: bad time")) << errors[0];
}

TEST(PfapParse, SeekingIsRefused) {
  Parser p;
  GstPad* src = gst_element_get_static_pad(p.harness()->element, "src");
  GstQuery* query = gst_query_new_seeking(GST_FORMAT_TIME);
  ASSERT_TRUE(gst_pad_query(src, query));
  gboolean seekable = TRUE;
  gst_query_parse_seeking(query, nullptr, &seekable, nullptr, nullptr);
  EXPECT_FALSE(seekable);
  gst_query_unref(query);
  EXPECT_FALSE(
      gst_pad_send_event(src, gst_event_new_seek(1.0, GST_FORMAT_TIME, GST_SEEK_FLAG_FLUSH,
                                                 GST_SEEK_TYPE_SET, 0, GST_SEEK_TYPE_NONE, 0)));
  gst_object_unref(src);
}

// The events a pipeline's fakesink receives.
void on_handoff(GstElement*, GstBuffer* buffer, GstPad*, gpointer events) {
  static_cast<std::vector<Event>*>(events)->push_back(pfap::testing::read_event(buffer));
}

TEST(PfapParsePipeline, FilesrcReadsAFileOfManyBlocks) {
  std::string text = "# a file of several 4096-byte blocks, lines across their edges\n";
  constexpr int kLines = 600;
  for (int i = 0; i < kLines; ++i) {
    text += std::to_string(i * 20) + " " + std::to_string(i % 256) + " 20 120 " +
            (i % 10 == 9 ? "E" : "W") + " <FAP 3 " + std::to_string(i) + " 200 1>\n";
  }
  ASSERT_GT(text.size(), 3 * 4096u);
  gchar* path = nullptr;
  const gint fd = g_file_open_tmp("pfaptextparse-XXXXXX.pfap", &path, nullptr);
  ASSERT_GE(fd, 0);
  close(fd);
  ASSERT_TRUE(g_file_set_contents(path, text.data(), static_cast<gssize>(text.size()), nullptr));

  const std::string description =
      std::string("filesrc location=\"") + path +
      "\" ! pfaptextparse ! fakesink name=sink sync=false signal-handoffs=true";
  GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
  ASSERT_NE(pipeline, nullptr);
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  std::vector<Event> events;
  g_signal_connect(sink, "handoff", G_CALLBACK(on_handoff), &events);
  gst_object_unref(sink);

  ASSERT_NE(gst_element_set_state(pipeline, GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
  GstBus* bus = gst_element_get_bus(pipeline);
  GstMessage* message = gst_bus_timed_pop_filtered(
      bus, 10 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
  ASSERT_NE(message, nullptr);
  EXPECT_EQ(GST_MESSAGE_TYPE(message), GST_MESSAGE_EOS);
  gst_message_unref(message);
  gst_object_unref(bus);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
  g_unlink(path);
  g_free(path);

  ASSERT_EQ(events.size(), static_cast<size_t>(kLines));
  for (int i = 0; i < kLines; ++i) {
    const Event& e = events[i];
    EXPECT_EQ(e.pts, static_cast<GstClockTime>(i) * 20 * kMs) << "line " << i;
    EXPECT_EQ(e.phoneme.symbol, i % 256) << "line " << i;
    EXPECT_EQ(e.faps, (std::vector<Fap>{{3, i, 200, Curve::kLinear}})) << "line " << i;
    EXPECT_EQ((e.flags & PFAP_FLAG_SENTENCE_START) != 0, i % 10 == 0) << "line " << i;
  }
}

// Runs `filesrc location=PATH ! pfaptextparse ... ! fakesink` to its end: the first error's or
// warning's message (with `skip`: skip-bad-lines=true), or "" at EOS.
std::string run_file(const std::string& path, bool skip) {
  pfap::testing::Pipeline p("filesrc location=\"" + path + "\" ! pfaptextparse skip-bad-lines=" +
                            (skip ? "true" : "false") + " ! fakesink sync=false");
  if (!p.ok()) return p.error();
  if (std::string e = p.set_state(GST_STATE_PLAYING); !e.empty()) return e;
  return p.wait_eos(std::chrono::seconds(10), /*warnings=*/true);
}

TEST(PfapParsePipeline, BadLineFromAFileNamesTheFile) {
  pfap::testing::TempDir dir;
  const std::string path = dir.file("broken.pfap");
  const std::string text = "0 1 20 100 -\n40 2 5000 100 -\n";
  ASSERT_TRUE(g_file_set_contents(path.c_str(), text.data(), static_cast<gssize>(text.size()),
                                  nullptr));
  const std::string error = run_file(path, false);
  EXPECT_TRUE(contains(error, "line 2, column 6 of file \"" + path + "\": bad duration")) << error;
  const std::string warning = run_file(path, true);
  EXPECT_TRUE(contains(warning, "Skipped .pfap line 2, column 6 of file \"" + path + "\""))
      << warning;
}

TEST(PfapParsePipeline, ByteOrderMarkAtTheStartOfAFileIsSkipped) {
  pfap::testing::TempDir dir;
  const std::string path = dir.file("bom.pfap");
  const std::string text = "\xEF\xBB\xBF" "0 1 20 100 -\n20 2 20 100 E\n";
  ASSERT_TRUE(g_file_set_contents(path.c_str(), text.data(), static_cast<gssize>(text.size()),
                                  nullptr));
  EXPECT_EQ(run_file(path, false), "");
}

// Runs a gst-launch description to its end: "" at EOS, else the first error or warning.
std::string run(const std::string& description) {
  pfap::testing::Pipeline p(description);
  if (!p.ok()) return p.error();
  if (std::string e = p.set_state(GST_STATE_PLAYING); !e.empty()) return e;
  return p.wait_eos(std::chrono::seconds(10), /*warnings=*/true);
}

// The readers' names from before they were named pfap<format>parse, as the writers are
// pfap<format>enc (docs/elements.md, "Names"), still make the same element: rank none, so
// that autoplugging takes the new name, a description that names it, and the same text
// from the same file.
TEST(DeprecatedNames, OldReaderNamesMakeTheSameElement) {
  pfap::testing::TempDir dir;
  const std::string text = "0 1 20 100 W <FAP 3 100 20 1>\n20 2 30 100 E <FAP 3 0 30 1>\n";
  const std::string pfap = dir.file("in.pfap"), fap = dir.file("in.fap");
  ASSERT_TRUE(
      g_file_set_contents(pfap.c_str(), text.data(), static_cast<gssize>(text.size()), nullptr));
  ASSERT_EQ(run("filesrc location=\"" + pfap + "\" ! pfaptextparse ! pfapfapenc ! filesink " +
                "location=\"" + fap + "\""),
            "");
  for (const auto& [old_name, name, input] : {std::tuple{"pfapparse", "pfaptextparse", pfap},
                                              std::tuple{"fapparse", "pfapfapparse", fap}}) {
    GstElementFactory* old_factory = gst_element_factory_find(old_name);
    GstElementFactory* factory = gst_element_factory_find(name);
    ASSERT_NE(old_factory, nullptr) << old_name;
    ASSERT_NE(factory, nullptr) << name;
    EXPECT_EQ(gst_plugin_feature_get_rank(GST_PLUGIN_FEATURE(old_factory)), GST_RANK_NONE);
    EXPECT_EQ(std::string(
                  gst_element_factory_get_metadata(old_factory, GST_ELEMENT_METADATA_DESCRIPTION)),
              std::string("Deprecated name of ") + name +
                  ": the same element with rank none; use " + name);
    GstElement* element = gst_element_factory_create(old_factory, nullptr);
    ASSERT_NE(element, nullptr) << old_name;
    EXPECT_TRUE(g_type_is_a(G_OBJECT_TYPE(element), gst_element_factory_get_element_type(factory)))
        << old_name;
    EXPECT_EQ(gst_element_get_factory(element), old_factory) << old_name;
    // Default object names follow the name typed: `pfapparse0` from pfapparse,
    // `pfaptextparse0` from pfaptextparse.
    gchar* object_name = gst_element_get_name(element);
    EXPECT_EQ(std::string(object_name).rfind(old_name, 0), 0u) << object_name;
    EXPECT_EQ(std::string(object_name).find_first_of("0123456789"), std::string(old_name).size())
        << object_name;
    g_free(object_name);
    gst_object_unref(element);
    GstElement* renamed = gst_element_factory_create(factory, nullptr);
    object_name = gst_element_get_name(renamed);
    EXPECT_EQ(std::string(object_name).rfind(name, 0), 0u) << object_name;
    EXPECT_EQ(std::string(object_name).find_first_of("0123456789"), std::string(name).size())
        << object_name;
    g_free(object_name);
    gst_object_unref(renamed);

    std::string out[2];
    for (int i = 0; i < 2; ++i) {
      const std::string path = dir.file(std::string("out-") + (i ? name : old_name));
      EXPECT_EQ(run("filesrc location=\"" + input + "\" ! " + (i ? name : old_name) +
                    " ! pfaptextenc ! filesink location=\"" + path + "\""),
                "")
          << (i ? name : old_name);
      gchar* contents = nullptr;
      ASSERT_TRUE(g_file_get_contents(path.c_str(), &contents, nullptr, nullptr)) << path;
      out[i] = contents;
      g_free(contents);
    }
    EXPECT_FALSE(out[1].empty()) << name;
    EXPECT_EQ(out[0], out[1]) << old_name;
    gst_object_unref(old_factory);
    gst_object_unref(factory);
  }
}

}  // namespace
