// SPDX-License-Identifier: LGPL-2.1-or-later
// pfaptts: text in, espeak-ng speech on `audio` and its phonemes on `pfap`, on one timeline.
// GstHarness on the sink pad and the `audio` pad, a second harness on the `pfap` pad.
#include <gst/check/gstharness.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <iostream>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "element_harness.h"
#include "glib_log.h"
#include "heap.h"
#include "lip_sync.h"
#include "pfap/markup.h"
#include "pfap_buffers.h"
#include "pipeline.h"

namespace {

using pfap::testing::Event;
using pfap::testing::pop_messages;

constexpr int kRate = 22050;  // Debian's espeak-ng voices

GstBuffer* text_buffer(std::string_view text, GstClockTime pts = GST_CLOCK_TIME_NONE) {
  GstBuffer* buffer = gst_buffer_new_memdup(text.data(), text.size());
  GST_BUFFER_PTS(buffer) = pts;
  return buffer;
}

struct Audio {
  GstClockTime pts;
  GstClockTime duration;
  uint64_t offset;
  uint64_t offset_end;
  bool discont_flag;
  std::vector<int16_t> samples;
};

// pfaptts between two harnesses: the shared fixture's on the sink pad and `audio`, a second
// one on `pfap`.
class Tts : public pfap::testing::ElementHarness {
 public:
  Tts() : ElementHarness(gst_harness_new_with_padnames("pfaptts", "sink", "audio")) {
    pfap_ = gst_harness_new_with_element(h_->element, nullptr, "pfap");
    gst_harness_set_src_caps_str(h_, "text/x-raw, format=(string)utf8");
  }
  ~Tts() { gst_harness_teardown(pfap_); }

  GstHarness* pfap_harness() { return pfap_; }

  GstFlowReturn say(std::string_view text, GstClockTime pts = GST_CLOCK_TIME_NONE) {
    return gst_harness_push(h_, text_buffer(text, pts));
  }

  std::vector<Audio> audio() {
    std::vector<Audio> out;
    while (GstBuffer* b = gst_harness_try_pull(h_)) {
      Audio a{GST_BUFFER_PTS(b),
              GST_BUFFER_DURATION(b),
              GST_BUFFER_OFFSET(b),
              GST_BUFFER_OFFSET_END(b),
              GST_BUFFER_FLAG_IS_SET(b, GST_BUFFER_FLAG_DISCONT),
              {}};
      GstMapInfo map;
      gst_buffer_map(b, &map, GST_MAP_READ);
      const auto* s = reinterpret_cast<const int16_t*>(map.data);
      for (size_t i = 0; i < map.size / 2; ++i) a.samples.push_back(GINT16_FROM_LE(s[i]));
      gst_buffer_unmap(b, &map);
      gst_buffer_unref(b);
      out.push_back(std::move(a));
    }
    return out;
  }

  std::vector<Event> phonemes() {
    std::vector<Event> out;
    while (GstBuffer* b = gst_harness_try_pull(pfap_)) {
      out.push_back(pfap::testing::read_event(b));
      gst_buffer_unref(b);
    }
    return out;
  }

  // Events downstream of `pad` harness, of one type (the rest dropped).
  static std::vector<GstEvent*> events(GstHarness* h, GstEventType type) {
    std::vector<GstEvent*> out;
    while (GstEvent* e = gst_harness_try_pull_event(h)) {
      if (GST_EVENT_TYPE(e) == type) {
        out.push_back(e);
      } else {
        gst_event_unref(e);
      }
    }
    return out;
  }


