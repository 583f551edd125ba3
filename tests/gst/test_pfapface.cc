// SPDX-License-Identifier: LGPL-2.1-or-later
// pfapface: x-pfap in, frames out. Frame timing, EOS, gaps, flushing, caps, bad input, live
// input, golden frames of the example sessions against stored PNGs, pictures that must
// differ (mouth shapes, expressions, head yaw), and the commands of docs/elements.md,
// "Talking head: pfapface".
//
// Golden frames: tests/gst/golden/*.png, 160x120, overlay off (fonts differ between
// machines). After a deliberate change to the drawing, regenerate them with
//   PFAP_UPDATE_GOLDEN=1 meson test -C build pfapface
// and look at the new pictures before committing them.
#include <cairo.h>
#include <glib/gstdio.h>
#include <gst/check/gstharness.h>
#include <gst/video/video.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "element_harness.h"
#include "pfap/markup_event.h"
#include "pfap/phoneme_table.h"
#include "glib_log.h"
#include "documented_commands.h"
#include "pfap_buffers.h"
#include "pipeline.h"
#include "release_fonts.h"
#include "temp_dir.h"

namespace {

using pfap::Curve;
using pfap::Fap;
using pfap::MarkupEvent;
using pfap::Phoneme;
using pfap::testing::doc_section;
using pfap::testing::launch_descriptions;
using pfap::testing::markup_buffer;
using pfap::testing::Pipeline;
using pfap::testing::read_file;
using pfap::testing::replace_all;
using pfap::testing::source_path;
using pfap::testing::TempDir;

constexpr GstClockTime kMs = GST_MSECOND;
constexpr const char* kSmallCaps = "video/x-raw,format=BGRx,width=160,height=120,framerate=25/1";

uint8_t symbol(const char* name) {
  return *pfap::find_symbol(*pfap::find_alphabet(pfap::kArpabetAlphabet), name);
}

GstBuffer* phoneme(const char* name, GstClockTime pts, uint16_t duration_ms,
                   std::vector<Fap> faps = {}) {
  MarkupEvent event;
  event.phoneme = Phoneme{symbol(name), duration_ms, 60};
  event.faps = std::move(faps);
  return markup_buffer(event, pts);
}

Fap fap(int index, int32_t amplitude, uint16_t transition_ms = 0, Curve curve = Curve::kLinear) {
  return {static_cast<uint8_t>(index), amplitude, transition_ms, curve};
}

// A frame's pixels, 4 bytes each (B, G, R, x on little-endian), rows packed.
struct Picture {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> bgrx;

  int channel(int x, int y, int c) const { return bgrx[(y * width + x) * 4 + c]; }
  bool operator==(const Picture&) const = default;
};

Picture picture_of(GstBuffer* buffer, GstCaps* caps) {
  GstVideoInfo info;
  EXPECT_TRUE(gst_video_info_from_caps(&info, caps));
  Picture p{GST_VIDEO_INFO_WIDTH(&info), GST_VIDEO_INFO_HEIGHT(&info), {}};
  GstMapInfo map;
  gst_buffer_map(buffer, &map, GST_MAP_READ);
  const int stride = GST_VIDEO_INFO_PLANE_STRIDE(&info, 0);
  for (int y = 0; y < p.height; ++y) {
    p.bgrx.insert(p.bgrx.end(), map.data + y * stride, map.data + y * stride + p.width * 4);
  }
  gst_buffer_unmap(buffer, &map);
  return p;
}

// Mean absolute difference per colour channel over a region, 0..255.
double mean_difference(const Picture& a, const Picture& b, int x0 = 0, int y0 = 0, int x1 = -1,
                       int y1 = -1) {
  if (x1 < 0) x1 = a.width;
  if (y1 < 0) y1 = a.height;
  double sum = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      for (int c = 0; c < 3; ++c) sum += std::abs(a.channel(x, y, c) - b.channel(x, y, c));
    }
  }
  return sum / (3.0 * (x1 - x0) * (y1 - y0));
}

// pfapface in a harness, with a bus for its warnings.
class Face : public pfap::testing::ElementHarness {
 public:
  explicit Face(const char* output_caps = kSmallCaps,
                const char* input_caps = "application/x-pfap, alphabet=(string)x-pfap-arpabet")
      : ElementHarness("pfapface") {
    if (output_caps != nullptr) gst_harness_set_sink_caps_str(h_, output_caps);
    gst_harness_set_src_caps_str(h_, input_caps);
  }

  void push(GstBuffer* buffer) { ASSERT_EQ(gst_harness_push(h_, buffer), GST_FLOW_OK); }
  void push_gap(GstClockTime pts, GstClockTime duration) {
    ASSERT_TRUE(gst_harness_push_event(h_, gst_event_new_gap(pts, duration)));
  }
  void eos() { ASSERT_TRUE(gst_harness_push_event(h_, gst_event_new_eos())); }

