// SPDX-License-Identifier: LGPL-2.1-or-later
// pfapalign: recorded speech and its text in, the audio unchanged and its phonemes on `pfap`.
// GstHarness on sink/src, one on `pfap` and one on `text_sink` when the text comes as buffers.
// The "recordings" are espeak-ng's at another rate and pitch, whose phoneme times are known.
#include <gst/check/gstharness.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "documented_commands.h"
#include "markupbuffer.h"
#include "pipeline.h"
#include "speech_fixtures.h"
#include "recognizer.h"
#include "speech.h"
#include "temp_dir.h"
#include "white_noise.h"

namespace {

constexpr const char* kText = "Please call Stella and ask her to bring these things.";
// Another sentence of about the same length.
constexpr const char* kOtherText = "The birch canoe slid on the smooth planks, then sank.";

struct Event {
  GstClockTime pts;
  GstClockTime duration;
  pfap::MarkupEvent event;
};

struct Result {
  std::vector<int16_t> audio;
  std::vector<Event> events;
  std::vector<std::string> warnings;
  std::string alphabet;  // of `pfap`'s caps
};

std::string caps_at(unsigned rate, int channels = 1) {
  return "audio/x-raw, format=(string)S16LE, layout=(string)interleaved, channels=(int)" +
         std::to_string(channels) + ", rate=(int)" + std::to_string(rate);
}

pfap::tts::Speech say(const std::string& text, int rate = 140, int pitch = 30) {
  return pfap::align::testing::say(text, {"en", rate, pitch, 100});
}

// Runs pfapalign (espeak-ng voice `voice`, `recognizer` unless nullptr) over `samples` at
// `rate` with the `text` property (nullptr: none), or, when `texts` is not empty, with those
// (PTS, text) buffers on text_sink.
Result run(const std::vector<int16_t>& samples, unsigned rate, const char* text,
           const std::vector<std::pair<GstClockTime, std::string>>& texts = {},
           const char* voice = "en", bool live = false, const char* recognizer = nullptr) {
  GstHarness* h = gst_harness_new_with_padnames("pfapalign", "sink", "src");
  if (live || recognizer != nullptr) {  // read when the element goes to PAUSED
    gst_element_set_state(h->element, GST_STATE_READY);
    if (live) g_object_set(h->element, "live", TRUE, nullptr);
    if (recognizer != nullptr) {
      gst_util_set_object_arg(G_OBJECT(h->element), "recognizer", recognizer);
    }
    gst_element_set_state(h->element, GST_STATE_PLAYING);
  }
  GstHarness* pfap = gst_harness_new_with_element(h->element, nullptr, "pfap");
  GstHarness* t =
      texts.empty() ? nullptr : gst_harness_new_with_element(h->element, "text_sink", nullptr);
  GstBus* bus = gst_bus_new();
  gst_element_set_bus(h->element, bus);
  if (text != nullptr) g_object_set(h->element, "text", text, nullptr);
  g_object_set(h->element, "voice", voice, nullptr);
  gst_harness_set_src_caps_str(h, caps_at(rate).c_str());
  if (t != nullptr) {
    gst_harness_set_src_caps_str(t, "text/x-raw, format=(string)utf8");
    for (const auto& [pts, bytes] : texts) {
      GstBuffer* b = gst_buffer_new_memdup(bytes.data(), bytes.size());
      GST_BUFFER_PTS(b) = pts;
      EXPECT_EQ(gst_harness_push(t, b), GST_FLOW_OK);
    }
    gst_harness_push_event(t, gst_event_new_eos());
  }
  // In buffers of 100 ms, as a decoder gives them.
  const size_t chunk = rate / 10;
  for (size_t i = 0; i < samples.size(); i += chunk) {
    const size_t n = std::min(chunk, samples.size() - i);
    GstBuffer* b = gst_buffer_new_memdup(samples.data() + i, n * 2);
    GST_BUFFER_PTS(b) = gst_util_uint64_scale(i, GST_SECOND, rate);
    GST_BUFFER_DURATION(b) = gst_util_uint64_scale(n, GST_SECOND, rate);
    EXPECT_EQ(gst_harness_push(h, b), GST_FLOW_OK);
  }
  gst_harness_push_event(h, gst_event_new_eos());

  Result r;
  while (GstBuffer* b = gst_harness_try_pull(h)) {
    GstMapInfo map;
    gst_buffer_map(b, &map, GST_MAP_READ);
    const auto* s = reinterpret_cast<const int16_t*>(map.data);
    r.audio.insert(r.audio.end(), s, s + map.size / 2);
    gst_buffer_unmap(b, &map);
    gst_buffer_unref(b);
  }
  while (GstBuffer* b = gst_harness_try_pull(pfap)) {
    Event e{GST_BUFFER_PTS(b), GST_BUFFER_DURATION(b), {}};
    EXPECT_TRUE(pfap_buffer_read(b, e.event));
    r.events.push_back(e);
    gst_buffer_unref(b);
  }
  while (GstMessage* m = gst_bus_pop_filtered(bus, GST_MESSAGE_WARNING)) {
    GError* error = nullptr;
    gst_message_parse_warning(m, &error, nullptr);
    r.warnings.push_back(error->message);
    g_error_free(error);
    gst_message_unref(m);
  }
  GstPad* pfap_pad = gst_element_get_static_pad(h->element, "pfap");
  if (GstCaps* caps = gst_pad_get_current_caps(pfap_pad)) {
    const gchar* alphabet = gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet");
    r.alphabet = alphabet != nullptr ? alphabet : "";
    gst_caps_unref(caps);
  }
  gst_object_unref(pfap_pad);
  gst_bus_set_flushing(bus, TRUE);
  if (t != nullptr) gst_harness_teardown(t);
  gst_harness_teardown(pfap);
  gst_harness_teardown(h);
  gst_object_unref(bus);
  return r;
}

// The events tile [0, end): each starts where the one before ended.
void expect_tiles(const Result& r, GstClockTime end) {
  ASSERT_FALSE(r.events.empty());
  GstClockTime next = 0;
  for (const Event& e : r.events) {
    EXPECT_EQ(e.pts, next);
    next = e.pts + e.duration;
  }
  EXPECT_EQ(next, end);
}

bool has_warning(const Result& r, const std::string& part) {
  for (const std::string& w : r.warnings) {
    if (w.find(part) != std::string::npos) return true;
  }
  return false;
}

TEST(PfapAlign, PhonemesOnTheRecordingsTimelineAndTheAudioUnchanged) {
  const pfap::tts::Speech truth = say(kText);
  const Result r = run(truth.samples, truth.sample_rate, kText);
  EXPECT_EQ(r.audio, truth.samples);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  ASSERT_EQ(r.events.size(), truth.phonemes.size());
  expect_tiles(r, gst_util_uint64_scale(truth.samples.size(), GST_SECOND, truth.sample_rate));
  std::vector<double> errors;
  for (size_t k = 0; k < r.events.size(); ++k) {
    EXPECT_EQ(r.events[k].event.phoneme.symbol, truth.phonemes[k].event.phoneme.symbol);
    EXPECT_EQ(r.events[k].event.phoneme.word_begin, truth.phonemes[k].event.phoneme.word_begin);
    const double want = static_cast<double>(truth.phonemes[k].start) / truth.sample_rate;
    errors.push_back(std::abs(static_cast<double>(r.events[k].pts) / GST_SECOND - want));
  }
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.020);
  EXPECT_LT(errors[errors.size() * 9 / 10], 0.050);
}

