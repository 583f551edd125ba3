// SPDX-License-Identifier: LGPL-2.1-or-later
// pfapmarksenc and pfapmarksparse: element behaviour with GstHarness, and the commands of
// docs/elements.md, "Speech marks", run as written against the files in docs/examples/.
#include <gst/check/gstharness.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "documented_commands.h"
#include "element_harness.h"
#include "pfap/markup.h"
#include "pfap/markup_event.h"
#include "pfap_buffers.h"
#include "pipeline.h"
#include "temp_dir.h"

namespace {

using namespace std::chrono_literals;
using pfap::Phoneme;
using pfap::testing::Pipeline;
using pfap::testing::pull_text;
using pfap::testing::read_file;
using pfap::testing::replace_all;
using pfap::testing::source_path;
using pfap::testing::TempDir;

constexpr GstClockTime kMs = GST_MSECOND;
constexpr std::array<const char*, 5> kElements{"pfapmarksenc", "pfapmarksparse", "pfaptextparse",
                                               "rtppfappay", "pfapface"};

// The messages of the bus's warnings (or errors), taken off it.
std::vector<std::string> messages(GstBus* bus, GstMessageType type) {
  std::vector<std::string> out;
  while (GstMessage* m = gst_bus_pop_filtered(bus, type)) {
    GError* error = nullptr;
    if (type == GST_MESSAGE_ERROR) {
      gst_message_parse_error(m, &error, nullptr);
    } else {
      gst_message_parse_warning(m, &error, nullptr);
    }
    out.push_back(error->message);
    g_error_free(error);
    gst_message_unref(m);
  }
  return out;
}

class HarnessTest : public ::testing::Test {
 protected:
  void make(const char* description) {
    h_ = gst_harness_new_parse(description);
    gst_element_set_bus(h_->element, bus_);
  }
  ~HarnessTest() override {
    if (h_ != nullptr) gst_harness_teardown(h_);
    gst_bus_set_flushing(bus_, TRUE);
    gst_object_unref(bus_);
  }
  GstHarness* h_ = nullptr;
  GstBus* bus_ = gst_bus_new();
};

using MarksEnc = HarnessTest;

Phoneme phoneme(uint8_t symbol, uint16_t duration_ms, bool word_begin = false,
                bool end_of_text = false) {
  Phoneme p{symbol, duration_ms, 60};
  p.word_begin = word_begin;
  p.end_of_text = end_of_text;
  return p;
}

TEST_F(MarksEnc, WritesPollyMarksPerUtterance) {
  make("pfapmarksenc format=polly");
  gst_harness_set_src_caps_str(h_, PFAP_MARKUP_CAPS ",alphabet=x-pfap-arpabet");
  // "HH AH" + "M" (end of text), then a second sentence starting 1 s in: "P" with no end.
  const GstClockTime base = 5000 * kMs;  // stream time: marks from 5 s
  gst_harness_push(h_, pfap::testing::phoneme_buffer(phoneme(16, 60, true), {}, base, true));
  gst_harness_push(h_, pfap::testing::phoneme_buffer(phoneme(3, 90), {}, base + 60 * kMs, false));
  EXPECT_EQ(pull_text(h_), "");  // the utterance is not over
  gst_harness_push(
      h_, pfap::testing::phoneme_buffer(phoneme(22, 80, true, true), {}, base + 150 * kMs, false));
  EXPECT_EQ(pull_text(h_),
            "{\"time\":5000,\"type\":\"sentence\",\"value\":\"HH-AH M\"}\n"
            "{\"time\":5000,\"type\":\"word\",\"value\":\"HH-AH\"}\n"
            "{\"time\":5000,\"type\":\"viseme\",\"value\":\"k\"}\n"
            "{\"time\":5060,\"type\":\"viseme\",\"value\":\"@\"}\n"
            "{\"time\":5150,\"type\":\"word\",\"value\":\"M\"}\n"
            "{\"time\":5150,\"type\":\"viseme\",\"value\":\"p\"}\n"
            "{\"time\":5230,\"type\":\"viseme\",\"value\":\"sil\"}\n");
  gst_harness_push(h_, pfap::testing::phoneme_buffer(phoneme(27, 70, true), {}, base + kMs * 1000,
                                                     true));
  gst_harness_push_event(h_, gst_event_new_eos());
  EXPECT_EQ(pull_text(h_),
            "{\"time\":6000,\"type\":\"sentence\",\"value\":\"P\"}\n"
            "{\"time\":6000,\"type\":\"word\",\"value\":\"P\"}\n"
            "{\"time\":6000,\"type\":\"viseme\",\"value\":\"p\"}\n"
            "{\"time\":6070,\"type\":\"viseme\",\"value\":\"sil\"}\n");
  EXPECT_TRUE(messages(bus_, GST_MESSAGE_WARNING).empty());
}

TEST_F(MarksEnc, UnknownAlphabetAndMalformedBuffersWarnAndGoOn) {
  make("pfapmarksenc format=azure");
  gst_harness_set_src_caps_str(h_, PFAP_MARKUP_CAPS ",alphabet=x-sampa");
  for (int i = 0; i < 5; ++i) {
    gst_harness_push(h_, pfap::testing::phoneme_buffer(phoneme(7, 100), {}, i * 100 * kMs, i == 0));
  }
  GstBuffer* bad = gst_buffer_new_allocate(nullptr, 3, nullptr);
  gst_buffer_memset(bad, 0, 0xff, 3);
  gst_harness_push(h_, bad);
  gst_harness_push(h_, pfap::testing::phoneme_buffer(phoneme(7, 100, false, true), {}, 500 * kMs,
                                                     false));
  const std::string text = pull_text(h_);
  // All six, each as the half-open mouth (Azure 4), then silence where speech ends.
  EXPECT_EQ(text.rfind("{\"audioOffset\":0,\"visemeId\":4}\n", 0), 0u) << text;
  EXPECT_NE(text.find("{\"audioOffset\":5000000,\"visemeId\":4}\n"
                      "{\"audioOffset\":6000000,\"visemeId\":0}\n"),
            std::string::npos)
      << text;
  const std::vector<std::string> warnings = messages(bus_, GST_MESSAGE_WARNING);
  // Rate-limited: the unknown phonemes at the 1st, 2nd, 4th of 6 buffers, one malformed.
  ASSERT_EQ(warnings.size(), 4u);
  EXPECT_NE(warnings[0].find("no known viseme"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[3].find("malformed"), std::string::npos) << warnings[3];
}

TEST_F(MarksEnc, ArkitFramesAtTheFrameRateEndAfterTheLastTransition) {
  make("pfapmarksenc format=arkit-csv frame-rate=20");
  gst_harness_set_src_caps_str(h_, PFAP_MARKUP_CAPS ",alphabet=x-pfap-arpabet");
  // A blink (FAP 19 to 1024 over 100 ms) with a 100 ms phoneme; frames every 50 ms.
  gst_harness_push(h_, pfap::testing::phoneme_buffer(phoneme(22, 100), {{19, 1024, 100}}, 0, true));
  gst_harness_push_event(h_, gst_event_new_eos());
  const std::string csv = pull_text(h_);
  std::istringstream lines(csv);
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(lines, line)) rows.push_back(line);
  ASSERT_EQ(rows.size(), 5u) << csv;  // header, 0, 50, 100, 150 ms (the mouth closes by 180)
  EXPECT_TRUE(rows[0].starts_with("time_ms,eyeBlinkLeft,"));
  EXPECT_TRUE(rows[1].starts_with("0.000,0.0000,"));
  EXPECT_TRUE(rows[2].starts_with("50.000,0.5000,"));
  EXPECT_TRUE(rows[3].starts_with("100.000,1.0000,"));
  // Each row: time, 52 weights, 3 angles.
  EXPECT_EQ(std::count(rows[2].begin(), rows[2].end(), ','), 55);
}

// frame-rate is a fraction, as GStreamer's framerates are; a whole number typed in a pipeline
// still parses (1.22 reads "30" as 30/1; a decimal it refuses, docs/elements.md).
TEST_F(MarksEnc, FrameRateIsAFractionAndWholeNumbersStillParse) {
  for (const auto& [typed, n, d] : {std::tuple{"30", 30, 1}, std::tuple{"30000/1001", 30000, 1001},
                                    std::tuple{"2997/100", 2997, 100}}) {
    GError* error = nullptr;
    GstElement* enc = gst_parse_launch(
        (std::string("pfapmarksenc format=arkit-csv frame-rate=") + typed).c_str(), &error);
    ASSERT_NE(enc, nullptr) << typed << ": " << (error ? error->message : "");
    EXPECT_EQ(error, nullptr) << typed << ": " << error->message;
    g_clear_error(&error);
    GValue rate = G_VALUE_INIT;
    g_value_init(&rate, GST_TYPE_FRACTION);
    g_object_get_property(G_OBJECT(enc), "frame-rate", &rate);
    EXPECT_EQ(gst_value_get_fraction_numerator(&rate), n) << typed;
    EXPECT_EQ(gst_value_get_fraction_denominator(&rate), d) << typed;
    g_value_unset(&rate);
    gst_object_unref(enc);
  }
  // At 30000/1001 the frames are 33.367 ms apart, not 33.333.
  make("pfapmarksenc format=arkit-csv frame-rate=30000/1001");
  gst_harness_set_src_caps_str(h_, PFAP_MARKUP_CAPS ",alphabet=x-pfap-arpabet");
  gst_harness_push(h_, pfap::testing::phoneme_buffer(phoneme(22, 100), {}, 0, true));
  gst_harness_push_event(h_, gst_event_new_eos());
  const std::string csv = pull_text(h_);
  EXPECT_NE(csv.find("\n33.367,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\n100.100,"), std::string::npos) << csv;
}

// Issue 27: 2,000 phonemes 11.6 days apart made 4.5 MB of arkit-json each at 240 frames/s.
TEST_F(MarksEnc, ArkitLongRestIsCutWithAWarning) {
  make("pfapmarksenc format=arkit-csv frame-rate=240");
  gst_harness_set_src_caps_str(h_, PFAP_MARKUP_CAPS ",alphabet=x-pfap-arpabet");
  constexpr GstClockTime kDay = 24 * 3600 * GST_SECOND;
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(gst_harness_push(
                  h_, pfap::testing::phoneme_buffer(phoneme(22, 100), {}, i * 12 * kDay, i == 0)),
              GST_FLOW_OK);
  }
  gst_harness_push_event(h_, gst_event_new_eos());
  const std::string csv = pull_text(h_);
  // Header; 284 frames (0 to 1.18 s) after each of the first 3, 44 after the last.
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 3 * 284 + 44);
  const std::vector<std::string> warnings = messages(bus_, GST_MESSAGE_WARNING);
  ASSERT_EQ(warnings.size(), 2u);  // at the 1st and 2nd of 3
  EXPECT_EQ(warnings[0],
            "A rest longer than 1000 ms: its frames after that are left out, and the next "
            "frame's time jumps.");
}