  // Every frame up to EOS (bounded by the harness's own 60 s wait per frame).
  std::vector<GstBuffer*> frames_until_eos() {
    std::vector<GstBuffer*> frames;
    GstBuffer* buffer = nullptr;
    while (gst_harness_pull_until_eos(h_, &buffer) && buffer != nullptr) frames.push_back(buffer);
    return frames;
  }
  // The next `n` frames, waiting at most 10 s in all; fewer if they do not come.
  std::vector<GstBuffer*> frames(size_t n) {
    std::vector<GstBuffer*> out;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (out.size() < n && std::chrono::steady_clock::now() < deadline) {
      if (GstBuffer* b = gst_harness_try_pull(h_)) {
        out.push_back(b);
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    }
    return out;
  }
  Picture picture(GstBuffer* buffer) {
    GstCaps* caps = gst_pad_get_current_caps(h_->sinkpad);
    Picture p = picture_of(buffer, caps);
    gst_caps_unref(caps);
    return p;
  }
  std::string output_caps() {
    GstCaps* caps = gst_pad_get_current_caps(h_->sinkpad);
    if (caps == nullptr) return "(none)";
    gchar* s = gst_caps_to_string(caps);
    std::string text(s);
    g_free(s);
    gst_caps_unref(caps);
    return text;
  }
};

void unref_all(std::vector<GstBuffer*>& buffers) {
  for (GstBuffer* b : buffers) gst_buffer_unref(b);
  buffers.clear();
}

// The frame at `frame_index` of a session of one phoneme held from 0 to 400 ms with `faps`.
Picture still(const char* name, std::vector<Fap> faps, int frame_index = 5,
              const char* style = "cartoon") {
  Face face;
  gst_util_set_object_arg(G_OBJECT(face.element()), "style", style);
  face.push(phoneme(name, 0, 400, std::move(faps)));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  EXPECT_GT(frames.size(), static_cast<size_t>(frame_index));
  Picture p = frames.size() > static_cast<size_t>(frame_index) ? face.picture(frames[frame_index])
                                                               : Picture{};
  unref_all(frames);
  return p;
}

// ---------------------------------------------------------------------------------------------
// Frame timing

// `seconds` of contiguous 100 ms phonemes: exactly rate * seconds frames, frame i at
// i / rate, lasting to the next.
void expect_frames_for(int seconds, int fps_n, int fps_d) {
  const std::string caps =
      "video/x-raw,format=BGRx,width=32,height=24,framerate=" + std::to_string(fps_n) + "/" +
      std::to_string(fps_d);
  Face face(caps.c_str());
  for (int i = 0; i < seconds * 10; ++i) face.push(phoneme(i % 2 ? "AA" : "M", i * 100 * kMs, 100));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  const uint64_t expected = gst_util_uint64_scale_ceil(seconds, static_cast<uint64_t>(fps_n),
                                                       static_cast<uint64_t>(fps_d));
  ASSERT_EQ(frames.size(), expected);
  for (size_t i = 0; i < frames.size(); ++i) {
    const GstClockTime pts = gst_util_uint64_scale(i, GST_SECOND * fps_d, fps_n);
    const GstClockTime next = gst_util_uint64_scale(i + 1, GST_SECOND * fps_d, fps_n);
    EXPECT_EQ(GST_BUFFER_PTS(frames[i]), pts) << i;
    EXPECT_EQ(GST_BUFFER_DURATION(frames[i]), next - pts) << i;
    EXPECT_EQ(gst_buffer_get_size(frames[i]), 32u * 24 * 4);
  }
  EXPECT_TRUE(GST_BUFFER_IS_DISCONT(frames[0]));
  unref_all(frames);
  EXPECT_TRUE(face.warnings().empty());
}

TEST(PfapFaceTiming, ThreeSecondsAt25FpsAre75Frames) { expect_frames_for(3, 25, 1); }
TEST(PfapFaceTiming, TwoSecondsAtNtscRate) { expect_frames_for(2, 30000, 1001); }

TEST(PfapFaceTiming, GapsBetweenPhonemesAreFilledWithFrames) {
  Face face;
  face.push(phoneme("HH", 0, 100));
  face.push(phoneme("AY", 1000 * kMs, 100));  // 900 ms of silence before it
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  ASSERT_EQ(frames.size(), 28u);  // 0 .. 1080 ms
  for (size_t i = 0; i < frames.size(); ++i) EXPECT_EQ(GST_BUFFER_PTS(frames[i]), i * 40 * kMs);
  unref_all(frames);
}

TEST(PfapFaceTiming, TransitionsRunningAtTheEndAreRenderedToTheirEnd) {
  Face face;
  face.push(phoneme("M", 0, 100, {fap(69, 40, 1000, Curve::kSpline)}));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  EXPECT_EQ(frames.size(), 25u);
  unref_all(frames);
}

TEST(PfapFaceTiming, LaterEventReleasesTheFramesBeforeIt) {
  Face face;
  face.push(phoneme("HH", 0, 100));
  face.push(phoneme("AY", 2000 * kMs, 100));
  // No EOS: the event at 2 s shows that nothing can come for the frames before it.
  std::vector<GstBuffer*> frames = face.frames(50);
  ASSERT_EQ(frames.size(), 50u);
  EXPECT_EQ(GST_BUFFER_PTS(frames.back()), 1960 * kMs);
  unref_all(frames);
}

TEST(PfapFaceTiming, GapEventReleasesFramesThroughIt) {
  Face face;
  face.push(phoneme("HH", 0, 100));
  face.push_gap(100 * kMs, 900 * kMs);
  std::vector<GstBuffer*> frames = face.frames(25);
  ASSERT_EQ(frames.size(), 25u);  // up to 960 ms
  unref_all(frames);
  face.eos();
  frames = face.frames_until_eos();
  EXPECT_EQ(frames.size(), 0u) << "the gap ended the stream at 1 s";
  unref_all(frames);
}

// The outside tester's two-line file: "0 1 60 120 W", then "9223372032759 1 60 120 E", 292
// years later. The face at rest draws 10 s of frames, then one GAP event up to the frame of
// the next event, not a frame every 40 ms for centuries (docs/face.md, "Long silences").
TEST(PfapFaceTiming, FarFutureEventCostsOneGapNotCenturiesOfFrames) {
  Face face;
  const GstClockTime far = 9223372032759 * kMs;
  face.push(phoneme("W", 0, 120));
  face.push(phoneme("EH", far, 120));
  face.eos();
  std::vector<GstBuffer*> frames;
  std::vector<GstEvent*> gaps;
  bool eos = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!eos && frames.size() < 1000 && std::chrono::steady_clock::now() < deadline) {
    if (GstBuffer* b = gst_harness_try_pull(face.harness())) {
      frames.push_back(b);
      continue;
    }
    while (GstEvent* e = gst_harness_try_pull_event(face.harness())) {
      if (GST_EVENT_TYPE(e) == GST_EVENT_GAP) {
        gaps.push_back(e);
        continue;
      }
      eos = eos || GST_EVENT_TYPE(e) == GST_EVENT_EOS;
      gst_event_unref(e);
    }
    if (!eos) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_TRUE(eos) << frames.size() << " frames";
  // 0 .. 10.08 s: the phoneme and 10 s at rest; then 9223372032720 .. 9223372032840 ms.
  ASSERT_EQ(frames.size(), 257u);
  EXPECT_EQ(GST_BUFFER_PTS(frames[252]), 10080 * kMs);
  EXPECT_EQ(GST_BUFFER_PTS(frames[253]), 9223372032720 * kMs);
  EXPECT_EQ(GST_BUFFER_PTS(frames.back()), 9223372032840 * kMs);
  ASSERT_EQ(gaps.size(), 1u);
  GstClockTime gap_pts = 0, gap_duration = 0;
  gst_event_parse_gap(gaps[0], &gap_pts, &gap_duration);
  EXPECT_EQ(gap_pts, 10120 * kMs);
  EXPECT_EQ(gap_pts + gap_duration, GST_BUFFER_PTS(frames[253]));
  // The frame after the gap is the face at rest, as the one before it.
  EXPECT_EQ(face.picture(frames[252]), face.picture(frames[253]));
  unref_all(frames);
  for (GstEvent* e : gaps) gst_event_unref(e);
}

// A GAP from upstream (a TTS's silence) of an hour: the same, 10 s of frames, then a gap.
TEST(PfapFaceTiming, LongGapEventIsPassedOnAfterTenSecondsAtRest) {
  Face face;
  face.push(phoneme("HH", 0, 100));
  face.push_gap(100 * kMs, 3600 * GST_SECOND);
  face.push(phoneme("AY", 3600 * GST_SECOND + 100 * kMs, 100));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  // 0 .. 10.08 s, then the frame holding 3600.1 s and those of "AY".
  ASSERT_LT(frames.size(), 270u);
  EXPECT_EQ(GST_BUFFER_PTS(frames[252]), 10080 * kMs);
  EXPECT_EQ(GST_BUFFER_PTS(frames[253]), 3600080 * kMs);
  unref_all(frames);
}

TEST(PfapFaceTiming, EmptyStreamEndsWithoutFrames) {
  Face face;
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  EXPECT_EQ(frames.size(), 0u);
  EXPECT_TRUE(face.errors().empty());
}

// A live source: frames keep coming at the rate while no markup does.
TEST(PfapFaceTiming, LiveInputKeepsProducingFramesThroughSilence) {
  std::atomic<int> frames{0};  // outlives the pipeline, which counts into it
  Pipeline p(
      "appsrc name=src is-live=true format=time caps=application/x-pfap,alphabet=x-pfap-arpabet "
      "! pfapface ! video/x-raw,width=32,height=24,framerate=25/1 ! fakesink name=sink "
      "signal-handoffs=true sync=false");
  ASSERT_TRUE(p.ok()) << p.error();
  g_signal_connect(p.by_name("sink"), "handoff",
                   G_CALLBACK(+[](GstElement*, GstBuffer*, GstPad*, gpointer count) {
                     ++*static_cast<std::atomic<int>*>(count);
                   }),
                   &frames);
  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(pfap::testing::push(p.by_name("src"), phoneme("AA", 0, 100)), GST_FLOW_OK);
  // One phoneme of 100 ms and then nothing; 10 frames (400 ms) must come anyway.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (frames < 10 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_GE(frames.load(), 10);
  EXPECT_EQ(p.poll_error(), "");
  ASSERT_EQ(p.set_state(GST_STATE_NULL), "");
}

// ---------------------------------------------------------------------------------------------
// EOS, flushing, new streams, bad input

TEST(PfapFace, FlushBringsBackTheNeutralFaceAndTheFirstFrame) {
  const Picture neutral = still("M", {});
  Face face;
  face.push(phoneme("M", 0, 2000, {fap(49, 30000), fap(69, 63)}));
  face.push(phoneme("M", 2000 * kMs, 100));  // releases 50 frames
  std::vector<GstBuffer*> frames = face.frames(10);
  ASSERT_EQ(frames.size(), 10u);
  EXPECT_NE(face.picture(frames[5]), neutral);
  unref_all(frames);

  ASSERT_TRUE(gst_harness_push_event(face.harness(), gst_event_new_flush_start()));
  ASSERT_TRUE(gst_harness_push_event(face.harness(), gst_event_new_flush_stop(TRUE)));
  GstSegment segment;
  gst_segment_init(&segment, GST_FORMAT_TIME);
  ASSERT_TRUE(gst_harness_push_event(face.harness(), gst_event_new_segment(&segment)));
  while (GstBuffer* stale = gst_harness_try_pull(face.harness())) gst_buffer_unref(stale);
  face.push(phoneme("M", 0, 400));
  face.eos();
  frames = face.frames_until_eos();
  ASSERT_EQ(frames.size(), 10u);
  EXPECT_EQ(GST_BUFFER_PTS(frames[0]), 0u);
  EXPECT_EQ(face.picture(frames[5]), neutral) << "no yaw, no joy after the flush";
  unref_all(frames);
}

TEST(PfapFace, NewStreamStartsNeutral) {
  const Picture neutral = still("M", {});
  Face face;
  face.push(phoneme("M", 0, 200, {fap(49, 30000)}));
  ASSERT_TRUE(gst_harness_push_event(face.harness(), gst_event_new_stream_start("second")));
  GstSegment segment;
  gst_segment_init(&segment, GST_FORMAT_TIME);
  ASSERT_TRUE(gst_harness_push_event(face.harness(), gst_event_new_segment(&segment)));
  face.push(phoneme("M", 0, 400));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  ASSERT_GE(frames.size(), 6u);
  EXPECT_EQ(face.picture(frames.back()), neutral);
  unref_all(frames);
}

TEST(PfapFace, MalformedBufferIsDroppedWithAWarningAndFramesGoOn) {
  Face face;
  face.push(phoneme("M", 0, 200, {fap(49, 30000)}));
  GstBuffer* bad = gst_buffer_new_allocate(nullptr, 3, nullptr);
  gst_buffer_memset(bad, 0, 0xff, 3);
  GST_BUFFER_PTS(bad) = 200 * kMs;
  face.push(bad);
  face.push(phoneme("AA", 400 * kMs, 200));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  EXPECT_EQ(frames.size(), 15u) << "0 .. 600 ms";
  const std::vector<std::string> warnings = face.warnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("malformed"), std::string::npos) << warnings[0];
  // The good state before it is kept: the head is still turned. The eye band shows it (the
  // mouth differs anyway: AA against M).
  EXPECT_NE(face.picture(frames.back()), still("M", {}, 5));
  EXPECT_GT(mean_difference(face.picture(frames.back()), still("M", {}, 5), 55, 0, 105, 62), 0);
  unref_all(frames);
}

