// SPDX-License-Identifier: LGPL-2.1-or-later
// The counters of the plugins' elements: one `stats` GstStructure on every element that
// counts, the same field name for the same thing, and the payloader's and depayloader's added
// to their RTP base classes' statistics rather than hiding them (docs/elements.md,
// "Counters").
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <string>

#include "documented_commands.h"
#include "pipeline.h"
#include "temp_dir.h"

namespace {

using namespace std::chrono_literals;
using pfap::testing::Pipeline;
using pfap::testing::source_path;
using pfap::testing::TempDir;

// The element's stats, or nullptr; the caller frees it.
GstStructure* stats_of(GstElement* element) {
  GstStructure* stats = nullptr;
  g_object_get(element, "stats", &stats, nullptr);
  return stats;
}

// Whether `stats` has every field of `fields`.
::testing::AssertionResult has_fields(const GstStructure* stats,
                                      std::initializer_list<const char*> fields) {
  if (stats == nullptr) return ::testing::AssertionFailure() << "no stats";
  for (const char* field : fields) {
    if (!gst_structure_has_field(stats, field)) {
      gchar* text = gst_structure_to_string(stats);
      auto failure = ::testing::AssertionFailure() << "no " << field << " in " << text;
      g_free(text);
      return failure;
    }
  }
  return ::testing::AssertionSuccess();
}

guint64 counter(const GstStructure* stats, const char* field) {
  guint64 value = G_MAXUINT64;
  EXPECT_TRUE(gst_structure_get_uint64(stats, field, &value)) << field;
  return value;
}

// hello.pfap through the payloader and depayloader to the text writer.
TEST(Stats, PayloaderAndDepayloaderAddTheirCountersToTheBaseClassStatistics) {
  Pipeline p("filesrc location=" + source_path("docs/examples/hello.pfap") +
             " ! pfaptextparse name=parse ! rtppfappay name=pay ! rtppfapdepay name=depay ! "
             "pfaptextenc name=enc ! fakesink");
  ASSERT_TRUE(p.ok()) << p.error();
  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(p.wait_eos(10s, true), "");

  GstStructure* pay = stats_of(p.by_name("pay"));
  // GstRTPBasePayload's, which gst-rtsp-server and webrtcbin users read from any payloader.
  EXPECT_TRUE(has_fields(pay, {"clock-rate", "running-time", "seqnum", "timestamp", "ssrc", "pt",
                               "seqnum-offset", "timestamp-offset"}));
  EXPECT_TRUE(has_fields(pay, {"packets", "recovery-entries", "complete-recoveries", "requests",
                               "requests-served", "complete-too-large", "oversized", "malformed"}));
  guint clock_rate = 0;
  EXPECT_TRUE(gst_structure_get_uint(pay, "clock-rate", &clock_rate));
  EXPECT_EQ(clock_rate, 44100u);
  EXPECT_GT(counter(pay, "packets"), 0u);
  gst_structure_free(pay);

  GstStructure* depay = stats_of(p.by_name("depay"));
  EXPECT_TRUE(has_fields(depay, {"seqnum", "timestamp", "npt-start", "npt-stop", "play-speed",
                                 "play-scale", "running-time-dts", "running-time-pts"}));
  EXPECT_TRUE(has_fields(depay, {"packets", "phonemes", "faps", "malformed", "lost"}));
  EXPECT_GT(counter(depay, "phonemes"), 0u);
  gst_structure_free(depay);

  // The parser's events out are the writer's events in, one per line.
  GstStructure* parse = stats_of(p.by_name("parse"));
  GstStructure* enc = stats_of(p.by_name("enc"));
  EXPECT_TRUE(has_fields(parse, {"events", "bad-lines"}));
  EXPECT_TRUE(has_fields(enc, {"events", "malformed", "earlier"}));
  EXPECT_GT(counter(parse, "events"), 0u);
  EXPECT_EQ(counter(enc, "events"), counter(parse, "events"));
  EXPECT_EQ(counter(enc, "malformed"), 0u);
  gst_structure_free(parse);
  gst_structure_free(enc);
}

// Every element that counts has `stats`, with the same names for the same counters.
TEST(Stats, EveryCountingElementHasStatsWithTheSharedNames) {
  struct Expected {
    const char* element;
    std::initializer_list<const char*> fields;
  };
  const std::array<Expected, 9> expected{{
      {"pfaptextenc", {"events", "malformed", "earlier"}},
      {"pfapfapenc", {"events", "malformed", "earlier"}},
      {"pfapmarksenc", {"events", "malformed", "earlier"}},
      {"pfaptextparse", {"events", "bad-lines"}},
      {"pfapfapparse", {"events", "bad-lines"}},
      {"pfapmarksparse", {"events", "bad-lines"}},
      {"rtppfappay", {"packets", "malformed"}},
      {"rtppfapdepay", {"packets", "malformed"}},
      {"pfaptts", {"bad-bookmarks"}},
  }};
  for (const Expected& e : expected) {
    SCOPED_TRACE(e.element);
    GstElement* element = gst_element_factory_make(e.element, nullptr);
    ASSERT_NE(element, nullptr);
    GParamSpec* pspec = g_object_class_find_property(G_OBJECT_GET_CLASS(element), "stats");
    ASSERT_NE(pspec, nullptr);
    EXPECT_EQ(G_PARAM_SPEC_VALUE_TYPE(pspec), GST_TYPE_STRUCTURE);
    GstStructure* stats = stats_of(element);
    EXPECT_TRUE(has_fields(stats, e.fields));
    if (stats != nullptr) gst_structure_free(stats);
    gst_object_unref(element);
  }
}

// The single counter properties from before stay, deprecated, and agree with `stats`.
TEST(Stats, DeprecatedCounterPropertiesStillCount) {
  TempDir dir;
  const std::string bad = dir.file("bad.pfap");
  ASSERT_TRUE(
      g_file_set_contents(bad.c_str(), "0 16 60 118 W\nnot a line\n60 3 70 124 -\n", -1, nullptr));
  Pipeline parse("filesrc location=" + bad +
                 " ! pfaptextparse name=parse skip-bad-lines=true ! fakesink");
  ASSERT_TRUE(parse.ok()) << parse.error();
  ASSERT_EQ(parse.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(parse.wait_eos(10s), "");
  guint64 bad_lines = 0;
  g_object_get(parse.by_name("parse"), "bad-lines", &bad_lines, nullptr);
  GstStructure* stats = stats_of(parse.by_name("parse"));
  EXPECT_EQ(bad_lines, 1u);
  EXPECT_EQ(counter(stats, "bad-lines"), 1u);
  EXPECT_EQ(counter(stats, "events"), 2u);
  gst_structure_free(stats);

  Pipeline tts(
      "pfaptts name=t skip-bad-bookmarks=true text=\"Hi <FAP 999 1 1 1 1 1 1> there.\" "
      "t.audio ! queue ! fakesink t.pfap ! queue ! fakesink");
  ASSERT_TRUE(tts.ok()) << tts.error();
  ASSERT_EQ(tts.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(tts.wait_eos(10s), "");
  guint64 bad_bookmarks = 0;
  g_object_get(tts.by_name("t"), "bad-bookmarks", &bad_bookmarks, nullptr);
  stats = stats_of(tts.by_name("t"));
  EXPECT_EQ(bad_bookmarks, 1u);
  EXPECT_EQ(counter(stats, "bad-bookmarks"), 1u);
  gst_structure_free(stats);
}

}  // namespace