 private:
  GstHarness* pfap_;
};

uint64_t total_samples(const std::vector<Audio>& audio) {
  uint64_t n = 0;
  for (const Audio& a : audio) n += a.samples.size();
  return n;
}

GstClockTime at_sample(uint64_t n) { return gst_util_uint64_scale(n, GST_SECOND, kRate); }

void unref_all(std::vector<GstEvent*>& events) {
  for (GstEvent* e : events) gst_event_unref(e);
  events.clear();
}

TEST(PfapTts, CapsStreamStartAndSegmentOnBothPads) {
  Tts t;
  ASSERT_EQ(t.say("Hello world."), GST_FLOW_OK);

  GstCaps* audio_caps = gst_pad_get_current_caps(t.harness()->sinkpad);
  ASSERT_NE(audio_caps, nullptr);
  GstCaps* want =
      gst_caps_from_string("audio/x-raw,format=S16LE,layout=interleaved,rate=22050,channels=1");
  EXPECT_TRUE(gst_caps_is_equal(audio_caps, want));
  gst_caps_unref(want);
  gst_caps_unref(audio_caps);

  GstCaps* pfap_caps = gst_pad_get_current_caps(t.pfap_harness()->sinkpad);
  ASSERT_NE(pfap_caps, nullptr);
  EXPECT_STREQ(gst_structure_get_string(gst_caps_get_structure(pfap_caps, 0), "alphabet"),
               "x-pfap-arpabet");
  gst_caps_unref(pfap_caps);

  for (GstHarness* h : {t.harness(), t.pfap_harness()}) {
    GstEvent* start = gst_pad_get_sticky_event(h->sinkpad, GST_EVENT_STREAM_START, 0);
    ASSERT_NE(start, nullptr);
    GstStreamFlags flags;
    gst_event_parse_stream_flags(start, &flags);
    EXPECT_EQ((flags & GST_STREAM_FLAG_SPARSE) != 0, h == t.pfap_harness());
    gst_event_unref(start);
    GstEvent* segment_event = gst_pad_get_sticky_event(h->sinkpad, GST_EVENT_SEGMENT, 0);
    ASSERT_NE(segment_event, nullptr);
    const GstSegment* segment = nullptr;
    gst_event_parse_segment(segment_event, &segment);
    EXPECT_EQ(segment->format, GST_FORMAT_TIME);
    EXPECT_EQ(segment->start, 0u);
    gst_event_unref(segment_event);
  }
}

TEST(PfapTts, PhonemesAreTimedByTheAudio) {
  Tts t;
  ASSERT_EQ(t.say("Hello <FAP 2 1 40 0 0 500 1> world, <FAP 48 20000 800 3> how are you?"),
            GST_FLOW_OK);
  const std::vector<Audio> audio = t.audio();
  const std::vector<Event> phonemes = t.phonemes();
  ASSERT_FALSE(audio.empty());
  ASSERT_GT(phonemes.size(), 10u);

  // Audio: contiguous, timestamps from the sample count.
  uint64_t n = 0;
  for (const Audio& a : audio) {
    EXPECT_EQ(a.offset, n);
    EXPECT_EQ(a.pts, at_sample(n));
    n += a.samples.size();
    EXPECT_EQ(a.offset_end, n);
    EXPECT_EQ(a.pts + a.duration, at_sample(n));
  }

  // Phonemes tile the audio: each starts where the one before ended, the last ends with the
  // audio; durations in ms add up to its length.
  EXPECT_EQ(phonemes.front().pts, 0u);
  uint64_t sum_ms = 0;
  int with_faps = 0;
  for (size_t i = 0; i < phonemes.size(); ++i) {
    const Event& e = phonemes[i];
    EXPECT_EQ(e.kind, PFAP_EVENT_PHONEME);
    if (i + 1 < phonemes.size()) {
      EXPECT_EQ(e.pts + e.duration, phonemes[i + 1].pts) << i;
      EXPECT_LT(e.pts, phonemes[i + 1].pts) << i;
    }
    // The PTS is a sample position.
    const uint64_t sample = gst_util_uint64_scale_round(e.pts, kRate, GST_SECOND);
    EXPECT_EQ(at_sample(sample), e.pts) << i;
    sum_ms += e.phoneme.duration_ms;
    with_faps += !e.faps.empty();
  }
  EXPECT_EQ(phonemes.back().pts + phonemes.back().duration, at_sample(n));
  EXPECT_NEAR(static_cast<double>(sum_ms), n * 1000.0 / kRate, 1.0);
  EXPECT_EQ(with_faps, 2);
  EXPECT_TRUE(phonemes.front().flags & PFAP_FLAG_SENTENCE_START);
  EXPECT_TRUE(phonemes.back().flags & PFAP_FLAG_END_OF_TEXT);
  EXPECT_TRUE(phonemes.front().discont);
  EXPECT_TRUE(audio.front().discont_flag);
}

TEST(PfapTts, EosOnBothPads) {
  Tts t;
  ASSERT_EQ(t.say("Yes."), GST_FLOW_OK);
  ASSERT_TRUE(gst_harness_push_event(t.harness(), gst_event_new_eos()));
  for (GstHarness* h : {t.harness(), t.pfap_harness()}) {
    std::vector<GstEvent*> eos = Tts::events(h, GST_EVENT_EOS);
    EXPECT_EQ(eos.size(), 1u);
    unref_all(eos);
  }
}

TEST(PfapTts, EosWithoutTextStillGivesCaps) {
  Tts t;
  ASSERT_TRUE(gst_harness_push_event(t.harness(), gst_event_new_eos()));
  EXPECT_TRUE(gst_pad_has_current_caps(t.harness()->sinkpad));
  EXPECT_TRUE(gst_pad_has_current_caps(t.pfap_harness()->sinkpad));
  std::vector<GstEvent*> eos = Tts::events(t.pfap_harness(), GST_EVENT_EOS);
  EXPECT_EQ(eos.size(), 1u);
  unref_all(eos);
}

TEST(PfapTts, FlushStartsTheTimelineAgain) {
  Tts t;
  ASSERT_EQ(t.say("One two three."), GST_FLOW_OK);
  ASSERT_FALSE(t.audio().empty());
  ASSERT_FALSE(t.phonemes().empty());
  ASSERT_TRUE(gst_harness_push_event(t.harness(), gst_event_new_flush_start()));
  ASSERT_TRUE(gst_harness_push_event(t.harness(), gst_event_new_flush_stop(TRUE)));
  for (GstHarness* h : {t.harness(), t.pfap_harness()}) {
    std::vector<GstEvent*> stops = Tts::events(h, GST_EVENT_FLUSH_STOP);
    EXPECT_EQ(stops.size(), 1u);
    unref_all(stops);
  }
  GstSegment segment;
  gst_segment_init(&segment, GST_FORMAT_TIME);
  ASSERT_TRUE(gst_harness_push_event(t.harness(), gst_event_new_segment(&segment)));
  ASSERT_EQ(t.say("Four."), GST_FLOW_OK);
  const std::vector<Audio> audio = t.audio();
  const std::vector<Event> phonemes = t.phonemes();
  ASSERT_FALSE(audio.empty());
  ASSERT_FALSE(phonemes.empty());
  EXPECT_EQ(audio[0].pts, 0u);
  EXPECT_EQ(audio[0].offset, 0u);
  EXPECT_EQ(phonemes[0].pts, 0u);
  EXPECT_TRUE(phonemes[0].discont);
  // The same stream goes on: a new segment, no new stream-start.
  for (GstHarness* h : {t.harness(), t.pfap_harness()}) {
    std::vector<GstEvent*> starts = Tts::events(h, GST_EVENT_STREAM_START);
    EXPECT_TRUE(starts.empty());
    unref_all(starts);
    GstEvent* segment_event = gst_pad_get_sticky_event(h->sinkpad, GST_EVENT_SEGMENT, 0);
    EXPECT_NE(segment_event, nullptr);
    if (segment_event != nullptr) gst_event_unref(segment_event);
  }
}

TEST(PfapTts, BadBookmarkIsAnErrorNamingItsCharacter) {
  Tts t;
  EXPECT_EQ(t.say("Héllo <FAP 3 1 0 7> world."), GST_FLOW_ERROR);
  const std::vector<std::string> errors = t.errors();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("character 18"), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("curve"), std::string::npos) << errors[0];
  EXPECT_TRUE(t.phonemes().empty());
}