// The parser forgotten: filesrc gives bytes, with a BYTES segment and no times.
TEST(PfapFace, BytesWithoutPfapparseAreAnErrorNamingTheParserWithoutCriticals) {
  pfap::testing::GlibLogCounter log;
  Pipeline p("filesrc location=\"" + source_path("docs/examples/hello.pfap") +
             "\" ! pfapface ! fakesink name=sink");
  ASSERT_TRUE(p.ok()) << p.error();
  int frames = 0;
  g_object_set(p.by_name("sink"), "signal-handoffs", TRUE, nullptr);
  g_signal_connect(p.by_name("sink"), "handoff",
                   G_CALLBACK(+[](GstElement*, GstBuffer*, GstPad*, gpointer n) {
                     ++*static_cast<int*>(n);
                   }),
                   &frames);
  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  const std::string error = p.wait_eos(std::chrono::seconds(10));
  EXPECT_NE(error.find("error from pfapface"), std::string::npos) << error;
  EXPECT_NE(error.find("pfaptextparse"), std::string::npos) << error;
  EXPECT_NE(error.find("bytes segment"), std::string::npos) << error;
  EXPECT_EQ(frames, 0);
  ASSERT_EQ(p.set_state(GST_STATE_NULL), "");
  EXPECT_EQ(log.count(), 0) << log.first();
}