using MarksParse = HarnessTest;

// Every buffer the harness holds, as events.
std::vector<pfap::testing::Event> pull_events(GstHarness* h) {
  std::vector<pfap::testing::Event> events;
  while (GstBuffer* b = gst_harness_try_pull(h)) {
    events.push_back(pfap::testing::read_event(b));
    gst_buffer_unref(b);
  }
  return events;
}

TEST_F(MarksParse, PollyMarksByteByByte) {
  make("pfapmarksparse format=polly");
  const std::string text =
      "{\"time\":0,\"type\":\"sentence\",\"value\":\"Hi.\"}\n"
      "{\"time\":6,\"type\":\"word\",\"value\":\"Hi\"}\n"
      "{\"time\":6,\"type\":\"viseme\",\"value\":\"k\"}\r\n"
      "{\"time\":73,\"type\":\"viseme\",\"value\":\"a\"}\n"
      "{\"time\":300,\"type\":\"viseme\",\"value\":\"sil\"}";  // no line end at the last
  for (char c : text) {
    GstBuffer* b = gst_buffer_new_memdup(&c, 1);
    ASSERT_EQ(gst_harness_push(h_, b), GST_FLOW_OK);
  }
  gst_harness_push_event(h_, gst_event_new_eos());
  GstCaps* caps = gst_pad_get_current_caps(h_->sinkpad);
  ASSERT_NE(caps, nullptr);
  EXPECT_STREQ(gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet"),
               "x-pfap-polly-viseme");
  gst_caps_unref(caps);
  const std::vector<pfap::testing::Event> events = pull_events(h_);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].pts, 6 * kMs);
  EXPECT_EQ(events[0].duration, 67 * kMs);
  EXPECT_EQ(events[0].phoneme.symbol, 6);  // k
  EXPECT_TRUE(events[0].phoneme.word_begin);
  EXPECT_TRUE(events[0].flags & PFAP_FLAG_SENTENCE_START);
  EXPECT_TRUE(events[0].discont);
  EXPECT_EQ(events[1].pts, 73 * kMs);
  EXPECT_EQ(events[1].phoneme.symbol, 12);  // a
  EXPECT_EQ(events[2].pts, 300 * kMs);
  EXPECT_EQ(events[2].duration, 150 * kMs);  // the last viseme, with no end given
  EXPECT_TRUE(events[2].phoneme.end_of_text);
}