TEST(PfapTts, BadBookmarkSkippedWithAWarning) {
  Tts t;
  g_object_set(t.element(), "skip-bad-bookmarks", TRUE, nullptr);
  EXPECT_EQ(t.say("Hello <FAP 3 1 0 7> big <FAP 4 5 0 1> world."), GST_FLOW_OK);
  const std::vector<std::string> warnings = t.warnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("character 18: curve"), std::string::npos) << warnings[0];
  EXPECT_TRUE(t.errors().empty());
  // The good bookmark is there, on "world"'s first phoneme.
  const std::vector<Event> phonemes = t.phonemes();
  int faps = 0;
  for (const Event& e : phonemes) {
    for (const pfap::Fap& f : e.faps) {
      ++faps;
      EXPECT_EQ(f.index, 4);
      EXPECT_TRUE(e.phoneme.word_begin);
    }
  }
  EXPECT_EQ(faps, 1);
}

// 10,000 bad bookmarks in one text: warnings at the 1st, 2nd, 4th, ... 8192nd (14), every one
// counted in bad-bookmarks, the text spoken.
TEST(PfapTts, BadBookmarkWarningsAreRateLimited) {
  Tts t;
  g_object_set(t.element(), "skip-bad-bookmarks", TRUE, nullptr);
  std::string text;
  for (int i = 0; i < 10000; ++i) text += "<FAP 3 1 0 7>";
  text += " Hello.";
  EXPECT_EQ(t.say(text), GST_FLOW_OK);
  const std::vector<std::string> warnings = t.warnings();
  EXPECT_EQ(warnings.size(), 14u);
  guint64 bad = 0;
  g_object_get(t.element(), "bad-bookmarks", &bad, nullptr);
  EXPECT_EQ(bad, 10000u);
  EXPECT_FALSE(t.phonemes().empty());
}