TEST(PfapFace, EventEarlierThanTheLastIsAppliedAtItsTimeWithAWarning) {
  Face face;
  face.push(phoneme("M", 400 * kMs, 200));
  face.push(phoneme("AA", 100 * kMs, 100));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  EXPECT_EQ(frames.size(), 15u);
  EXPECT_EQ(face.warnings().size(), 1u);
  unref_all(frames);
}

TEST(PfapFace, EarlierEventsAreWarnedAboutAtThe1st2nd4th8th) {
  // 200 events in reverse time order: 199 go back, 8 warnings (the 1st to the 128th).
  Face face;
  for (int i = 199; i >= 0; --i) face.push(phoneme("AA", i * 10 * kMs, 10));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  EXPECT_FALSE(frames.empty());
  const std::vector<std::string> warnings = face.warnings();
  ASSERT_EQ(warnings.size(), 8u);
  EXPECT_NE(warnings.back().find("earlier than the one before"), std::string::npos);
  unref_all(frames);
}

TEST(PfapFace, UnknownAlphabetWarnsOnceAndStillMovesTheMouth) {
  Face face(kSmallCaps, "application/x-pfap, alphabet=(string)x-klingon");
  for (int i = 0; i < 5; ++i) face.push(phoneme("AA", i * 200 * kMs, 200));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  ASSERT_EQ(frames.size(), 25u);
  const std::vector<std::string> warnings = face.warnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("mouth"), std::string::npos) << warnings[0];
  // Mid-phoneme (100 ms) the generic mouth is open; at the phoneme's edge (200 ms) closed.
  EXPECT_GT(mean_difference(face.picture(frames[2]), face.picture(frames[5])), 0.1);
  unref_all(frames);
}