TEST(PfapAlign, UtterancesOnTheTextPadStartAtTheirPts) {
  const pfap::tts::Speech a = say("Good morning.");
  const pfap::tts::Speech b = say("See you tomorrow.");
  std::vector<int16_t> audio = a.samples;
  audio.resize(audio.size() + a.sample_rate / 2, 0);  // half a second of silence
  const size_t b_start = audio.size();
  audio.insert(audio.end(), b.samples.begin(), b.samples.end());
  const GstClockTime b_time = gst_util_uint64_scale(b_start, GST_SECOND, a.sample_rate);
  const Result r =
      run(audio, a.sample_rate, nullptr, {{0, "Good morning."}, {b_time, "See you tomorrow."}});
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  expect_tiles(r, gst_util_uint64_scale(audio.size(), GST_SECOND, a.sample_rate));
  EXPECT_EQ(r.events.size(), a.phonemes.size() + b.phonemes.size());
  // The second utterance's first phoneme (a pause, then "S") starts at its PTS.
  const auto second = std::find_if(r.events.begin(), r.events.end(),
                                   [&](const Event& e) { return e.pts >= b_time; });
  ASSERT_NE(second, r.events.end());
  EXPECT_EQ(second->pts, b_time);
  EXPECT_TRUE(second->event.sentence_start);
}