// The outside tester's 1 MiB text in one buffer (docs/tts.md, "Long texts"): spoken a sentence
// at a time, so the first audio comes after the first sentence's synthesis (the whole text
// would take minutes), the heap holds one sentence's speech, and going to NULL mid-text
// returns at once.
TEST(PfapTts, LongTextSpeaksSentenceBySentenceAndStopsAtOnce) {
  std::string text;
  while (text.size() < (1u << 20)) text += "The quick brown fox jumps over the lazy dog. ";
  text.resize(1u << 20);
  pfap::testing::Pipeline p(
      "appsrc name=src format=time ! text/x-raw,format=utf8 ! pfaptts name=t "
      "t.audio ! queue ! fakesink name=audio sync=false t.pfap ! queue ! fakesink sync=false");
  ASSERT_TRUE(p.ok()) << p.error();

  struct Watch {
    std::mutex mutex;
    std::condition_variable cond;
    std::chrono::steady_clock::time_point first_audio{};
    uint64_t samples = 0;
    size_t peak_heap = 0;
  } watch;
  GstPad* audio = gst_element_get_static_pad(p.by_name("t"), "audio");
  gst_pad_add_probe(
      audio, GST_PAD_PROBE_TYPE_BUFFER,
      [](GstPad*, GstPadProbeInfo* info, gpointer data) {
        auto* w = static_cast<Watch*>(data);
        std::lock_guard lock(w->mutex);
        if (w->samples == 0) w->first_audio = std::chrono::steady_clock::now();
        w->samples += gst_buffer_get_size(GST_PAD_PROBE_INFO_BUFFER(info)) / 2;
        w->peak_heap = std::max(w->peak_heap, pfap::testing::heap_bytes());
        w->cond.notify_all();
        return GST_PAD_PROBE_OK;
      },
      &watch, nullptr);
  gst_object_unref(audio);

  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  const size_t heap_before = pfap::testing::heap_bytes();
  const auto pushed = std::chrono::steady_clock::now();
  ASSERT_EQ(pfap::testing::push(p.by_name("src"), gst_buffer_new_memdup(text.data(), text.size())),
            GST_FLOW_OK);
  {
    std::unique_lock lock(watch.mutex);
    ASSERT_TRUE(watch.cond.wait_for(lock, std::chrono::seconds(5), [&] { return watch.samples > 0; }))
        << "no audio 5 s after a 1 MiB text";
    const auto first_ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(watch.first_audio - pushed).count();
    EXPECT_LT(first_ms, 1000) << "the first audio came " << first_ms << " ms after the text";
    // Some sentences later: 20 s of speech.
    ASSERT_TRUE(watch.cond.wait_for(lock, std::chrono::seconds(20),
                                    [&] { return watch.samples > 20u * kRate; }));
  }
  const auto stop = std::chrono::steady_clock::now();
  EXPECT_EQ(gst_element_set_state(p.get(), GST_STATE_NULL), GST_STATE_CHANGE_SUCCESS);
  const auto stop_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                           std::chrono::steady_clock::now() - stop)
                           .count();
  EXPECT_LT(stop_ms, 1000) << "to NULL mid-text took " << stop_ms << " ms";
  std::lock_guard lock(watch.mutex);
  // The text (1 MiB, and 4 MiB as code points) and a sentence's speech; the whole text's speech
  // would be 2.5 GB.
  EXPECT_LT(watch.peak_heap - std::min(watch.peak_heap, heap_before), 32u << 20)
      << "heap grew while speaking " << watch.samples / kRate << " s of a long text";
}

// The slowest piece to synthesize: 400 CJK characters (the longest piece) at the slowest rate
// are minutes of speech, seconds of synthesis and f0. A flush, and going to NULL, in the middle
// of it stop espeak-ng and the f0 at once.
TEST(PfapTts, FlushAndStateChangeStopASynthesisInTheMiddle) {
  std::string text;
  for (int i = 0; i < 1200; ++i) text += "\u6F22";
  pfap::testing::Pipeline p(
      "appsrc name=src format=time ! text/x-raw,format=utf8 ! pfaptts name=t rate=80 "
      "t.audio ! queue ! fakesink sync=false t.pfap ! queue ! fakesink sync=false");
  ASSERT_TRUE(p.ok()) << p.error();
  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  auto ms_since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() -
                                                                 t)
        .count();
  };
  GstElement* src = p.by_name("src");
  GstPad* sink = gst_element_get_static_pad(p.by_name("t"), "sink");
  ASSERT_EQ(pfap::testing::push(src, gst_buffer_new_memdup(text.data(), text.size())), GST_FLOW_OK);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  // flush-stop waits for the streaming thread to leave the element.
  auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(gst_pad_send_event(sink, gst_event_new_flush_start()));
  EXPECT_TRUE(gst_pad_send_event(sink, gst_event_new_flush_stop(FALSE)));
  EXPECT_LT(ms_since(start), 1000) << "a flush mid-synthesis took " << ms_since(start) << " ms";
  gst_object_unref(sink);

  ASSERT_EQ(pfap::testing::push(src, gst_buffer_new_memdup(text.data(), text.size())), GST_FLOW_OK);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  start = std::chrono::steady_clock::now();
  EXPECT_EQ(gst_element_set_state(p.get(), GST_STATE_NULL), GST_STATE_CHANGE_SUCCESS);
  EXPECT_LT(ms_since(start), 1000) << "to NULL mid-synthesis took " << ms_since(start) << " ms";
}