TEST(PfapFace, StateEventsApply) {
  Face face;
  MarkupEvent complete;
  complete.kind = PFAP_EVENT_COMPLETE;
  complete.faps = {fap(49, 30000)};
  face.push(phoneme("M", 0, 100, {fap(69, 63)}));
  face.push(markup_buffer(complete, 100 * kMs));  // joy to 0, yaw set
  face.push(phoneme("M", 200 * kMs, 200));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  ASSERT_EQ(frames.size(), 10u);
  EXPECT_EQ(face.picture(frames[8]), still("M", {fap(49, 30000)}, 8));
  unref_all(frames);
}

// ---------------------------------------------------------------------------------------------
// Caps

TEST(PfapFaceCaps, DefaultIs640x480At25) {
  Face face(nullptr);
  face.push(phoneme("M", 0, 40));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(gst_buffer_get_size(frames[0]), 640u * 480 * 4);
  const std::string caps = face.output_caps();
  EXPECT_NE(caps.find("width=(int)640"), std::string::npos) << caps;
  EXPECT_NE(caps.find("height=(int)480"), std::string::npos) << caps;
  EXPECT_NE(caps.find("framerate=(fraction)25/1"), std::string::npos) << caps;
  EXPECT_NE(caps.find("format=(string)BGRx"), std::string::npos) << caps;
  unref_all(frames);
}