TEST(PfapAlign, SilenceWarnsAndIsOnePause) {
  const std::vector<int16_t> silence(16000, 0);
  const Result r = run(silence, 16000, "<FAP 3 1 0 1>Hello.");
  EXPECT_TRUE(has_warning(r, "silent"));
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].event.phoneme.symbol, 0);
  EXPECT_EQ(r.events[0].event.faps.size(), 1u);  // the bookmark is not lost
  expect_tiles(r, GST_SECOND);
  EXPECT_EQ(r.audio, silence);
}

// A text much longer than the speech, noise, and (with the recognizer) another text of about
// the same length warn; the right text does not (docs/align.md, "Bad input").
TEST(PfapAlign, NoiseAndAnotherTextWarnOfAPoorMatch) {
  const pfap::tts::Speech s = say(kText);
  const Result right = run(s.samples, s.sample_rate, kText);
  EXPECT_FALSE(has_warning(right, "poorly"));
  const Result wrong =
      run(s.samples, s.sample_rate,
          "How much wood would a woodchuck chuck if a woodchuck could chuck wood? "
          "She sells sea shells by the sea shore. The quick brown fox jumps over the lazy "
          "dog. Peter Piper picked a peck of pickled peppers.");
  EXPECT_TRUE(has_warning(wrong, "poorly"));
  expect_tiles(wrong, gst_util_uint64_scale(s.samples.size(), GST_SECOND, s.sample_rate));
  const std::vector<int16_t> noise = pfap::testing::white_noise(s.samples.size());
  const Result noisy = run(noise, s.sample_rate, kText);
  expect_tiles(noisy, gst_util_uint64_scale(noise.size(), GST_SECOND, s.sample_rate));
  if (!pfap::align::recognition_available()) return;  // the cost alone: test_align.cc
  EXPECT_TRUE(has_warning(noisy, "poorly"));
  const Result other = run(s.samples, s.sample_rate, kOtherText);
  EXPECT_TRUE(has_warning(other, "poorly"));
}

TEST(PfapAlign, EmptyTextWarnsAndIsOnePause) {
  const pfap::tts::Speech s = say(kText);
  const GstClockTime end = gst_util_uint64_scale(s.samples.size(), GST_SECOND, s.sample_rate);
  const Result empty = run(s.samples, s.sample_rate, "");
  EXPECT_TRUE(has_warning(empty, "nothing to speak"));
  ASSERT_EQ(empty.events.size(), 1u);
  expect_tiles(empty, end);
}