TEST_F(MarksParse, BadLineIsAnErrorNamingLineAndColumn) {
  make("pfapmarksparse format=azure");
  const std::string text =
      "{\"audioOffset\":0,\"visemeId\":0}\n"
      "{\"audioOffset\":500000,\"visemeId\":99}\n";
  EXPECT_EQ(gst_harness_push(h_, gst_buffer_new_memdup(text.data(), text.size())),
            GST_FLOW_ERROR);
  const std::vector<std::string> errors = messages(bus_, GST_MESSAGE_ERROR);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0], "Bad line 2, column 34: not a viseme of this format");
}

// Blank lines before the first mark count however they come: they were left uncounted when a
// buffer held nothing else.
TEST_F(MarksParse, BlankLinesInBuffersOfTheirOwnAreCounted) {
  make("pfapmarksparse format=azure");
  for (const std::string piece : {"\n", "  \r\n", "{\"audioOffset\":0,\"visemeId\":99}\n"}) {
    gst_harness_push(h_, gst_buffer_new_memdup(piece.data(), piece.size()));
  }
  const std::vector<std::string> errors = messages(bus_, GST_MESSAGE_ERROR);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0], "Bad line 3, column 29: not a viseme of this format");
}

// White space in buffers of its own before a Rhubarb JSON document is no line of TSV.
TEST_F(MarksParse, RhubarbJsonAfterBuffersOfWhiteSpaceIsADocument) {
  make("pfapmarksparse format=rhubarb");
  const std::string doc = "{\"mouthCues\":[{\"start\":0.0,\"end\":0.1,\"value\":\"A\"}]}";
  for (const std::string& piece : {std::string("\n"), std::string("  "), doc}) {
    ASSERT_EQ(gst_harness_push(h_, gst_buffer_new_memdup(piece.data(), piece.size())), GST_FLOW_OK);
  }
  gst_harness_push_event(h_, gst_event_new_eos());
  EXPECT_EQ(pull_events(h_).size(), 1u);
  EXPECT_TRUE(messages(bus_, GST_MESSAGE_ERROR).empty());
}