TEST(PfapFaceCaps, SizePropertiesFixateOpenCaps) {
  Face face("video/x-raw,framerate=[1/1,10/1]");
  g_object_set(face.element(), "width", 200, "height", 100, nullptr);
  face.push(phoneme("M", 0, 200));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  ASSERT_EQ(frames.size(), 2u) << "10 fps, the nearest to 25 allowed";
  EXPECT_EQ(GST_BUFFER_DURATION(frames[0]), 100 * kMs);
  const std::string caps = face.output_caps();
  EXPECT_NE(caps.find("width=(int)200"), std::string::npos) << caps;
  EXPECT_NE(caps.find("height=(int)100"), std::string::npos) << caps;
  unref_all(frames);
}

TEST(PfapFaceCaps, DownstreamChoosesAlphaAndSize) {
  Face face("video/x-raw,format=BGRA,width=64,height=48,framerate=50/1");
  face.push(phoneme("M", 0, 100));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  ASSERT_EQ(frames.size(), 5u);
  const Picture p = face.picture(frames[0]);
  for (int y = 0; y < p.height; ++y) {
    for (int x = 0; x < p.width; ++x) ASSERT_EQ(p.channel(x, y, 3), 255) << "opaque";
  }
  unref_all(frames);
}

TEST(PfapFaceCaps, RefusesWhatItCannotDraw) {
  GstElement* face = gst_element_factory_make("pfapface", nullptr);
  ASSERT_NE(face, nullptr);
  GstPad* src = gst_element_get_static_pad(face, "src");
  GstCaps* i420 = gst_caps_from_string("video/x-raw,format=I420,width=64,height=48");
  GstCaps* allowed = gst_pad_query_caps(src, i420);
  EXPECT_TRUE(gst_caps_is_empty(allowed));
  gst_caps_unref(allowed);
  gst_caps_unref(i420);
  gst_object_unref(src);
  gst_object_unref(face);
}

// ---------------------------------------------------------------------------------------------
// Pictures that must differ

// The mouth's box in a 160x120 frame (the head is 94 pixels high, centred).
constexpr int kMouthX0 = 60, kMouthX1 = 100, kMouthY0 = 75, kMouthY1 = 100;

TEST(PfapFacePictures, ClosedVisemeAndOpenVowelDifferInTheMouthOnly) {
  for (const char* style : {"cartoon", "line"}) {
    const Picture m = still("M", {}, 5, style), b = still("B", {}, 5, style),
                  p = still("P", {}, 5, style);
    const Picture aa = still("AA", {}, 5, style);
    EXPECT_EQ(m, b) << "p, b, m share a viseme";
    EXPECT_EQ(m, p);
    EXPECT_GT(mean_difference(m, aa, kMouthX0, kMouthY0, kMouthX1, kMouthY1), 10) << style;
    // Rows 0..62 hold the eyes (row 54) and all above; the head's sides (which a dropped
    // jaw moves a little) are outside columns 55..105.
    EXPECT_EQ(mean_difference(m, aa, 55, 0, 105, 62), 0) << "eyes and above unchanged";
  }
}

TEST(PfapFacePictures, ExpressionsChangeThePicture) {
  const Picture neutral = still("M", {});
  for (int index = 69; index <= 74; ++index) {
    const Picture expressive = still("M", {fap(index, 63)});
    // Joy, the subtlest, changes 0.73 on average (corners, cheeks, lower lids).
    EXPECT_GT(mean_difference(neutral, expressive), 0.5) << "FAP " << index;
  }
}

// Where the dark lines of a line drawing are, horizontally, in the band of the eyes.
double dark_centroid_x(const Picture& p, int y0, int y1) {
  double sum = 0, count = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < p.width; ++x) {
      if (p.channel(x, y, 1) < 100) {
        sum += x;
        ++count;
      }
    }
  }
  return count > 0 ? sum / count : -1;
}

TEST(PfapFacePictures, HeadYawMovesTheFace) {
  const Picture ahead = still("M", {}, 5, "line");
  const Picture left = still("M", {fap(49, 30000)}, 5, "line");
  const Picture right = still("M", {fap(49, -30000)}, 5, "line");
  // Eyes and nose: rows 45 to 80 of 120, without the head's outline at the sides.
  const double c = dark_centroid_x(ahead, 45, 80);
  EXPECT_NEAR(c, 80, 2) << "centred";
  EXPECT_GT(dark_centroid_x(left, 45, 80), c + 4) << "to the viewer's right";
  EXPECT_LT(dark_centroid_x(right, 45, 80), c - 4);
}

TEST(PfapFacePictures, DebugOverlayWritesAtTheTop) {
  Face face;
  g_object_set(face.element(), "debug-overlay", TRUE, nullptr);
  face.push(phoneme("AA", 0, 400, {fap(31, 200)}));
  face.eos();
  std::vector<GstBuffer*> frames = face.frames_until_eos();
  ASSERT_EQ(frames.size(), 10u);
  const Picture plain = still("AA", {fap(31, 200)});
  EXPECT_GT(mean_difference(face.picture(frames[5]), plain, 0, 0, 160, 10), 5);
  unref_all(frames);
}