// Without a text (no property, text_sink not linked) the phonemes are recognized from the
// audio, where the build has the recognizer; else the audio is one pause, with a warning.
TEST(PfapAlign, WithoutTextPhonemesAreRecognizedOrOnePause) {
  const pfap::tts::Speech s = say(kText);
  const GstClockTime end = gst_util_uint64_scale(s.samples.size(), GST_SECOND, s.sample_rate);
  const Result none = run(s.samples, s.sample_rate, nullptr);
  expect_tiles(none, end);
  EXPECT_EQ(none.audio, s.samples);
  if (!pfap::align::recognition_available()) {
    EXPECT_TRUE(has_warning(none, "cannot recognize phonemes"));
    ASSERT_EQ(none.events.size(), 1u);
    return;
  }
  EXPECT_TRUE(none.warnings.empty());
  size_t phonemes = 0;
  for (const Event& e : none.events) phonemes += e.event.phoneme.symbol != 0 ? 1 : 0;
  EXPECT_GT(phonemes, 20u);  // espeak-ng says 41
  EXPECT_TRUE(none.events.front().event.sentence_start);
  EXPECT_TRUE(none.events.back().event.phoneme.end_of_text);
}

// Bad input without a text: silence, noise and a rate the model does not take each warn, the
// audio passes unchanged and the phonemes are one pause over it.
TEST(PfapAlign, WithoutTextBadInputWarnsAndIsOnePause) {
  if (!pfap::align::recognition_available()) GTEST_SKIP() << "no recognizer in this build";
  const std::vector<int16_t> silence(16000, 0);
  const std::vector<int16_t> noise = pfap::testing::white_noise(16000);
  const std::vector<std::tuple<std::vector<int16_t>, unsigned, const char*>> cases{
      {silence, 16000, "silent"},
      {noise, 16000, "no speech was recognized"},
      {noise, 8000, "8000 Hz cannot be aligned"},
  };
  for (const auto& [audio, rate, warning] : cases) {
    const Result r = run(audio, rate, nullptr);
    EXPECT_TRUE(has_warning(r, warning)) << warning;
    EXPECT_EQ(r.audio, audio);
    ASSERT_EQ(r.events.size(), 1u) << warning;
    EXPECT_EQ(r.events[0].event.phoneme.symbol, 0);
    expect_tiles(r, gst_util_uint64_scale(audio.size(), GST_SECOND, rate));
  }
}

// The same live: silence and a bad rate warn when the audio ends, the audio passes unchanged
// and its phonemes are pauses, given out in pieces as it came. Loud noise is heard as an HH
// live (docs/align.md, "Live without the text"): the audio passes, its phonemes tile it.
TEST(PfapAlign, WithoutTextLiveBadInputWarnsAndIsPauses) {
  if (!pfap::align::recognition_available()) GTEST_SKIP() << "no recognizer in this build";
  const std::vector<int16_t> silence(32000, 0);
  const std::vector<int16_t> noise = pfap::testing::white_noise(32000);
  const std::vector<std::tuple<std::vector<int16_t>, unsigned, const char*>> cases{
      {silence, 16000, "silent"},
      {noise, 8000, "8000 Hz cannot be aligned"},
  };
  const Result heard = run(noise, 16000, nullptr, {}, "en", true);
  EXPECT_EQ(heard.audio, noise);
  expect_tiles(heard, gst_util_uint64_scale(noise.size(), GST_SECOND, 16000));
  for (const auto& [audio, rate, warning] : cases) {
    const Result r = run(audio, rate, nullptr, {}, "en", true);
    EXPECT_TRUE(has_warning(r, warning)) << warning;
    EXPECT_EQ(r.audio, audio);
    EXPECT_GT(r.events.size(), 1u) << warning << ": in pieces";
    for (const Event& e : r.events) EXPECT_EQ(e.event.phoneme.symbol, 0) << warning;
    expect_tiles(r, gst_util_uint64_scale(audio.size(), GST_SECOND, rate));
  }
}