TEST(PfapTts, UtterancePtsGivesSilenceAndGap) {
  Tts t;
  ASSERT_EQ(t.say("First.", 0), GST_FLOW_OK);
  const uint64_t first_end = total_samples(t.audio());
  const std::vector<Event> first = t.phonemes();
  ASSERT_FALSE(first.empty());
  std::vector<GstEvent*> no_gaps = Tts::events(t.pfap_harness(), GST_EVENT_GAP);
  EXPECT_TRUE(no_gaps.empty());
  unref_all(no_gaps);

  ASSERT_EQ(t.say("Second.", 3 * GST_SECOND), GST_FLOW_OK);
  const std::vector<Audio> audio = t.audio();
  const std::vector<Event> second = t.phonemes();
  ASSERT_FALSE(second.empty());
  EXPECT_EQ(second.front().pts, 3 * GST_SECOND);
  EXPECT_TRUE(second.front().flags & PFAP_FLAG_SENTENCE_START);
  // Zero samples from the end of the first utterance to 3 s.
  const uint64_t silence = 3 * kRate - first_end;
  uint64_t zeros = 0;
  for (const Audio& a : audio) {
    if (a.pts >= 3 * GST_SECOND) break;
    for (int16_t v : a.samples) {
      EXPECT_EQ(v, 0);
      ++zeros;
    }
  }
  EXPECT_EQ(zeros, silence);
  EXPECT_EQ(audio.front().pts, at_sample(first_end));
  std::vector<GstEvent*> gaps = Tts::events(t.pfap_harness(), GST_EVENT_GAP);
  ASSERT_EQ(gaps.size(), 1u);
  GstClockTime gap_start, gap_duration;
  gst_event_parse_gap(gaps[0], &gap_start, &gap_duration);
  EXPECT_EQ(gap_start, at_sample(first_end));
  EXPECT_EQ(gap_start + gap_duration, 3 * GST_SECOND);
  unref_all(gaps);

  // Without a PTS, the next utterance follows at once.
  const uint64_t second_end = 3 * kRate + total_samples(audio) - silence;
  ASSERT_EQ(t.say("Third."), GST_FLOW_OK);
  const std::vector<Event> third = t.phonemes();
  ASSERT_FALSE(third.empty());
  EXPECT_EQ(third.front().pts, at_sample(second_end));
  EXPECT_EQ(first.front().pts, 0u);
}

// 50 utterances, most at given times and some right after the one before: every phoneme stays
// inside its utterance's audio, and the last ends exactly with the audio.
TEST(PfapTts, LongSessionDoesNotDrift) {
  Tts t;
  g_object_set(t.element(), "rate", 450, nullptr);
  GstClockTime at = 0;
  uint64_t samples = 0;
  size_t n_phonemes = 0;
  for (int i = 0; i < 50; ++i) {
    SCOPED_TRACE("utterance " + std::to_string(i));
    const bool timed = i % 5 != 4;
    if (timed) {
      at = std::max(at, at_sample(samples)) + 123'456'789;  // a pause of ~123 ms
    }
    ASSERT_EQ(t.say("Number " + std::to_string(i) + " is here.", timed ? at : GST_CLOCK_TIME_NONE),
              GST_FLOW_OK);
    const std::vector<Audio> audio = t.audio();
    const std::vector<Event> phonemes = t.phonemes();
    ASSERT_FALSE(phonemes.empty());
    const uint64_t begin = samples;
    samples += total_samples(audio);
    // Where the speech starts: at its time (rounded to a sample), or at once.
    const uint64_t speech_start =
        timed ? gst_util_uint64_scale_round(at, kRate, GST_SECOND) : begin;
    EXPECT_EQ(phonemes.front().pts, at_sample(speech_start));
    EXPECT_EQ(phonemes.back().pts + phonemes.back().duration, at_sample(samples));
    for (const Event& e : phonemes) {
      EXPECT_GE(e.pts, at_sample(speech_start));
      EXPECT_LT(e.pts, at_sample(samples));
    }
    n_phonemes += phonemes.size();
    GstClockTime end = GST_CLOCK_TIME_NONE;
    for (const Audio& a : audio) end = a.pts + a.duration;
    EXPECT_EQ(end, at_sample(samples));
  }
  EXPECT_GT(n_phonemes, 500u);
  EXPECT_GT(samples, 50u * kRate / 2);
}

