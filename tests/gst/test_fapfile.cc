// SPDX-License-Identifier: LGPL-2.1-or-later
// pfapfapparse and pfapfapenc (docs/fap-files.md, docs/elements.md "MPEG-4 FAP files"):
//  - FapParse.*: each real file in ../shared/fap (or $PFAP_FAP_DIR) through pfapfapparse, fed in
//    odd-sized chunks: the events applied to a FapState and sampled at the frame times give
//    back every value of the file; bad files are errors naming the file and line.
//  - FapRoundTrip.*: pfapfapparse ! rtppfappay ! (seeded 10 % loss) ! rtppfapdepay ! pfapfapenc:
//    the written file has every frame of the original whose phoneme the receiver got whole
//    (not flagged uncertain), and, without loss, every frame.
//  - FapDocumented.*: the commands of docs/elements.md, "MPEG-4 FAP files", run as written
//    with the real files, temporary outputs and fakesink for the display.
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "documented_commands.h"
#include "element_harness.h"
#include "pfap/fap_animation.h"
#include "pfap/fap_file.h"
#include "pfap/fap_state.h"
#include "pfap_buffers.h"
#include "pipeline.h"
#include "temp_dir.h"

namespace {

namespace fs = std::filesystem;
using pfap::testing::doc_section;
using pfap::testing::launch_descriptions;
using pfap::testing::Pipeline;
using pfap::testing::plugin_available;
using pfap::testing::read_file;
using pfap::testing::replace_all;
using pfap::testing::TempDir;

constexpr const char* kElements[] = {"pfapfapparse", "pfapfapenc", "rtppfappay", "rtppfapdepay"};

fs::path shared_dir() {
  const char* env = std::getenv("PFAP_FAP_DIR");
  return env != nullptr && *env != '\0' ? fs::path(env) : fs::path(PFAP_SHARED_FAP_DIR);
}

std::vector<fs::path> shared_files() {
  std::vector<fs::path> files;
  if (!fs::is_directory(shared_dir())) return files;
  for (const auto& entry : fs::directory_iterator(shared_dir())) {
    if (entry.path().extension() == ".fap") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

#define SKIP_WITHOUT_SHARED_FILES(files)              \
  if ((files).empty())                                \
  GTEST_SKIP() << "no .fap files in " << shared_dir() \
               << ": the real MPEG-4 FAP files live beside the project in ../shared/fap"

std::vector<pfap::FapAmplitudes> amplitudes_of(const pfap::FapFile& file) {
  std::vector<pfap::FapAmplitudes> out;
  pfap::NotCarried ignored;
  for (const pfap::FapFrame& frame : file.frames)
    out.push_back(pfap::amplitudes_of(frame, ignored));
  return out;
}

// Pushes `bytes` into the harness in chunks of 1000 bytes (lines split across buffers), then
// EOS.
void push_file(GstHarness* h, const std::string& bytes) {
  gst_harness_set_src_caps_str(h, "text/plain");
  for (size_t at = 0; at < bytes.size(); at += 1000) {
    const std::string chunk = bytes.substr(at, 1000);
    ASSERT_EQ(gst_harness_push(h, gst_buffer_new_memdup(chunk.data(), chunk.size())), GST_FLOW_OK);
  }
  ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
}

TEST(FapParse, EachRealFileGivesBackEveryValueAtItsFrameTimes) {
  ASSERT_TRUE(plugin_available(kElements));
  const auto files = shared_files();
  SKIP_WITHOUT_SHARED_FILES(files);
  for (const fs::path& path : files) {
    SCOPED_TRACE(path.filename().string());
    const std::string bytes = read_file(path);
    pfap::FapFile file;
    ASSERT_TRUE(pfap::read_fap_file(bytes, file).ok());

    GstHarness* h = gst_harness_new("pfapfapparse");
    push_file(h, bytes);
    GstCaps* caps = gst_pad_get_current_caps(h->sinkpad);
    ASSERT_NE(caps, nullptr);
    EXPECT_STREQ(gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet"),
                 "x-pfap-arpabet");
    gst_caps_unref(caps);

    pfap::FapState state;
    std::vector<std::pair<GstClockTime, std::vector<pfap::Fap>>> events;
    while (GstBuffer* b = gst_harness_try_pull(h)) {
      const pfap::testing::Event e = pfap::testing::read_event(b);
      events.emplace_back(GST_BUFFER_PTS(b), e.faps);
      gst_buffer_unref(b);
    }
    gst_harness_teardown(h);
    ASSERT_FALSE(events.empty());

    const auto want = amplitudes_of(file);
    size_t next = 0;
    for (uint32_t k = 0; k < file.header.frame_count; ++k) {
      const auto at = static_cast<GstClockTime>(pfap::frame_time_ms(k, 25.0)) * GST_MSECOND;
      for (; next < events.size() && events[next].first <= at; ++next) {
        for (const pfap::Fap& f : events[next].second) {
          state.apply(f, static_cast<int64_t>(events[next].first));
        }
      }
      for (int i = pfap::kMinFapIndex; i <= pfap::kMaxFapIndex; ++i) {
        ASSERT_EQ(state.amplitude(i, static_cast<int64_t>(at)), want[k][i])
            << "frame " << k << " FAP " << i;
      }
    }
  }
}

// Runs `text` through filesrc ! pfapfapparse ! fakesink; returns the bus error.
std::string error_of(const std::string& text, const TempDir& dir) {
  const std::string path = dir.file("bad.fap");
  EXPECT_TRUE(
      g_file_set_contents(path.c_str(), text.data(), static_cast<gssize>(text.size()), nullptr));
  Pipeline p("filesrc location=" + path + " ! pfapfapparse ! fakesink");
  EXPECT_TRUE(p.ok()) << p.error();
  EXPECT_EQ(p.set_state(GST_STATE_PLAYING), "");
  return p.wait_eos(std::chrono::seconds(10));
}

TEST(FapParse, BadFilesAreErrorsNamingFileLineAndField) {
  ASSERT_TRUE(plugin_available(kElements));
  TempDir dir;
  std::string mask = "0 0 1";
  for (int i = 4; i <= 68; ++i) mask += " 0";
  struct Case {
    std::string text;
    std::string said;
  };
  const Case cases[] = {
      {"2.1 t 25 2\n" + mask + "\n0 5\n", "line 4: the file ends before the header's count"},
      {"2.1 t 25 1\n" + mask + " 0\n0 5\n", "line 2, field 69: mask without 68 flags"},
      {"2.1 t 25 1\n" + mask + "\n0 3000000\n", "line 3, field 2 (FAP 3): value out of range"},
      {"2.1 t 25 4000000\n", "line 1, field 4: frame count not an integer"},
      {"2.1 t 100000 1\n", "line 1, field 3: frame rate not a number"},
      {"2.1 t 25 1\n" + std::string(100000, '0') + "\n", "line 2: line longer than"},
      {"\x01\x02garbage", "line 1, field 1: unsupported version"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.said);
    const std::string error = error_of(c.text, dir);
    EXPECT_NE(error.find("Bad FAP file " + dir.file("bad.fap") + ", " + c.said), std::string::npos)
        << error;
  }
}

// Issue 27: a UTF-8 byte order mark before a FAP file was "unsupported version".
TEST(FapParse, ByteOrderMarkAtTheStartIsSkipped) {
  ASSERT_TRUE(plugin_available(kElements));
  TempDir dir;
  std::string mask = "0 0 1";
  for (int i = 4; i <= 68; ++i) mask += " 0";
  const std::string bom = "\xEF\xBB\xBF";
  EXPECT_EQ(error_of(bom + "2.1 t 25 1\n" + mask + "\n0 5\n", dir), "");
  // Only at the start: later, it is a bad field.
  EXPECT_NE(error_of("2.1 t 25 1\n" + bom + mask + "\n0 5\n", dir).find("line 2, field 1"),
            std::string::npos);
}

TEST(FapParse, VisemesAreReportedNotSilentlyLost) {
  ASSERT_TRUE(plugin_available(kElements));
  TempDir dir;
  std::string mask = "1 0 1";
  for (int i = 4; i <= 68; ++i) mask += " 0";
  std::string text = "2.1 t 25 3\n";
  for (int k = 0; k < 3; ++k) text += mask + "\n" + std::to_string(k) + " 1 0 0 0 5\n";
  const std::string path = dir.file("visemes.fap");
  ASSERT_TRUE(g_file_set_contents(path.c_str(), text.data(), -1, nullptr));
  Pipeline p("filesrc location=" + path + " ! pfapfapparse ! fakesink");
  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  // Warned at the 1st and 2nd frame that sets FAP 1, not at the 3rd; then EOS.
  int warnings = 0;
  for (std::string message = p.wait_eos(std::chrono::seconds(10), true); !message.empty();
       message = p.wait_eos(std::chrono::seconds(10), true)) {
    ASSERT_NE(message.find("sets FAP 1 (viseme), which PFAP does not carry"), std::string::npos)
        << message;
    ASSERT_LT(++warnings, 10);
  }
  EXPECT_EQ(warnings, 2);
}

// Three values rounded in one frame pass the 1st and 2nd rounded value at once: one warning.
TEST(FapParse, RoundedValuesAreWarnedAbout) {
  ASSERT_TRUE(plugin_available(kElements));
  TempDir dir;
  std::string mask = "0 0 1 1 1";
  for (int i = 6; i <= 68; ++i) mask += " 0";
  const std::string text = "2.1 t 25 1\n" + mask + "\n0 1.5 2.25 -3.5\n";
  const std::string path = dir.file("fractions.fap");
  ASSERT_TRUE(g_file_set_contents(path.c_str(), text.data(), -1, nullptr));
  Pipeline p("filesrc location=" + path + " ! pfapfapparse ! fakesink");
  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  const std::string message = p.wait_eos(std::chrono::seconds(10), true);
  EXPECT_NE(message.find("frame 0 has values with a fraction, rounded to whole FAP units"),
            std::string::npos)
      << message;
  EXPECT_EQ(p.wait_eos(std::chrono::seconds(10), true), "");  // then EOS, no other warning
}

// With a speech pad, the file's FAPs go on the speech's phonemes, whichever input ends first.
TEST(FapParse, MergedWithASpeechStreamKeepsTheFileValuesAndTheSpeechPhonemes) {
  ASSERT_TRUE(plugin_available(kElements));
  std::string mask = "0 0 1";
  for (int i = 4; i <= 68; ++i) mask += " 0";
  std::string text = "2.1 t 25 10\n";
  for (int k = 0; k < 10; ++k)
    text += mask + "\n" + std::to_string(k) + " " + std::to_string(k * 7) + "\n";
  pfap::FapFile file;
  ASSERT_TRUE(pfap::read_fap_file(text, file).ok());
  for (const bool speech_ends_first : {true, false}) {
    SCOPED_TRACE(speech_ends_first ? "speech ends first" : "file ends first");
    GstHarness* h = gst_harness_new_with_padnames("pfapfapparse", "sink", "src");
    GstHarness* speech = gst_harness_new_with_element(h->element, "speech", nullptr);
    ASSERT_NE(speech, nullptr);
    gst_harness_set_src_caps_str(speech, "application/x-pfap,alphabet=x-sampa");
    gst_harness_set_src_caps_str(h, "text/plain");
    ASSERT_EQ(gst_harness_push(h, gst_buffer_new_memdup(text.data(), text.size())), GST_FLOW_OK);
    for (const auto& [start, duration] : {std::pair{0, 100}, {100, 150}}) {
      pfap::Phoneme p;
      p.symbol = 9;
      p.duration_ms = static_cast<uint16_t>(duration);
      ASSERT_EQ(gst_harness_push(
                    speech, pfap::testing::phoneme_buffer(p, {}, start * GST_MSECOND, start == 0)),
                GST_FLOW_OK);
    }
    EXPECT_EQ(gst_harness_try_pull(h), nullptr);  // nothing before both inputs end
    GstHarness* first = speech_ends_first ? speech : h;
    GstHarness* second = speech_ends_first ? h : speech;
    ASSERT_TRUE(gst_harness_push_event(first, gst_event_new_eos()));
    EXPECT_EQ(gst_harness_try_pull(h), nullptr);
    ASSERT_TRUE(gst_harness_push_event(second, gst_event_new_eos()));

    GstCaps* caps = gst_pad_get_current_caps(h->sinkpad);
    ASSERT_NE(caps, nullptr);
    EXPECT_STREQ(gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet"), "x-sampa");
    gst_caps_unref(caps);
    pfap::FapState state;
    std::vector<pfap::testing::Event> events;
    while (GstBuffer* b = gst_harness_try_pull(h)) {
      events.push_back(pfap::testing::read_event(b));
      events.back().pts = GST_BUFFER_PTS(b);
      gst_buffer_unref(b);
    }
    size_t next = 0;
    for (uint32_t k = 0; k < 10; ++k) {
      const auto at = static_cast<GstClockTime>(pfap::frame_time_ms(k, 25.0)) * GST_MSECOND;
      for (; next < events.size() && events[next].pts <= at; ++next) {
        for (const pfap::Fap& f : events[next].faps) {
          state.apply(f, static_cast<int64_t>(events[next].pts));
        }
      }
      EXPECT_EQ(state.amplitude(3, static_cast<int64_t>(at)), k * 7.0) << "frame " << k;
    }
    // The speech's 250 ms are its symbol, cut at the frames; silence carries the rest.
    for (const auto& e : events) {
      EXPECT_EQ(e.phoneme.symbol, e.pts < 250 * GST_MSECOND ? 9 : 0) << e.pts;
    }
    EXPECT_TRUE(events.back().phoneme.end_of_text);
    gst_harness_teardown(speech);
    gst_harness_teardown(h);
  }
}

// Runs `text`, a FAP file, through pfapfapparse with `speech` on its speech pad; expects `want`.
void expect_whole_merge(const std::string& text, const std::vector<pfap::TextEvent>& speech,
                        const std::vector<pfap::TextEvent>& want) {
  GstHarness* h = gst_harness_new_with_padnames("pfapfapparse", "sink", "src");
  GstHarness* speech_pad = gst_harness_new_with_element(h->element, "speech", nullptr);
  ASSERT_NE(speech_pad, nullptr);
  gst_harness_set_src_caps_str(speech_pad, "application/x-pfap");
  for (const pfap::TextEvent& e : speech) {
    const auto pts = static_cast<GstClockTime>(e.time_ms) * GST_MSECOND;
    ASSERT_EQ(gst_harness_push(speech_pad, pfap::testing::markup_buffer(e.event, pts)),
              GST_FLOW_OK);
  }
  ASSERT_TRUE(gst_harness_push_event(speech_pad, gst_event_new_eos()));
  push_file(h, text);
  std::vector<pfap::TextEvent> got;
  while (GstBuffer* b = gst_harness_try_pull(h)) {
    pfap::TextEvent e;
    e.time_ms = static_cast<int64_t>(GST_BUFFER_PTS(b) / GST_MSECOND);
    GstMapInfo map;
    gst_buffer_map(b, &map, GST_MAP_READ);
    EXPECT_TRUE(pfap::read_markup({map.data, map.size}, e.event));
    gst_buffer_unmap(b, &map);
    gst_buffer_unref(b);
    got.push_back(std::move(e));
  }
  gst_harness_teardown(speech_pad);
  gst_harness_teardown(h);
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(got[i], want[i]) << "event " << i << " at " << want[i].time_ms << " ms";
  }
}

// Issue 27: merged, pfapfapparse held the file's events, merge_with_speech's copy of their FAPs
// and its output at once (760 MB for a 261 MB file); it now merges in windows of at least
// 4096 file events, which must give what the whole merge gives.
TEST(FapParse, MergedInWindowsIsTheWholeMerge) {
  ASSERT_TRUE(plugin_available(kElements));
  std::string mask = "0 0 1";
  for (int i = 4; i <= 68; ++i) mask += " 0";
  // 12,000 frames at 25 a second, FAP 3 changing at every third: three windows and more.
  constexpr int kFrames = 12000;
  std::string text = "2.1 t 25 " + std::to_string(kFrames) + "\n";
  for (int k = 0; k < kFrames; ++k) {
    text += mask + "\n" + std::to_string(k) + " " + std::to_string(k / 3 * 5 % 1000) + "\n";
  }
  pfap::FapFile file;
  ASSERT_TRUE(pfap::read_fap_file(text, file).ok());
  for (uint32_t seed = 1; seed <= 8; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // Speech phonemes of 10 to 400 ms, after gaps of 0 to 300 ms, half of them starting at a
    // frame; ending a text now and then.
    std::mt19937 random(seed);
    std::vector<pfap::TextEvent> speech;
    for (int64_t at = 0; at < int64_t{kFrames} * 40 + 2000;) {
      pfap::TextEvent e;
      e.time_ms = at;
      e.event.phoneme.symbol = static_cast<uint8_t>(1 + random() % 40);
      e.event.phoneme.duration_ms = static_cast<uint16_t>(10 + random() % 391);
      e.event.phoneme.end_of_text = random() % 7 == 0;
      e.event.sentence_start = speech.empty() || speech.back().event.phoneme.end_of_text;
      speech.push_back(e);
      at += e.event.phoneme.duration_ms;
      if (random() % 2 == 0) at = (at + random() % 301 + 39) / 40 * 40;
    }
    expect_whole_merge(text, speech, pfap::merge_with_speech(speech, pfap::markup_of(file)));
  }
}

// ---------------------------------------------------------------------------------------------
// Over RTP with loss, back to a file

struct RoundTrip {
  pfap::FapFile written;
  std::vector<pfap::testing::Event> received;  // what pfapfapenc took
  unsigned packets = 0;
  unsigned dropped = 0;
};

struct DropState {
  std::mt19937 random;
  double loss;
  unsigned packets = 0;
  unsigned dropped = 0;
};

GstPadProbeReturn drop_some(GstPad*, GstPadProbeInfo*, gpointer data) {
  auto* s = static_cast<DropState*>(data);
  // The first packet, the payloader's complete state, always arrives: the receiver starts
  // whole (else it waits for a complete state, draft 6.4). Data packets are lost from the 1st.
  const bool drop = s->packets++ > 0 && std::uniform_real_distribution<>(0, 1)(s->random) < s->loss;
  if (!drop) return GST_PAD_PROBE_OK;
  ++s->dropped;
  return GST_PAD_PROBE_DROP;
}

GstPadProbeReturn keep_event(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* received = static_cast<std::vector<pfap::testing::Event>*>(data);
  received->push_back(pfap::testing::read_event(GST_PAD_PROBE_INFO_BUFFER(info)));
  received->back().pts = GST_BUFFER_PTS(GST_PAD_PROBE_INFO_BUFFER(info));
  return GST_PAD_PROBE_OK;
}

RoundTrip round_trip(const std::string& bytes, double loss, uint32_t seed) {
  RoundTrip out;
  GstHarness* h = gst_harness_new_parse(
      "pfapfapparse ! rtppfappay name=pay recovery-depth=4 ! rtppfapdepay name=depay ! "
      "pfapfapenc name=enc");
  DropState drops{std::mt19937(seed), loss};
  GstElement* depay = gst_bin_get_by_name(GST_BIN(h->element), "depay");
  GstElement* enc = gst_bin_get_by_name(GST_BIN(h->element), "enc");
  GstPad* depay_sink = gst_element_get_static_pad(depay, "sink");
  GstPad* enc_sink = gst_element_get_static_pad(enc, "sink");
  gst_pad_add_probe(depay_sink, GST_PAD_PROBE_TYPE_BUFFER, drop_some, &drops, nullptr);
  gst_pad_add_probe(enc_sink, GST_PAD_PROBE_TYPE_BUFFER, keep_event, &out.received, nullptr);
  push_file(h, bytes);
  const std::string text = pfap::testing::pull_text(h);
  gst_object_unref(depay_sink);
  gst_object_unref(enc_sink);
  gst_object_unref(depay);
  gst_object_unref(enc);
  gst_harness_teardown(h);
  const pfap::FapFileResult result = pfap::read_fap_file(text, out.written);
  EXPECT_TRUE(result.ok()) << pfap::describe(result) << "\n" << text.substr(0, 400);
  out.packets = drops.packets;
  out.dropped = drops.dropped;
  return out;
}

// Whether frame time `at` lies in a received phoneme the depayloader did not flag uncertain.
bool whole_at(const std::vector<pfap::testing::Event>& received, GstClockTime at) {
  for (const auto& e : received) {
    if (e.kind != PFAP_EVENT_PHONEME || e.phoneme.duration_ms == 0) continue;
    if (e.pts <= at && at < e.pts + e.phoneme.duration_ms * GST_MSECOND) {
      return (e.flags & PFAP_FLAG_UNCERTAIN) == 0;
    }
  }
  return false;
}

TEST(FapRoundTrip, WithoutLossEveryFrameComesBack) {
  ASSERT_TRUE(plugin_available(kElements));
  const auto files = shared_files();
  SKIP_WITHOUT_SHARED_FILES(files);
  for (const fs::path& path : files) {
    SCOPED_TRACE(path.filename().string());
    const std::string bytes = read_file(path);
    pfap::FapFile file;
    ASSERT_TRUE(pfap::read_fap_file(bytes, file).ok());
    const RoundTrip r = round_trip(bytes, 0.0, 1);
    EXPECT_EQ(r.dropped, 0u);
    ASSERT_EQ(r.written.frames.size(), file.frames.size());
    EXPECT_EQ(amplitudes_of(r.written), amplitudes_of(file));
  }
}

TEST(FapRoundTrip, TenPercentLossRecoveredGivesEveryFrameTheReceiverHadWhole) {
  ASSERT_TRUE(plugin_available(kElements));
  const auto files = shared_files();
  SKIP_WITHOUT_SHARED_FILES(files);
  unsigned frames = 0, checked = 0, packets = 0, dropped = 0;
  for (const fs::path& path : files) {
    SCOPED_TRACE(path.filename().string());
    const std::string bytes = read_file(path);
    pfap::FapFile file;
    ASSERT_TRUE(pfap::read_fap_file(bytes, file).ok());
    const RoundTrip r = round_trip(bytes, 0.10, 2000 + static_cast<uint32_t>(frames));
    // The file ends with the last phoneme received: the last packets may be lost.
    ASSERT_LE(r.written.frames.size(), file.frames.size());
    const auto got = amplitudes_of(r.written);
    const auto want = amplitudes_of(file);
    for (size_t k = 0; k < want.size(); ++k) {
      const auto at = static_cast<GstClockTime>(pfap::frame_time_ms(k, 25.0)) * GST_MSECOND;
      ++frames;
      if (!whole_at(r.received, at)) continue;
      ++checked;
      ASSERT_LT(k, got.size());
      EXPECT_EQ(got[k], want[k]) << "frame " << k;
    }
    packets += r.packets;
    dropped += r.dropped;
  }
  std::cout << "[ fapfile  ] " << dropped << " of " << packets << " packets dropped; " << checked
            << " of " << frames << " frames received whole and compared\n";
  EXPECT_GT(dropped, packets / 20);     // the loss happened
  EXPECT_GT(checked, frames * 6 / 10);  // and recovery made most frames whole
}

// ---------------------------------------------------------------------------------------------
// pfapfapenc on its own

// Pushes events into pfapfapenc with the given properties; returns the file and the warnings.
struct Encoded {
  std::string text;
  std::vector<std::string> warnings;
};

Encoded encode(const std::string& properties, const std::vector<GstBuffer*>& buffers) {
  GstHarness* h = gst_harness_new_parse(("pfapfapenc " + properties).c_str());
  GstBus* bus = gst_bus_new();
  gst_element_set_bus(h->element, bus);
  gst_harness_set_src_caps_str(h, "application/x-pfap");
  for (GstBuffer* b : buffers) EXPECT_EQ(gst_harness_push(h, b), GST_FLOW_OK);
  EXPECT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
  Encoded out;
  out.text = pfap::testing::pull_text(h);
  while (GstMessage* m = gst_bus_pop_filtered(bus, GST_MESSAGE_WARNING)) {
    GError* error = nullptr;
    gst_message_parse_warning(m, &error, nullptr);
    out.warnings.emplace_back(error->message);
    g_error_free(error);
    gst_message_unref(m);
  }
  gst_element_set_bus(h->element, nullptr);
  gst_object_unref(bus);
  gst_harness_teardown(h);
  return out;
}

GstBuffer* phoneme_at(GstClockTime pts, uint16_t duration_ms, std::vector<pfap::Fap> faps) {
  pfap::MarkupEvent e;
  e.kind = PFAP_EVENT_PHONEME;
  e.phoneme.duration_ms = duration_ms;
  e.faps = std::move(faps);
  return pfap::testing::markup_buffer(e, pts);
}

// frame-rate is a fraction, as GStreamer's framerates are; "25" typed in a pipeline is still
// 25/1 (1.22 refuses a decimal: 12.5 is typed 25/2). The file's header holds a decimal number.
TEST(PfapFapEnc, FrameRateIsAFractionAndWholeNumbersStillParse) {
  ASSERT_TRUE(plugin_available(kElements));
  for (const auto& [typed, rate] :
       {std::pair{"25", 25.0}, std::pair{"25/2", 12.5}, std::pair{"30000/1001", 29.97002997}}) {
    const Encoded out = encode(std::string("frame-rate=") + typed,
                               {phoneme_at(0, 100, {{3, 50, 0, pfap::Curve::kLinear}})});
    pfap::FapFile file;
    const pfap::FapFileResult result = pfap::read_fap_file(out.text, file);
    ASSERT_TRUE(result.ok()) << typed << ": " << pfap::describe(result) << "\n" << out.text;
    EXPECT_EQ(file.header.frame_rate, rate) << typed;
    EXPECT_TRUE(out.warnings.empty()) << typed;
  }
  GstElement* enc = gst_element_factory_make("pfapfapenc", nullptr);
  ASSERT_NE(enc, nullptr);
  GParamSpec* spec = g_object_class_find_property(G_OBJECT_GET_CLASS(enc), "frame-rate");
  ASSERT_NE(spec, nullptr);
  EXPECT_EQ(spec->value_type, GST_TYPE_FRACTION);
  gst_object_unref(enc);
}

TEST(PfapFapEnc, MalformedEventsAreDroppedWithAWarningAndTheFileGoesOn) {
  ASSERT_TRUE(plugin_available(kElements));
  const char junk[] = "not an event";
  const Encoded out =
      encode("frame-rate=10 name-in-file=\"my face\"",
             {phoneme_at(0, 100, {{3, 50, 0, pfap::Curve::kLinear}}),
              gst_buffer_new_memdup(junk, sizeof junk),
              phoneme_at(100 * GST_MSECOND, 100, {{3, -20, 0, pfap::Curve::kLinear}})});
  ASSERT_EQ(out.warnings.size(), 1u);
  EXPECT_NE(out.warnings[0].find("malformed"), std::string::npos) << out.warnings[0];
  pfap::FapFile file;
  const pfap::FapFileResult result = pfap::read_fap_file(out.text, file);
  ASSERT_TRUE(result.ok()) << pfap::describe(result) << "\n" << out.text;
  EXPECT_EQ(file.header.name, "my_face");
  EXPECT_EQ(file.header.frame_rate, 10.0);
  ASSERT_EQ(file.frames.size(), 2u);
  EXPECT_EQ(file.frames[0].value[3], 50);
  EXPECT_EQ(file.frames[1].value[3], -20);
}

TEST(PfapFapEnc, MaxFramesBoundsTheFileWithAWarning) {
  ASSERT_TRUE(plugin_available(kElements));
  std::vector<GstBuffer*> buffers;
  for (int i = 0; i < 20; ++i) {
    buffers.push_back(phoneme_at(i * 40 * GST_MSECOND, 40, {{5, i, 0, pfap::Curve::kLinear}}));
  }
  const Encoded out = encode("max-frames=8", buffers);
  ASSERT_FALSE(out.warnings.empty());
  EXPECT_NE(out.warnings[0].find("The FAP file is full (8 frames)"), std::string::npos)
      << out.warnings[0];
  EXPECT_LE(out.warnings.size(), 5u);  // rate-limited: the 1st, 2nd, 4th, 8th ... only
  pfap::FapFile file;
  ASSERT_TRUE(pfap::read_fap_file(out.text, file).ok());
  ASSERT_EQ(file.frames.size(), 8u);
  EXPECT_EQ(file.frames[7].value[5], 7);
}

// The writers' one rule (pfap::EventTimeline, PFAP_WARN_EARLIER_EVENT), as pfaptextenc's.
TEST(PfapFapEnc, EarlierEventIsWrittenAtThePreviousTimeWithAWarning) {
  ASSERT_TRUE(plugin_available(kElements));
  const Encoded out = encode(
      "frame-rate=10", {phoneme_at(100 * GST_MSECOND, 100, {{3, 50, 0, pfap::Curve::kLinear}}),
                        phoneme_at(40 * GST_MSECOND, 0, {{3, -20, 0, pfap::Curve::kLinear}})});
  ASSERT_EQ(out.warnings.size(), 1u);
  EXPECT_NE(out.warnings[0].find("earlier than the one before"), std::string::npos)
      << out.warnings[0];
  pfap::FapFile file;
  ASSERT_TRUE(pfap::read_fap_file(out.text, file).ok()) << out.text;
  ASSERT_EQ(file.frames.size(), 2u);
  EXPECT_EQ(file.frames[0].value[3], 0);    // before the first event
  EXPECT_EQ(file.frames[1].value[3], -20);  // the earlier event, after the first at 100 ms
}

// Issue 27: pfapfapenc took 345 MB at its frame limit, where docs/fap-files.md said 108 MB:
// the frames' amplitudes, then the whole FapFile, its text and a copy of it. The text now goes
// out in pieces of about 64 KiB as it is written, from the amplitudes.
TEST(PfapFapEnc, TheFileGoesOutInPiecesAsItIsWritten) {
  ASSERT_TRUE(plugin_available(kElements));
  std::vector<pfap::Fap> every;
  for (uint8_t fap = pfap::kMinFapIndex; fap <= pfap::kFapFileFaps; ++fap) {
    every.push_back({fap, 1000, 0, pfap::Curve::kLinear});
  }
  // Every FAP set, then 100 s of frames at 25 a second: about 1.3 MB of text.
  GstHarness* h = gst_harness_new("pfapfapenc");
  gst_harness_set_src_caps_str(h, "application/x-pfap");
  ASSERT_EQ(gst_harness_push(h, phoneme_at(0, 100, every)), GST_FLOW_OK);
  ASSERT_EQ(gst_harness_push(h, phoneme_at(100 * GST_SECOND, 0, {})), GST_FLOW_OK);
  ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
  std::string text;
  size_t buffers = 0, largest = 0;
  while (GstBuffer* b = gst_harness_try_pull(h)) {
    GstMapInfo map;
    gst_buffer_map(b, &map, GST_MAP_READ);
    text.append(reinterpret_cast<const char*>(map.data), map.size);
    largest = std::max(largest, map.size);
    ++buffers;
    gst_buffer_unmap(b, &map);
    gst_buffer_unref(b);
  }
  gst_harness_teardown(h);
  pfap::FapFile file;
  ASSERT_TRUE(pfap::read_fap_file(text, file).ok());
  ASSERT_GE(file.frames.size(), 2500u);
  EXPECT_EQ(file.frames.back().value[68], 1000);
  EXPECT_GT(buffers, text.size() / (65 * 1024));
  EXPECT_LT(largest, size_t{66 * 1024});  // 64 KiB and the last frame's lines
}

TEST(PfapFapEnc, NoEventsNoFileAndAWarning) {
  ASSERT_TRUE(plugin_available(kElements));
  const Encoded out = encode("", {});
  EXPECT_EQ(out.text, "");
  ASSERT_EQ(out.warnings.size(), 1u);
  EXPECT_NE(out.warnings[0].find("No PFAP events"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// docs/elements.md, "MPEG-4 FAP files"

TEST(FapDocumented, EveryCommandRunsToEos) {
  const auto files = shared_files();
  SKIP_WITHOUT_SHARED_FILES(files);
  const char* used[] = {"pfapfapparse", "pfapfapenc", "pfaptts", "pfapface", "netsim"};
  ASSERT_TRUE(plugin_available(used));
  const std::vector<std::string> commands =
      launch_descriptions(doc_section("docs/elements.md", "## MPEG-4 FAP files"));
  ASSERT_EQ(commands.size(), 4u);
  TempDir dir;
  for (std::string command : commands) {
    SCOPED_TRACE(command);
    replace_all(command, "../shared/fap/", shared_dir().string() + "/");
    replace_all(command, "location=hello.fap", "location=" + dir.file("hello.fap"));
    replace_all(command, "location=joy-again.fap", "location=" + dir.file("joy-again.fap"));
    replace_all(command, "autovideosink", "fakesink sync=false");
    Pipeline p(command);
    ASSERT_TRUE(p.ok()) << p.error();
    ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
    EXPECT_EQ(p.wait_eos(std::chrono::seconds(60)), "");
  }
  // The files the commands wrote read back.
  for (const char* name : {"hello.fap", "joy-again.fap"}) {
    SCOPED_TRACE(name);
    pfap::FapFile file;
    const pfap::FapFileResult result = pfap::read_fap_file(read_file(dir.file(name)), file);
    EXPECT_TRUE(result.ok()) << pfap::describe(result);
    EXPECT_GT(file.frames.size(), 10u);
  }
}

}  // namespace