// ---------------------------------------------------------------------------------------------
// Golden frames

// Frames of `session` through pfaptextparse and pfapface at 160x120, 25 fps.
std::vector<Picture> render_session(const std::string& session, const char* style,
                                    const std::vector<int>& indexes) {
  GstHarness* h = gst_harness_new_parse(
      ("pfaptextparse alphabet=x-pfap-arpabet ! pfapface style=" + std::string(style)).c_str());
  gst_harness_set_sink_caps_str(h, kSmallCaps);
  gst_harness_set_src_caps_str(h, "text/x-raw, format=(string)utf8");
  gchar* text = nullptr;
  gsize length = 0;
  EXPECT_TRUE(g_file_get_contents(source_path(session).c_str(), &text, &length, nullptr));
  EXPECT_EQ(gst_harness_push(h, gst_buffer_new_wrapped(text, length)), GST_FLOW_OK);
  EXPECT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
  std::vector<Picture> pictures;
  GstCaps* caps = nullptr;
  GstBuffer* buffer = nullptr;
  for (int i = 0; gst_harness_pull_until_eos(h, &buffer) && buffer != nullptr; ++i) {
    if (caps == nullptr) caps = gst_pad_get_current_caps(h->sinkpad);
    if (std::find(indexes.begin(), indexes.end(), i) != indexes.end()) {
      pictures.push_back(picture_of(buffer, caps));
    }
    gst_buffer_unref(buffer);
  }
  if (caps != nullptr) gst_caps_unref(caps);
  gst_harness_teardown(h);
  EXPECT_EQ(pictures.size(), indexes.size()) << session;
  return pictures;
}

void write_png(const Picture& p, const std::string& path) {
  cairo_surface_t* s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, p.width, p.height);
  cairo_surface_flush(s);
  unsigned char* data = cairo_image_surface_get_data(s);
  const int stride = cairo_image_surface_get_stride(s);
  for (int y = 0; y < p.height; ++y) {
    std::copy_n(&p.bgrx[y * p.width * 4], p.width * 4, data + y * stride);
  }
  cairo_surface_mark_dirty(s);
  EXPECT_EQ(cairo_surface_write_to_png(s, path.c_str()), CAIRO_STATUS_SUCCESS) << path;
  cairo_surface_destroy(s);
}

// The reference picture in `path`; empty when it cannot be read.
Picture read_png(const std::string& path) {
  cairo_surface_t* s = cairo_image_surface_create_from_png(path.c_str());
  Picture p;
  if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
    p.width = cairo_image_surface_get_width(s);
    p.height = cairo_image_surface_get_height(s);
    const unsigned char* data = cairo_image_surface_get_data(s);
    const int stride = cairo_image_surface_get_stride(s);
    for (int y = 0; y < p.height; ++y) {
      p.bgrx.insert(p.bgrx.end(), data + y * stride, data + y * stride + p.width * 4);
    }
  }
  cairo_surface_destroy(s);
  return p;
}

struct Golden {
  const char* session;
  const char* style;
  std::vector<int> frames;  // at 25 fps
};

// What each frame shows is in docs/face.md, "Golden frames".
const Golden kGolden[] = {
    {"docs/examples/hello.pfap", "cartoon", {2, 5, 11, 27, 39}},
    {"docs/examples/expressions.pfap", "cartoon", {30, 65, 100, 160}},
    {"docs/examples/face.pfap", "line", {8, 30, 45, 62, 75}},
};

TEST(PfapFaceGolden, FramesMatchTheReferences) {
  const bool update = std::getenv("PFAP_UPDATE_GOLDEN") != nullptr;
  for (const Golden& g : kGolden) {
    const std::vector<Picture> pictures = render_session(g.session, g.style, g.frames);
    ASSERT_EQ(pictures.size(), g.frames.size());
    std::string name = g.session;
    name = name.substr(name.rfind('/') + 1);
    name = name.substr(0, name.find('.'));
    for (size_t i = 0; i < pictures.size(); ++i) {
      const std::string path =
          source_path("tests/gst/golden/" + name + "-" + std::to_string(g.frames[i]) + ".png");
      if (update) write_png(pictures[i], path);
      const Picture reference = read_png(path);
      ASSERT_EQ(reference.width, pictures[i].width) << path << " (regenerate: see the top)";
      ASSERT_EQ(reference.height, pictures[i].height) << path;
      // Anti-aliasing may differ a little between cairo and pixman versions; a moved or
      // missing feature does not pass.
      int far_off = 0;
      for (int y = 0; y < reference.height; ++y) {
        for (int x = 0; x < reference.width; ++x) {
          for (int c = 0; c < 3; ++c) {
            far_off += std::abs(reference.channel(x, y, c) - pictures[i].channel(x, y, c)) > 64;
          }
        }
      }
      EXPECT_LT(mean_difference(reference, pictures[i]), 1.0) << path;
      EXPECT_LT(far_off, reference.width * reference.height * 3 / 200) << path;
    }
  }
}