TEST(PfapAlign, UnsupportedRateWarnsAndPassesTheAudio) {
  const std::vector<int16_t> audio(8000, 100);
  const Result r = run(audio, 8000, kText);
  EXPECT_TRUE(has_warning(r, "8000 Hz cannot be aligned"));
  EXPECT_EQ(r.audio, audio);
  ASSERT_EQ(r.events.size(), 1u);
  expect_tiles(r, GST_SECOND);
}

TEST(PfapAlign, PhonemesOutsideTheAlphabetWarnOncePerMnemonic) {
  // German through voice "de": "ich" has a phoneme x-pfap-arpabet lacks (espeak-ng's "C").
  const pfap::tts::Speech s = say(kText);
  const Result r = run(s.samples, s.sample_rate, "Ich spreche, ich lache.", {}, "de");
  size_t outside = 0;
  for (const std::string& w : r.warnings) {
    if (w.find("is not in x-pfap-arpabet") != std::string::npos) ++outside;
  }
  EXPECT_GT(outside, 0u);
  const std::set<std::string> distinct(r.warnings.begin(), r.warnings.end());
  EXPECT_EQ(distinct.size(), r.warnings.size());  // once per mnemonic
  expect_tiles(r, gst_util_uint64_scale(s.samples.size(), GST_SECOND, s.sample_rate));
}

TEST(PfapAlign, StereoIsRefusedAtNegotiation) {
  GstHarness* h = gst_harness_new_with_padnames("pfapalign", "sink", "src");
  gst_harness_set_src_caps_str(h, caps_at(16000, 2).c_str());
  EXPECT_EQ(gst_harness_push(h, gst_buffer_new_allocate(nullptr, 400, nullptr)),
            GST_FLOW_NOT_NEGOTIATED);
  gst_harness_teardown(h);
}

// Issue 27: a rate above 48 kHz is refused, not kept whole with a warning that it cannot be
// aligned; audioresample before it then picks 48 kHz.
TEST(PfapAlign, RateAbove48kHzIsRefusedAtNegotiation) {
  GstHarness* h = gst_harness_new_with_padnames("pfapalign", "sink", "src");
  gst_harness_set_src_caps_str(h, caps_at(96000).c_str());
  EXPECT_EQ(gst_harness_push(h, gst_buffer_new_allocate(nullptr, 400, nullptr)),
            GST_FLOW_NOT_NEGOTIATED);
  gst_harness_teardown(h);
  pfap::testing::Pipeline p(
      "audiotestsrc num-buffers=5 ! audio/x-raw,rate=96000 ! audioresample ! pfapalign "
      "text=Hello. name=a a.src ! queue ! audio/x-raw,rate=48000 ! fakesink a.pfap ! queue ! "
      "fakesink");
  ASSERT_TRUE(p.ok()) << p.error();
  ASSERT_EQ(p.set_state(GST_STATE_PLAYING), "");
  EXPECT_EQ(p.wait_eos(std::chrono::seconds(30)), "");
}

// Issue 27: a text far longer than its audio (20 kB for 1.5 s) warns and is one pause,
// unspoken, where it took seconds and hundreds of MB and gave thousands of phonemes.
TEST(PfapAlign, TextFarLongerThanTheAudioWarnsAndIsOnePause) {
  const pfap::tts::Speech s = say(kText);
  std::string text;
  while (text.size() < 20000) text += std::string(kText) + " ";
  const Result r = run(s.samples, s.sample_rate, text.c_str());
  EXPECT_TRUE(has_warning(r, "far longer than the audio"));
  ASSERT_EQ(r.events.size(), 1u);
  expect_tiles(r, gst_util_uint64_scale(s.samples.size(), GST_SECOND, s.sample_rate));
  EXPECT_EQ(r.audio, s.samples);
}