TEST_F(MarksParse, SkipBadLinesWarnsRateLimitedAndGoesOn) {
  make("pfapmarksparse format=rhubarb skip-bad-lines=true");
  std::string text = "0.00\tX\n";
  for (int i = 0; i < 5; ++i) text += "0.10\tZ\n";  // five bad shapes
  text += "0.10\tA\n0.30\tX\n";
  EXPECT_EQ(gst_harness_push(h_, gst_buffer_new_memdup(text.data(), text.size())), GST_FLOW_OK);
  gst_harness_push_event(h_, gst_event_new_eos());
  const std::vector<pfap::testing::Event> events = pull_events(h_);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[1].pts, 100 * kMs);
  EXPECT_EQ(events[1].duration, 200 * kMs);
  EXPECT_EQ(events[1].phoneme.symbol, 1);  // A
  const std::vector<std::string> warnings = messages(bus_, GST_MESSAGE_WARNING);
  ASSERT_EQ(warnings.size(), 3u);  // the 1st, 2nd and 4th
  EXPECT_EQ(warnings[0], "Skipped line 2, column 6: not a viseme of this format (1 bad so far)");
  EXPECT_TRUE(messages(bus_, GST_MESSAGE_ERROR).empty());
}

TEST_F(MarksParse, RhubarbJsonIsReadWholeAtEos) {
  make("pfapmarksparse format=rhubarb");
  const std::string doc =
      "{\"metadata\":{\"soundFile\":\"a.wav\",\"duration\":0.30},\n"
      "\"mouthCues\":[{\"start\":0.00,\"end\":0.10,\"value\":\"X\"},\n"
      "{\"start\":0.10,\"end\":0.30,\"value\":\"F\"}]}\n";
  for (size_t i = 0; i < doc.size(); i += 7) {
    const std::string piece = doc.substr(i, 7);
    ASSERT_EQ(gst_harness_push(h_, gst_buffer_new_memdup(piece.data(), piece.size())),
              GST_FLOW_OK);
  }
  EXPECT_EQ(gst_harness_buffers_in_queue(h_), 0u);
  gst_harness_push_event(h_, gst_event_new_eos());
  const std::vector<pfap::testing::Event> events = pull_events(h_);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].pts, 100 * kMs);
  EXPECT_EQ(events[1].duration, 200 * kMs);
  EXPECT_EQ(events[1].phoneme.symbol, 6);  // F
}