// What gst-inspect-1.0 shows: every property of its own has a blurb, and the defaults.
TEST(PfapTts, PropertiesAreDocumented) {
  GstElement* tts = gst_element_factory_make("pfaptts", nullptr);
  ASSERT_NE(tts, nullptr);
  guint n = 0;
  GParamSpec** specs = g_object_class_list_properties(G_OBJECT_GET_CLASS(tts), &n);
  std::vector<std::string> own;
  for (guint i = 0; i < n; ++i) {
    if (specs[i]->owner_type != G_OBJECT_TYPE(tts)) continue;
    own.push_back(g_param_spec_get_name(specs[i]));
    const gchar* blurb = g_param_spec_get_blurb(specs[i]);
    EXPECT_TRUE(blurb != nullptr && *blurb != '\0') << own.back();
  }
  g_free(specs);
  std::sort(own.begin(), own.end());
  EXPECT_EQ(own, (std::vector<std::string>{"bad-bookmarks", "pitch", "rate", "skip-bad-bookmarks",
                                           "stats", "text", "voice", "volume"}));
  gchar* voice = nullptr;
  gint rate = 0, pitch = 0, volume = 0;
  g_object_get(tts, "voice", &voice, "rate", &rate, "pitch", &pitch, "volume", &volume, nullptr);
  EXPECT_STREQ(voice, "en");
  EXPECT_EQ(rate, 175);
  EXPECT_EQ(pitch, 50);
  EXPECT_EQ(volume, 100);
  g_free(voice);
  gst_object_unref(tts);
}

// rate=1000 in gst-launch: GObject refuses it by the range gst-inspect shows (80 - 450),
// with a warning naming the property, and the speech keeps its rate.
TEST(PfapTts, OutOfRangeNumbersAreRefusedByTheirRanges) {
  GstElement* tts = gst_element_factory_make("pfaptts", nullptr);
  ASSERT_NE(tts, nullptr);
  const struct {
    const char* name;
    gint minimum, maximum, default_value;
    const char* bad;
  } cases[] = {{"rate", 80, 450, 175, "1000"}, {"pitch", 0, 100, 50, "-1"},
               {"volume", 0, 200, 100, "201"}};
  for (const auto& c : cases) {
    const GParamSpecInt* spec =
        G_PARAM_SPEC_INT(g_object_class_find_property(G_OBJECT_GET_CLASS(tts), c.name));
    EXPECT_EQ(spec->minimum, c.minimum) << c.name;
    EXPECT_EQ(spec->maximum, c.maximum) << c.name;
    {
      pfap::testing::GlibLogCounter log;
      gst_util_set_object_arg(G_OBJECT(tts), c.name, c.bad);
      EXPECT_EQ(log.count(), 1) << c.name;
      EXPECT_NE(log.first().find(c.name), std::string::npos) << log.first();
    }
    gint value = 0;
    g_object_get(tts, c.name, &value, nullptr);
    EXPECT_EQ(value, c.default_value) << c.name;
  }
  gst_object_unref(tts);
}

TEST(PfapTts, UnknownVoiceFailsTheStateChange) {
  GstElement* tts = gst_element_factory_make("pfaptts", nullptr);
  ASSERT_NE(tts, nullptr);
  GstBus* bus = gst_bus_new();
  gst_element_set_bus(tts, bus);
  g_object_set(tts, "voice", "no-such-voice", nullptr);
  EXPECT_EQ(gst_element_set_state(tts, GST_STATE_PAUSED), GST_STATE_CHANGE_FAILURE);
  const std::vector<std::string> errors = pop_messages(bus, GST_MESSAGE_ERROR);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("no-such-voice"), std::string::npos) << errors[0];
  gst_element_set_state(tts, GST_STATE_NULL);
  gst_bus_set_flushing(bus, TRUE);
  gst_object_unref(bus);
  gst_object_unref(tts);
}

// The text property with the sink pad unlinked: the element speaks from its own thread and
// ends both streams.
TEST(PfapTts, TextPropertySpeaksAndEnds) {
  pfap::testing::Pipeline p(
      "pfaptts name=t text=\"Hello <FAP 3 100 0 1> world.\" "
      "t.audio ! queue ! appsink name=audio sync=false emit-signals=false wait-on-eos=false "
      "t.pfap ! queue ! appsink name=pfap sync=false emit-signals=false wait-on-eos=false");
  ASSERT_TRUE(p.ok()) << p.error();
  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(p.wait_eos(std::chrono::seconds(10)), "");
  std::vector<GstSample*> audio = pfap::testing::pull_all(p.by_name("audio"));
  std::vector<GstSample*> pfap = pfap::testing::pull_all(p.by_name("pfap"));
  EXPECT_FALSE(audio.empty());
  ASSERT_GT(pfap.size(), 5u);
  int faps = 0;
  for (GstSample* s : pfap) {
    faps += static_cast<int>(pfap::testing::read_event(gst_sample_get_buffer(s)).faps.size());
  }
  EXPECT_EQ(faps, 1);
  for (GstSample* s : audio) gst_sample_unref(s);
  for (GstSample* s : pfap) gst_sample_unref(s);
}

// ---------------------------------------------------------------------------------------------
// Loopback: pfaptts ! rtpL16pay and rtppfappay through one rtpbin, over UDP on 127.0.0.1, into
// another rtpbin ! rtpL16depay and rtppfapdepay. The measurement is LoopbackUdp's
// (test_pipeline.cc, lip_sync.h): each received phoneme's offset (receiver minus sender running
// time) against the offset of the audio sent at the same time, within 1 ms once rtpbin's RTCP
// sync is in place. The sender is not live: its udpsinks send both streams in real time.