// Issue 31: 2 s of silence before a sentence is a pause, offline and live, and the first sound
// starts within 50 ms of the speaker's (espeak-ng starts this text with no pause of its own).
TEST(PfapAlign, LeadingSilenceIsAPauseOfflineAndLive) {
  constexpr const char* kVowelFirst = "Always remember the open ocean.";
  const pfap::tts::Speech s = say(kVowelFirst);
  ASSERT_NE(s.phonemes[0].event.phoneme.symbol, 0);
  std::vector<int16_t> audio(2 * s.sample_rate, 0);
  audio.insert(audio.end(), s.samples.begin(), s.samples.end());
  for (const bool live : {false, true}) {
    SCOPED_TRACE(live ? "live" : "offline");
    const Result r = run(audio, s.sample_rate, kVowelFirst, {}, "en", live);
    ASSERT_GE(r.events.size(), 2u);
    EXPECT_EQ(r.events[0].event.phoneme.symbol, 0);
    size_t first = 0;  // the first sound (live, the pause comes in pieces)
    while (first < r.events.size() && r.events[first].event.phoneme.symbol == 0) ++first;
    ASSERT_LT(first, r.events.size());
    const double error_ms =
        std::abs(static_cast<double>(r.events[first].pts) - 2.0 * GST_SECOND) / GST_MSECOND;
    std::printf("%s, lead-in 2 s: first sound %.1f ms off\n", live ? "live" : "offline", error_ms);
    EXPECT_LT(error_ms, 50);
    expect_tiles(r, gst_util_uint64_scale(audio.size(), GST_SECOND, s.sample_rate));
  }
}