// Golden frames at different times differ from each other: the test would notice a face
// that stopped moving.
TEST(PfapFaceGolden, ReferencesDiffer) {
  const Golden& g = kGolden[0];
  const std::vector<Picture> pictures = render_session(g.session, g.style, g.frames);
  ASSERT_EQ(pictures.size(), g.frames.size());
  for (size_t i = 1; i < pictures.size(); ++i) EXPECT_NE(pictures[i - 1], pictures[i]) << i;
}

// ---------------------------------------------------------------------------------------------
// The commands of docs/elements.md, "pfapface"

// The gst-launch-1.0 lines of docs/elements.md's pfapface section, as pipeline descriptions.
std::vector<std::string> documented_commands() {
  return launch_descriptions(doc_section("docs/elements.md", "## pfapface"));
}

// A documented command made runnable here: the source tree's examples, output files in
// `dir`, a fakesink named "out" for the display.
std::string runnable(std::string command, const TempDir& dir) {
  replace_all(command, "docs/examples/", source_path("docs/examples/"));
  replace_all(command, "face.webm", dir.file("face.webm"));
  replace_all(command, "frame-%04d.png", dir.file("frame-%04d.png"));
  replace_all(command, "autovideosink", "fakesink name=out sync=false");
  return command;
}

TEST(PfapFaceDocumented, EveryCommandIsHere) { EXPECT_EQ(documented_commands().size(), 6u); }

// The four file commands run to EOS; the one without an alphabet warns once.
TEST(PfapFaceDocumented, FilesRenderToTheEnd) {
  const std::vector<std::string> commands = documented_commands();
  ASSERT_EQ(commands.size(), 6u);
  for (size_t i = 0; i < 4; ++i) {
    TempDir dir;
    Pipeline p(runnable(commands[i], dir));
    ASSERT_TRUE(p.ok()) << p.error();
    ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "") << commands[i];
    if (commands[i].find("alphabet=") == std::string::npos) {
      EXPECT_NE(p.wait_eos(std::chrono::seconds(60), true).find("mouth"), std::string::npos)
          << "a warning first: " << commands[i];
    }
    EXPECT_EQ(p.wait_eos(std::chrono::seconds(60), true), "") << commands[i];
    if (commands[i].find("face.webm") != std::string::npos) {
      EXPECT_GT(read_file(dir.file("face.webm")).size(), 10000u);
    }
    if (commands[i].find("pngenc") != std::string::npos) {
      EXPECT_EQ(dir.count(), 59) << "hello.pfap: its smile fades until 2.33 s";
      EXPECT_EQ(read_png(dir.file("frame-0000.png")).width, 640);
    }
  }
}

// Received over UDP, live: frames come while the session is sent, and keep coming after it.
TEST(PfapFaceDocumented, LiveOverRtp) {
  const std::vector<std::string> commands = documented_commands();
  ASSERT_EQ(commands.size(), 6u);
  std::atomic<int> frames{0};  // outlives the receiver, which counts into it
  TempDir dir;
  std::string receive = runnable(commands[4], dir);
  replace_all(receive, "port=5004", "port=0 name=udp");
  replace_all(receive, "sync=false", "sync=false signal-handoffs=true");
  Pipeline receiver(receive);
  ASSERT_TRUE(receiver.ok()) << receiver.error();
  g_signal_connect(receiver.by_name("out"), "handoff",
                   G_CALLBACK(+[](GstElement*, GstBuffer*, GstPad*, gpointer count) {
                     ++*static_cast<std::atomic<int>*>(count);
                   }),
                   &frames);
  ASSERT_EQ(receiver.set_state(GST_STATE_PLAYING), "");
  std::string send = runnable(commands[5], dir);
  replace_all(send, "port=5004",
              "port=" + std::to_string(pfap::testing::bound_port(receiver.by_name("udp"))));
  Pipeline sender(send);
  ASSERT_TRUE(sender.ok()) << sender.error();
  ASSERT_EQ(sender.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(sender.wait_eos(std::chrono::seconds(10)), "") << "sent in real time";
  const int at_end = frames;
  EXPECT_GT(at_end, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (frames < at_end + 10 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_GE(frames.load(), at_end + 10) << "frames go on in the silence after the session";
  EXPECT_EQ(receiver.poll_error(true), "");
  ASSERT_EQ(receiver.set_state(GST_STATE_NULL), "");
}

}  // namespace