// What reaches a payloader's sink pad: the phonemes with their running times, and EOS.
struct SentPhonemes {
  std::mutex mutex;
  std::vector<Event> events;
  std::atomic<int> eos{0};  // payloaders (audio and PFAP) that have had EOS

  static GstPadProbeReturn on_pfap(GstPad*, GstPadProbeInfo* info, gpointer data) {
    auto* sent = static_cast<SentPhonemes*>(data);
    std::lock_guard lock(sent->mutex);
    sent->events.push_back(pfap::testing::read_event(GST_PAD_PROBE_INFO_BUFFER(info)));
    return GST_PAD_PROBE_OK;
  }
  static GstPadProbeReturn on_event(GstPad*, GstPadProbeInfo* info, gpointer data) {
    if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) == GST_EVENT_EOS) {
      static_cast<SentPhonemes*>(data)->eos++;
    }
    return GST_PAD_PROBE_OK;
  }
};

TEST(PfapTtsLoopback, ReceivedPhonemesLineUpWithTheAudio) {
  pfap::testing::SentAudio sent_audio(kRate);
  SentPhonemes sent;
  pfap::testing::Received received;
  pfap::testing::ReceiverLinks links{nullptr, nullptr, &received};

  pfap::testing::Pipeline receiver(
      "rtpbin name=rtpbin buffer-mode=none "
      "udpsrc name=audio_rtp address=127.0.0.1 port=0 caps=\"application/x-rtp,media=audio,"
      "clock-rate=22050,encoding-name=L16,channels=1,payload=96\" ! rtpbin.recv_rtp_sink_0 "
      "udpsrc name=audio_rtcp address=127.0.0.1 port=0 ! rtpbin.recv_rtcp_sink_0 "
      "rtpbin.send_rtcp_src_0 ! udpsink name=audio_rr host=127.0.0.1 sync=false async=false "
      "udpsrc name=pfap_rtp address=127.0.0.1 port=0 caps=\"application/x-rtp,"
      "media=application,clock-rate=44100,encoding-name=PFAP,payload=97\" "
      "! rtpbin.recv_rtp_sink_1 "
      "udpsrc name=pfap_rtcp address=127.0.0.1 port=0 ! rtpbin.recv_rtcp_sink_1 "
      "rtpbin.send_rtcp_src_1 ! udpsink name=pfap_rr host=127.0.0.1 sync=false async=false "
      "rtpL16depay name=audio_depay ! appsink name=audio_sink sync=false emit-signals=true "
      "rtppfapdepay name=pfap_depay ! appsink name=pfap_sink sync=false emit-signals=true");
  ASSERT_TRUE(receiver.ok()) << receiver.error();
  pfap::testing::Pipeline sender(
      "rtpbin name=rtpbin sdes=\"application/x-rtp-source-sdes,cname=(string)pfaptts-test\" "
      "pfaptts name=tts rate=220 text=\"Hello <FAP 2 1 40 0 0 500 1> world. This talking head "
      "speaks over RTP, <FAP 48 20000 800 3> and its lips move with the sound.\" "
      "tts.audio ! queue ! audioconvert ! rtpL16pay name=audio_pay pt=96 "
      "! rtpbin.send_rtp_sink_0 "
      "rtpbin.send_rtp_src_0 ! udpsink name=audio_rtp host=127.0.0.1 async=false "
      "rtpbin.send_rtcp_src_0 ! udpsink name=audio_rtcp host=127.0.0.1 sync=false async=false "
      "udpsrc name=audio_rr address=127.0.0.1 port=0 ! rtpbin.recv_rtcp_sink_0 "
      "tts.pfap ! queue ! rtppfappay name=pfap_pay pt=97 ! rtpbin.send_rtp_sink_1 "
      "rtpbin.send_rtp_src_1 ! udpsink name=pfap_rtp host=127.0.0.1 async=false "
      "rtpbin.send_rtcp_src_1 ! udpsink name=pfap_rtcp host=127.0.0.1 sync=false async=false "
      "udpsrc name=pfap_rr address=127.0.0.1 port=0 ! rtpbin.recv_rtcp_sink_1");
  ASSERT_TRUE(sender.ok()) << sender.error();

  links.audio_depay = receiver.by_name("audio_depay");
  links.pfap_depay = receiver.by_name("pfap_depay");
  GstElement* receiver_rtpbin = receiver.by_name("rtpbin");
  g_signal_connect(receiver_rtpbin, "pad-added", G_CALLBACK(pfap::testing::on_rtpbin_pad), &links);
  g_signal_connect(receiver_rtpbin, "new-jitterbuffer",
                   G_CALLBACK(pfap::testing::on_new_jitterbuffer), &received);
  g_signal_connect(receiver.by_name("audio_sink"), "new-sample",
                   G_CALLBACK(pfap::testing::on_audio), &received);
  g_signal_connect(receiver.by_name("pfap_sink"), "new-sample",
                   G_CALLBACK(pfap::testing::on_phoneme), &received);
  for (const char* name : {"audio_pay", "pfap_pay"}) {
    GstPad* pad = gst_element_get_static_pad(sender.by_name(name), "sink");
    if (std::string_view(name) == "audio_pay") {
      gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, pfap::testing::record_sent_audio,
                        &sent_audio, nullptr);
    } else {
      gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, SentPhonemes::on_pfap, &sent, nullptr);
    }
    gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM, SentPhonemes::on_event, &sent,
                      nullptr);
    gst_object_unref(pad);
  }

  ASSERT_EQ(receiver.set_state(GST_STATE_READY), "");
  ASSERT_EQ(sender.set_state(GST_STATE_READY), "");
  for (const char* name : {"audio_rtp", "audio_rtcp", "pfap_rtp", "pfap_rtcp"}) {
    const guint port = pfap::testing::bound_port(receiver.by_name(name));
    ASSERT_NE(port, 0u) << name;
    g_object_set(sender.by_name(name), "port", port, nullptr);
  }
  for (const char* name : {"audio_rr", "pfap_rr"}) {
    const guint port = pfap::testing::bound_port(sender.by_name(name));
    ASSERT_NE(port, 0u) << name;
    g_object_set(receiver.by_name(name), "port", port, nullptr);
  }
  pfap::testing::fast_rtcp(sender.by_name("rtpbin"));
  pfap::testing::fast_rtcp(receiver_rtpbin);
  ASSERT_EQ(receiver.set_state(GST_STATE_PLAYING), "");
  ASSERT_EQ(sender.set_state(GST_STATE_PLAYING), "");

  // Until both payloaders have had EOS and everything sent has arrived (or a deadline).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  std::string failure;
  for (;;) {
    bool done = false;
    if (sent.eos == 2) {
      std::scoped_lock lock(sent.mutex, sent_audio.mutex, received.mutex);
      size_t samples = 0;
      for (const pfap::testing::Received::Audio& a : received.audio) samples += a.bytes.size();
      done = received.phonemes.size() >= sent.events.size() && samples >= sent_audio.bytes.size();
      if (!received.link_errors.empty()) failure = received.link_errors.front();
    }
    if (done || !failure.empty()) break;
    failure = sender.poll_error();
    if (failure.empty()) failure = receiver.poll_error();
    if (!failure.empty()) break;
    if (std::chrono::steady_clock::now() > deadline) {
      failure = "timed out: " + std::to_string(received.phonemes.size()) + " phonemes of " +
                std::to_string(sent.events.size()) + " received";
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  sender.set_state(GST_STATE_NULL);
  receiver.set_state(GST_STATE_NULL);
  ASSERT_EQ(failure, "");

  // Every phoneme arrives once, in order, with its fields and FAPs.
  ASSERT_GT(sent.events.size(), 30u);
  ASSERT_EQ(received.phonemes.size(), sent.events.size());
  std::vector<GstClockTime> sent_times;
  int faps = 0;
  for (size_t i = 0; i < sent.events.size(); ++i) {
    Event got = received.phonemes[i].event;
    Event want = sent.events[i];
    sent_times.push_back(want.pts);
    faps += static_cast<int>(want.faps.size());
    got.discont = want.discont = false;
    got.pts = want.pts;
    got.duration = want.duration = 0;  // the receiver's come from the whole ms
    EXPECT_EQ(got, want) << "phoneme " << i;
  }
  EXPECT_EQ(faps, 2);

  size_t unmatched = 0;
  const std::vector<pfap::testing::AudioOffset> audio =
      pfap::testing::audio_offsets(sent_audio, received, unmatched);
  // Buffers that start in silence cannot be found by their bytes.
  ASSERT_GT(audio.size(), received.audio.size() / 3)
      << unmatched << " of " << received.audio.size() << " received audio buffers not found";
  const pfap::testing::LipSync sync =
      pfap::testing::compare_offsets(audio, sent_times, received.phonemes, GST_MSECOND);
  SCOPED_TRACE("per phoneme (syncs < 2: before RTCP sync, not counted):\n" + sync.table);
  EXPECT_GE(sync.compared, 10) << "too few phonemes after RTCP sync";
  EXPECT_EQ(sync.out_of_tolerance, 0)
      << "worst |R_p - R_a| " << sync.worst / 1000 << " us over " << sync.compared << " phonemes";
  if (g_getenv("PFAP_TEST_VERBOSE") != nullptr) {
    std::cout << sync.table << "worst " << sync.worst << " ns over " << sync.compared << "\n";
  }
}

}  // namespace