TEST(PfapAlign, WaitForTheTextsEosEndsWithTheStream) {
  // text_sink linked, its EOS never comes: the audio's EOS waits for it, and stopping the
  // element ends the wait instead of hanging.
  GstHarness* h = gst_harness_new_with_padnames("pfapalign", "sink", "src");
  GstHarness* t = gst_harness_new_with_element(h->element, "text_sink", nullptr);
  gst_harness_set_src_caps_str(h, caps_at(16000).c_str());
  gst_harness_set_src_caps_str(t, "text/x-raw, format=(string)utf8");
  const std::vector<int16_t> audio(1600, 1000);
  ASSERT_EQ(gst_harness_push(h, gst_buffer_new_memdup(audio.data(), audio.size() * 2)),
            GST_FLOW_OK);
  std::atomic<bool> returned = false;
  std::thread eos([&] {
    gst_harness_push_event(h, gst_event_new_eos());
    returned = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_FALSE(returned);
  gst_element_set_state(h->element, GST_STATE_READY);
  eos.join();
  EXPECT_TRUE(returned);
  gst_harness_teardown(t);
  gst_harness_teardown(h);
}

// recognizer=visemes without a text: the detector's phonemes of the whole audio at its end,
// in its alphabet; with a text, the text is aligned as without the property.
TEST(PfapAlign, VisemesWithoutTextAndTheTextWhenThereIsOne) {
  const pfap::tts::Speech truth = say(kText);
  const GstClockTime end =
      gst_util_uint64_scale(truth.samples.size(), GST_SECOND, truth.sample_rate);
  const Result visemes = run(truth.samples, truth.sample_rate, nullptr, {}, "en", false, "visemes");
  EXPECT_EQ(visemes.alphabet, "x-pfap-oculus-viseme");
  EXPECT_EQ(visemes.audio, truth.samples);
  EXPECT_TRUE(visemes.warnings.empty()) << visemes.warnings.front();
  expect_tiles(visemes, end);
  std::set<int> seen;
  for (const Event& e : visemes.events) {
    EXPECT_LT(e.event.phoneme.symbol, 15);
    seen.insert(e.event.phoneme.symbol);
  }
  EXPECT_GT(seen.size(), 5u) << "speech is heard as several visemes";
  // Smoothed runs, about ten a second, not a phoneme every frame.
  EXPECT_LT(visemes.events.size(), truth.samples.size() * 20 / truth.sample_rate);

  const Result text = run(truth.samples, truth.sample_rate, kText, {}, "en", false, "visemes");
  EXPECT_EQ(text.alphabet, "x-pfap-arpabet");
  ASSERT_EQ(text.events.size(), truth.phonemes.size());
  for (size_t k = 0; k < text.events.size(); ++k) {
    EXPECT_EQ(text.events[k].event.phoneme.symbol, truth.phonemes[k].event.phoneme.symbol);
  }
}

// Below the detector's 8 kHz: a warning, and the audio is pauses.
TEST(PfapAlign, VisemesAtARateTheDetectorCannotTakeWarnAndArePauses) {
  const std::vector<int16_t> audio(6000, 1000);  // 1 s at 6 kHz
  const Result r = run(audio, 6000, nullptr, {}, "en", false, "visemes");
  EXPECT_TRUE(has_warning(r, "viseme detector cannot take it")) << r.warnings.size();
  expect_tiles(r, GST_SECOND);
  for (const Event& e : r.events) EXPECT_EQ(e.event.phoneme.symbol, 0);
}

// A push of phonemes at the audio's EOS that fails (here `pfap`'s peer refuses them) is posted
// as an error, offline and live: the event function cannot return it, and it was lost.
TEST(PfapAlign, AFailedPushAtTheEndIsPostedAsAnError) {
  const pfap::tts::Speech truth = say(kText);
  for (const bool live : {false, true}) {
    SCOPED_TRACE(live ? "live" : "offline");
    GstHarness* h = gst_harness_new_with_padnames("pfapalign", "sink", "src");
    if (live) {  // read when the element goes to PAUSED
      gst_element_set_state(h->element, GST_STATE_READY);
      g_object_set(h->element, "live", TRUE, nullptr);
      gst_element_set_state(h->element, GST_STATE_PLAYING);
    }
    GstPad* refusing = gst_pad_new("refusing", GST_PAD_SINK);
    gst_pad_set_chain_function(refusing, [](GstPad*, GstObject*, GstBuffer* b) {
      gst_buffer_unref(b);
      return GST_FLOW_NOT_NEGOTIATED;
    });
    gst_pad_set_event_function(refusing, [](GstPad*, GstObject*, GstEvent* e) -> gboolean {
      gst_event_unref(e);
      return TRUE;
    });
    gst_pad_set_active(refusing, TRUE);
    GstPad* pfap = gst_element_get_static_pad(h->element, "pfap");
    ASSERT_EQ(gst_pad_link(pfap, refusing), GST_PAD_LINK_OK);
    GstBus* bus = gst_bus_new();
    gst_element_set_bus(h->element, bus);
    g_object_set(h->element, "text", kText, nullptr);
    gst_harness_set_src_caps_str(h, caps_at(truth.sample_rate).c_str());
    // Live, 100 ms: the phonemes settle later than this, all of them at the EOS.
    const size_t n = live ? truth.sample_rate / 10 : truth.samples.size();
    EXPECT_EQ(gst_harness_push(h, gst_buffer_new_memdup(truth.samples.data(), n * 2)), GST_FLOW_OK);
    gst_harness_push_event(h, gst_event_new_eos());
    GstMessage* m = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
    ASSERT_NE(m, nullptr);
    GError* error = nullptr;
    gchar* debug = nullptr;
    gst_message_parse_error(m, &error, &debug);
    EXPECT_TRUE(g_error_matches(error, GST_STREAM_ERROR, GST_STREAM_ERROR_FAILED));
    EXPECT_NE(std::string(debug).find("not-negotiated"), std::string::npos) << debug;
    g_error_free(error);
    g_free(debug);
    gst_message_unref(m);
    gst_bus_set_flushing(bus, TRUE);
    gst_harness_teardown(h);
    gst_pad_set_active(refusing, FALSE);
    gst_object_unref(refusing);
    gst_object_unref(pfap);
    gst_object_unref(bus);
  }
}

// The launch lines of docs/elements.md's pfapalign section, each run on a WAV pfaptts makes;
// the live one (live=true, RTP in and out) is run by test_pfapalign_live.
std::vector<std::string> documented_commands() {
  std::vector<std::string> out;
  for (std::string& d : pfap::testing::launch_descriptions(
           pfap::testing::doc_section("docs/elements.md", "## pfapalign"))) {
    if (d.find(" live=true ") == std::string::npos) out.push_back(std::move(d));
  }
  return out;
}

// `description` run to its end with its files in `dir`: "" or what went wrong.
std::string run_line(std::string description, const pfap::testing::TempDir& dir) {
  for (const char* f : {"speech.wav", "speech.txt", "speech.pfap", "face.webm"}) {
    pfap::testing::replace_all(description, std::string("location=") + f,
                               "location=" + dir.file(f));
  }
  pfap::testing::Pipeline p(description);
  if (!p.ok()) return p.error();
  std::string e = p.set_state(GST_STATE_PLAYING);
  if (e.empty()) e = p.wait_eos(std::chrono::seconds(60));
  return e;
}

size_t file_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  return in ? static_cast<size_t>(in.tellg()) : 0;
}

TEST(PfapAlignDocumented, EveryCommandRuns) {
  const std::vector<std::string> commands = documented_commands();
  ASSERT_EQ(commands.size(), 5u);
  const pfap::testing::TempDir dir;
  const std::string text =
      "Please call Stella. Ask her to bring these things with her from the store.";
  {
    // The "recording": pfaptts at another rate and pitch than pfapalign's voice.
    pfap::testing::Pipeline make("pfaptts rate=140 pitch=30 text=\"" + text +
                                 "\" name=t t.audio ! queue ! wavenc ! filesink location=" +
                                 dir.file("speech.wav") + " t.pfap ! queue ! fakesink");
    ASSERT_TRUE(make.ok()) << make.error();
    ASSERT_EQ(make.set_state(GST_STATE_PLAYING), "");
    ASSERT_EQ(make.wait_eos(std::chrono::seconds(30)), "");
    std::ofstream(dir.file("speech.txt")) << text;
  }
  auto read = [&](const char* name) {
    std::ifstream in(dir.file(name));
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  ASSERT_EQ(run_line(commands[0], dir), "") << commands[0];
  const std::string from_property = read("speech.pfap");
  EXPECT_GT(std::count(from_property.begin(), from_property.end(), '\n'), 40);
  ASSERT_EQ(run_line(commands[1], dir), "") << commands[1];
  // The text from a file: the same phonemes (espeak-ng's synthesis differs by a few samples
  // from one call to the next, and the times by a few ms).
  auto symbols = [](const std::string& pfap_text) {
    std::vector<std::string> out;
    std::istringstream lines(pfap_text);
    for (std::string start, symbol, rest; lines >> start >> symbol && std::getline(lines, rest);) {
      out.push_back(symbol);
    }
    return out;
  };
  EXPECT_EQ(symbols(read("speech.pfap")), symbols(from_property));
  ASSERT_EQ(run_line(commands[2], dir), "") << commands[2];
  EXPECT_GT(file_size(dir.file("face.webm")), 20000u);
  ASSERT_EQ(run_line(commands[3], dir), "") << commands[3];
  const std::string without_text = read("speech.pfap");
  // Recognized phonemes, or one pause where the build cannot recognize.
  EXPECT_GT(std::count(without_text.begin(), without_text.end(), '\n'),
            pfap::align::recognition_available() ? 30 : 0);
  ASSERT_EQ(run_line(commands[4], dir), "") << commands[4];
  // The viseme detector's, in every build: runs of its 15 visemes.
  const std::vector<std::string> visemes = symbols(read("speech.pfap"));
  EXPECT_GT(visemes.size(), 20u);
  EXPECT_TRUE(std::all_of(visemes.begin(), visemes.end(),
                          [](const std::string& v) { return std::stoi(v) < 15; }));
}

}  // namespace