// Issue 27: 10 cues with the 6th bad gave 4, even with skip-bad-lines.
TEST_F(MarksParse, RhubarbJsonBadCueIsSkippedAndEveryGoodOneKept) {
  make("pfapmarksparse format=rhubarb skip-bad-lines=true");
  std::string doc = "{\"mouthCues\":[";
  for (int i = 0; i < 10; ++i) {
    if (i > 0) doc += ",\n";
    doc += "{\"start\":" + std::to_string(i) + ".0,\"end\":" + std::to_string(i + 1) +
           ".0,\"value\":\"" + (i == 5 ? "Z" : "B") + "\"}";
  }
  doc += "]}";
  ASSERT_EQ(gst_harness_push(h_, gst_buffer_new_memdup(doc.data(), doc.size())), GST_FLOW_OK);
  gst_harness_push_event(h_, gst_event_new_eos());
  const std::vector<pfap::testing::Event> events = pull_events(h_);
  std::vector<GstClockTime> times;
  for (const pfap::testing::Event& e : events) times.push_back(e.pts);
  // Cue 6's second is a rest, from cue 5's end.
  EXPECT_EQ(times, (std::vector<GstClockTime>{0, 1000 * kMs, 2000 * kMs, 3000 * kMs, 4000 * kMs,
                                              5000 * kMs, 6000 * kMs, 7000 * kMs, 8000 * kMs,
                                              9000 * kMs}));
  ASSERT_EQ(events.size(), 10u);
  EXPECT_EQ(events[4].phoneme.symbol, 2);  // B
  EXPECT_EQ(events[4].duration, 1000 * kMs);
  EXPECT_EQ(events[5].phoneme.symbol, 0);  // X
  EXPECT_EQ(events[6].phoneme.symbol, 2);
  const std::vector<std::string> warnings = messages(bus_, GST_MESSAGE_WARNING);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(warnings[0].starts_with("Skipped cue of Rhubarb JSON document 1, column "))
      << warnings[0];
  EXPECT_TRUE(warnings[0].ends_with(": not a viseme of this format (1 bad so far)")) << warnings[0];
  EXPECT_TRUE(messages(bus_, GST_MESSAGE_ERROR).empty());
}

// Issue 27: every 4 KiB chunk past 16 MiB was counted as one more bad item.
TEST_F(MarksParse, OversizedRhubarbJsonIsOneBadItem) {
  make("pfapmarksparse format=rhubarb skip-bad-lines=true");
  const std::string cue = "{\"start\":0.0,\"end\":0.1,\"value\":\"A\"},";
  std::string chunk = "{\"mouthCues\":[";
  while (chunk.size() + cue.size() <= 4096) chunk += cue;
  chunk.resize(4096, ' ');
  const size_t chunks = 17 * 1024 / 4;  // 17 MiB
  for (size_t i = 0; i < chunks; ++i) {
    ASSERT_EQ(gst_harness_push(h_, gst_buffer_new_memdup(chunk.data(), chunk.size())), GST_FLOW_OK);
  }
  gst_harness_push_event(h_, gst_event_new_eos());
  EXPECT_EQ(gst_harness_buffers_in_queue(h_), 0u);
  const std::vector<std::string> warnings = messages(bus_, GST_MESSAGE_WARNING);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0],
            "Skipped Rhubarb JSON document 1, column 16777217: larger than 16 MiB (1 bad so far)");
  EXPECT_TRUE(messages(bus_, GST_MESSAGE_ERROR).empty());
}

// Issue 27: a UTF-8 byte order mark before Rhubarb JSON was read as TSV, before Polly and
// Azure lines was "not a JSON value". Here it comes split over one-byte buffers, as appsrc
// may give it.
TEST_F(MarksParse, ByteOrderMarkAtTheStartIsSkippedInEveryFormat) {
  const struct {
    const char* format;
    const char* text;
    uint8_t symbol;
  } rows[] = {
      {"polly", "{\"time\":0,\"type\":\"viseme\",\"value\":\"p\"}\n", 1},
      {"azure", "{\"audioOffset\":0,\"visemeId\":21}\n", 21},
      {"rhubarb", "0.00\tF\n", 6},
      {"rhubarb", "{\"mouthCues\":[{\"start\":0.00,\"end\":0.10,\"value\":\"F\"}]}", 6},
  };
  for (const auto& row : rows) {
    SCOPED_TRACE(std::string(row.format) + ": " + row.text);
    make((std::string("pfapmarksparse format=") + row.format).c_str());
    const std::string text = std::string("\xEF\xBB\xBF") + row.text;
    GstFlowReturn flow = GST_FLOW_OK;
    for (size_t i = 0; i < text.size() && flow == GST_FLOW_OK; ++i) {
      flow = gst_harness_push(h_, gst_buffer_new_memdup(&text[i], 1));
    }
    EXPECT_EQ(flow, GST_FLOW_OK);
    gst_harness_push_event(h_, gst_event_new_eos());
    const std::vector<pfap::testing::Event> events = pull_events(h_);
    EXPECT_EQ(events.size(), 1u);
    if (!events.empty()) {
      EXPECT_EQ(events[0].pts, 0u);
      EXPECT_EQ(events[0].phoneme.symbol, row.symbol);
    }
    EXPECT_EQ(messages(bus_, GST_MESSAGE_ERROR), std::vector<std::string>{});
    EXPECT_TRUE(messages(bus_, GST_MESSAGE_WARNING).empty());
    gst_harness_teardown(h_);
    h_ = nullptr;
  }
}

// A byte order mark only where the text starts, and bytes that begin like one are text.
TEST_F(MarksParse, ByteOrderMarkLaterOrIncompleteIsText) {
  make("pfapmarksparse format=rhubarb");
  const std::string text =
      "\xEF\xBB"
      "0.00\tF\n";
  ASSERT_EQ(gst_harness_push(h_, gst_buffer_new_memdup(text.data(), text.size())), GST_FLOW_ERROR);
  const std::vector<std::string> errors = messages(bus_, GST_MESSAGE_ERROR);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0],
            "Bad line 1, column 1: bad time (a number >= 0 in the format's unit, "
            "under about 292 years)");
}

// ---------------------------------------------------------------------------------------------
// DocumentedMarks: docs/elements.md, "Speech marks: avatars' vocabularies in and out"

constexpr const char* kSection = "## Speech marks: avatars' vocabularies in and out";

TEST(DocumentedMarks, EveryCommandGivesTheExampleFile) {
  ASSERT_TRUE(pfap::testing::plugin_available(kElements));
  const std::vector<std::string> commands =
      pfap::testing::launch_descriptions(pfap::testing::doc_section("docs/elements.md", kSection));
  ASSERT_EQ(commands.size(), 10u);
  TempDir dir;
  int compared = 0;
  for (std::string command : commands) {
    SCOPED_TRACE(command);
    replace_all(command, "docs/examples/", source_path("docs/examples/"));
    replace_all(command, "autovideosink", "fakesink name=video");
    // The output file, to a temporary one of the same name.
    std::string output;
    const size_t sink = command.find("filesink location=");
    if (sink != std::string::npos) {
      const size_t start = sink + std::string("filesink location=").size();
      output = command.substr(start);
      command.replace(start, std::string::npos, dir.file(output));
    }
    Pipeline p(command);
    ASSERT_TRUE(p.ok()) << p.error();
    // pfapface's frames, counted.
    int frames = 0;
    if (GstElement* video = p.by_name("video")) {
      GstPad* pad = gst_element_get_static_pad(video, "sink");
      gst_pad_add_probe(
          pad, GST_PAD_PROBE_TYPE_BUFFER,
          [](GstPad*, GstPadProbeInfo*, gpointer data) {
            ++*static_cast<int*>(data);
            return GST_PAD_PROBE_OK;
          },
          &frames, nullptr);
      gst_object_unref(pad);
    }
    ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
    // Warnings fail too: pfapface warns of phonemes whose alphabet it does not know.
    ASSERT_EQ(p.wait_eos(20s, true), "");
    if (output.empty()) {
      EXPECT_GT(frames, 30);  // hello's 1.7 s at pfapface's default frame rate
      continue;
    }
    EXPECT_EQ(read_file(dir.file(output)), read_file(source_path("docs/examples/marks/" + output)))
        << output;
    ++compared;
  }
  EXPECT_EQ(compared, 9);
}

}  // namespace
