// SPDX-License-Identifier: LGPL-2.1-or-later
// The example pipelines stay on one line, to be copied.
// clang-format off
/**
 * SECTION:element-pfapalign
 * @title: pfapalign
 * @see_also: pfaptts, pfapface, pfaptextenc, rtppfappay
 *
 * PFAP from speech that was not synthesized here: a recording and its text in, the audio out
 * unchanged on `src` and its phonemes on `pfap` (application/x-pfap,
 * `alphabet=x-pfap-arpabet`), on the audio's timeline. The text is spoken by espeak-ng
 * (#GstPfapAlign:voice, the recording's language), both are turned into MFCC frames and
 * matched by dynamic time warping, and each phoneme boundary of the synthetic speech is moved
 * to the time of the recording it matches; word starts, stress and `<FAP ...>` bookmarks are
 * those pfaptts gives, f0 is measured on the recording (docs/align.md).
 *
 * Audio: S16LE mono. The alignment takes 16000 to 48000 Hz; below 16000 Hz (put
 * `audioresample` before) the audio still passes and each utterance is one pause, with a
 * warning. Rates above 48000 Hz, other formats and channel counts are refused at negotiation:
 * put `audioresample` and `audioconvert` before.
 *
 * Text: #GstPfapAlign:text, the whole stream's, when `text_sink` is not linked; else
 * `text_sink` (text/x-raw or text/plain), one utterance per buffer, which lasts from its PTS
 * (running time) to the next utterance's or the end. A text buffer without a PTS continues
 * the one before (so a file read in blocks is one utterance); the first starts at the audio's
 * start. Audio before the first utterance is a pause.
 *
 * Without a text (no #GstPfapAlign:text, `text_sink` not linked or given nothing), the
 * phonemes are recognized from the audio alone: pocketsphinx's all-phone search with its US
 * English model, whose visemes are right on most 10 ms frames (docs/align.md). Built only with
 * pocketsphinx (meson feature `recognition`); without it, a warning and one pause. With
 * #GstPfapAlign:recognizer `visemes`, the frame-level viseme detector hears them instead, as
 * `alphabet=x-pfap-oculus-viseme`: less accurate on human speech, and live within 95 ms
 * instead of 700 (docs/align.md, "The viseme detector in pfapalign").
 *
 * The phonemes come when the audio ends (EOS, a new segment or sample rate), after the text
 * pad's EOS; with #GstPfapAlign:live, for live sources, as the audio comes, each within the
 * latency the element declares (docs/align.md, "Live"), with a text or without. Silence,
 * noise, a text that does not match, an empty text or none, bad bookmarks and unsupported
 * rates each give a warning (rate-limited), and the stream goes on: an utterance
 * that cannot be aligned is one pause carrying its bookmarks.
 *
 * ## Example pipelines
 * |[
 * gst-launch-1.0 filesrc location=speech.wav ! wavparse ! audioconvert ! audioresample ! pfapalign text="Hello world." name=a a.src ! fakesink a.pfap ! pfaptextenc ! filesink location=speech.pfap
 * ]| A WAV and its text to a .pfap file.
 * |[
 * gst-launch-1.0 filesrc location=speech.wav ! wavparse ! audioconvert ! audioresample ! audio/x-raw,rate=16000 ! pfapalign name=a a.src ! queue ! fakesink a.pfap ! queue ! pfaptextenc ! filesink location=speech.pfap
 * ]| A WAV without its text: the phonemes recognized.
 * |[
 * gst-launch-1.0 udpsrc address=127.0.0.1 port=5004 caps="application/x-rtp,media=audio,clock-rate=16000,encoding-name=L16,channels=1,payload=96" ! rtpjitterbuffer latency=20 ! rtpL16depay ! audioconvert ! audio/x-raw,format=S16LE ! pfapalign live=true recognizer=visemes name=a a.src ! queue ! autoaudiosink a.pfap ! queue ! pfapface ! videoconvert ! autovideosink
 * ]| Live RTP audio without a text: a face that moves with it, within 95 ms.
 * |[
 * gst-launch-1.0 rtpbin name=r udpsrc address=127.0.0.1 port=5004 caps="application/x-rtp,media=audio,clock-rate=16000,encoding-name=L16,channels=1,payload=96" ! rtpjitterbuffer latency=50 ! rtpL16depay ! audioconvert ! audio/x-raw,format=S16LE ! pfapalign live=true text="Hello world." name=a a.src ! queue ! audioconvert ! rtpL16pay pt=96 ! r.send_rtp_sink_0 r.send_rtp_src_0 ! udpsink host=127.0.0.1 port=5000 r.send_rtcp_src_0 ! udpsink host=127.0.0.1 port=5001 sync=false async=false a.pfap ! queue ! rtppfappay pt=97 ! r.send_rtp_sink_1 r.send_rtp_src_1 ! udpsink host=127.0.0.1 port=5002 r.send_rtcp_src_1 ! udpsink host=127.0.0.1 port=5003 sync=false async=false
 * ]| Live RTP audio in; the audio and its phonemes out as two RTP sessions, in sync by RTCP.
 */
// clang-format on
#include "gstpfapalign.h"

#include <gst/base/gstflowcombiner.h>

#include <algorithm>
#include <array>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "aligner.h"
#include "inexact.h"
#include "live.h"
#include "markupbuffer.h"
#include "pfap/markup.h"
#include "ratelimit.h"
#include "recognizer.h"
#include "sample_times.h"
#include "sparse.h"
#include "utterances.h"

GST_DEBUG_CATEGORY_STATIC(pfapalign_debug);
#define GST_CAT_DEFAULT pfapalign_debug

namespace {

constexpr const char* kDefaultVoice = "en";

enum {
  PROP_0,
  PROP_TEXT,
  PROP_VOICE,
  PROP_LIVE,
  PROP_RECOGNIZER,
};

// The audio streaming thread's, but for `texts` and `text_segment`.
struct Stream {
  unsigned rate = 0;
  GstSegment segment;                        // the audio's, also sent on `pfap`
  GstClockTime first = GST_CLOCK_TIME_NONE;  // segment position of the first sample kept
  pfap::align::KeptAudio kept;               // offline
  bool pfap_discont = true;
  std::array<guint64, 6> problems{};  // per pfap::align::Problem, for pfap_warn_at
  guint64 bad_bookmarks = 0;
  std::set<std::string> warned_phonemes;          // inexact mnemonics already warned about
  std::array<guint64, 4> recognition_problems{};  // per pfap::align::RecognitionProblem

  // Live: upstream is live, and the phonemes go out as the audio comes (live_* below).
  bool live = false;
  // Without a text: the property's, until the stream starts; then kVisemes only where the
  // stream has no text (its alphabet is then the detector's).
  pfap::align::Recognizer recognizer = pfap::align::Recognizer::kPhonemes;
  pfap::align::LiveUtterances utterances;  // sample counts from `first`

  pfap::align::TextQueue texts;  // shared with the text pad's thread
  GstSegment text_segment;       // the text pad's thread's
};

}  // namespace

struct _GstPfapAlign {
  GstElement parent;
  GstPad* sinkpad;
  GstPad* textpad;
  GstPad* srcpad;
  GstPad* pfappad;
  GstFlowCombiner* flow_combiner;

  // Properties, under the object lock.
  gchar* text;
  gchar* voice;
  gboolean live;
  pfap::align::Recognizer recognizer;

  Stream* stream;
};

// Above 48 kHz (pfap::align::kMaxRate) refused: the element would keep audio it cannot align.
#define AUDIO_CAPS                                                                          \
  "audio/x-raw, format = (string) S16LE, layout = (string) interleaved, rate = (int) [ 1, " \
  "48000 ], channels = (int) 1"
static_assert(pfap::align::kMaxRate == 48000);

static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(AUDIO_CAPS));

static GstStaticPadTemplate text_template =
    GST_STATIC_PAD_TEMPLATE("text_sink", GST_PAD_SINK, GST_PAD_ALWAYS,
                            GST_STATIC_CAPS("text/x-raw, format = (string) utf8; text/plain"));

static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(AUDIO_CAPS));

static GstStaticPadTemplate pfap_template = GST_STATIC_PAD_TEMPLATE(
    "pfap", GST_PAD_SRC, GST_PAD_ALWAYS,
    GST_STATIC_CAPS(PFAP_MARKUP_CAPS ", alphabet = (string) { x-pfap-arpabet, "
                                     "x-pfap-oculus-viseme }"));
static_assert(pfap::kArpabetAlphabet == "x-pfap-arpabet");
static_assert(pfap::kOculusVisemeAlphabet == "x-pfap-oculus-viseme");

#define GST_TYPE_PFAP_ALIGN_RECOGNIZER (gst_pfap_align_recognizer_get_type())
static GType gst_pfap_align_recognizer_get_type() {
  static GType type = 0;
  static const GEnumValue values[] = {
      {static_cast<gint>(pfap::align::Recognizer::kPhonemes),
       "pocketsphinx's phonemes, x-pfap-arpabet: the accurate choice", "phonemes"},
      {static_cast<gint>(pfap::align::Recognizer::kVisemes),
       "the frame-level viseme detector's visemes, x-pfap-oculus-viseme: within 100 ms", "visemes"},
      {0, nullptr, nullptr},
  };
  if (g_once_init_enter(&type)) {
    g_once_init_leave(&type, g_enum_register_static("GstPfapAlignRecognizer", values));
  }
  return type;
}

G_DEFINE_TYPE(GstPfapAlign, gst_pfap_align, GST_TYPE_ELEMENT)
GST_ELEMENT_REGISTER_DEFINE(pfapalign, "pfapalign", GST_RANK_NONE, GST_TYPE_PFAP_ALIGN)

// Runs `work`, which calls align/: what it allocates grows with its input, and under a memory
// limit std::bad_alloc must not go into GStreamer. An error is posted instead.
template <typename Work>
static GstFlowReturn guarded(GstPfapAlign* self, Work&& work) {
  try {
    return work();
  } catch (const std::exception& e) {
    GST_ELEMENT_ERROR(self, RESOURCE, FAILED, ("Cannot align the audio: %s", e.what()), (nullptr));
    return GST_FLOW_ERROR;
  }
}

// The audio kept and the texts dropped: at a new stream or a flush.
static void reset(GstPfapAlign* self) {
  Stream& s = *self->stream;
  s.first = GST_CLOCK_TIME_NONE;
  s.kept.reset();
  s.pfap_discont = true;
  s.utterances.reset();
  gst_segment_init(&s.segment, GST_FORMAT_TIME);
  s.texts.reset();
  gst_flow_combiner_reset(self->flow_combiner);
}

// `cost` and `heard` as pfap::align::Alignment's relative_cost and heard_agreement.
static void warn_problem(GstPfapAlign* self, pfap::align::Problem problem, GstClockTime at,
                         double cost, double heard) {
  Stream& s = *self->stream;
  if (problem == pfap::align::Problem::kNone) return;
  if (!pfap_warn_at(++s.problems[static_cast<size_t>(problem)])) return;
  GST_ELEMENT_WARNING(
      self, STREAM, DECODE,
      ("Utterance at %" GST_TIME_FORMAT ": %s", GST_TIME_ARGS(at),
       pfap::align::problem_text(problem)),
      ("relative warp cost %.2f (poor from %.2f), visemes heard on %.0f %% of "
       "frames (poor below %.0f %%; -1: not measured); %" G_GUINT64_FORMAT " so far",
       cost, pfap::align::kPoorMatchCost, heard * 100, pfap::align::kPoorHeardAgreement * 100,
       s.problems[static_cast<size_t>(problem)]));
}

// Pushes `phonemes`, whose starts count from sample `from` of the audio kept, on `pfap`.
static GstFlowReturn push_phonemes(GstPfapAlign* self,
                                   const std::vector<pfap::tts::SpokenPhoneme>& phonemes,
                                   size_t from) {
  Stream& s = *self->stream;
  GstFlowReturn ret = GST_FLOW_OK;
  for (const pfap::tts::SpokenPhoneme& p : phonemes) {
    if (ret != GST_FLOW_OK) break;
    GstBuffer* buffer = pfap_buffer_new(p.event);
    if (buffer == nullptr) {
      // align() and recognize() keep every value in range: a bug.
      GST_ELEMENT_ERROR(self, STREAM, FAILED, (nullptr), ("a phoneme x-pfap cannot hold"));
      return GST_FLOW_ERROR;
    }
    const pfap::align::PhonemeTime time = pfap::align::phoneme_time(p, from, s.first, s.rate);
    GST_BUFFER_PTS(buffer) = time.pts;
    GST_BUFFER_DURATION(buffer) = time.duration;
    if (s.pfap_discont) GST_BUFFER_FLAG_SET(buffer, GST_BUFFER_FLAG_DISCONT);
    s.pfap_discont = false;
    ret = gst_flow_combiner_update_pad_flow(self->flow_combiner, self->pfappad,
                                            gst_pad_push(self->pfappad, buffer));
  }
  return ret;
}

// Without a text, where the build has no recognizer: a warning (the audio is one pause).
static void warn_cannot_recognize(GstPfapAlign* self) {
  GST_ELEMENT_WARNING(self, STREAM, DECODE,
                      ("No text for the audio, and this build cannot recognize phonemes "
                       "without it: the audio is one pause"),
                      ("set the text property or link text_sink; the text-free mode needs "
                       "pocketsphinx (meson feature `recognition`)"));
}

// What was wrong with the recognition of the audio from `at`, if anything (rate-limited).
static void warn_recognition_problem(GstPfapAlign* self, pfap::align::RecognitionProblem problem,
                                     GstClockTime at) {
  Stream& s = *self->stream;
  if (problem == pfap::align::RecognitionProblem::kNone) return;
  const auto k = static_cast<size_t>(problem);
  if (!pfap_warn_at(++s.recognition_problems[k])) return;
  GST_ELEMENT_WARNING(self, STREAM, DECODE,
                      ("Audio at %" GST_TIME_FORMAT " without text: %s", GST_TIME_ARGS(at),
                       pfap::align::problem_text(problem)),
                      ("%" G_GUINT64_FORMAT " so far", s.recognition_problems[k]));
}

// Without a text: the phonemes of all the audio kept, heard by `source` (recognized or the
// detector's visemes), or one pause with a warning where the build cannot recognize.
static GstFlowReturn hear_kept(GstPfapAlign* self, pfap::align::PhonemeSource source) {
  Stream& s = *self->stream;
  GST_INFO_OBJECT(self, "no text: hearing %zu samples", s.kept.samples().size());
  pfap::align::Heard heard;
  std::string error;
  if (!pfap::align::hear(s.kept.samples(), s.rate, source, heard, error)) {
    GST_ELEMENT_ERROR(self, LIBRARY, INIT, ("%s", error.c_str()), (nullptr));  // no model
    return GST_FLOW_ERROR;
  }
  if (heard.cannot_recognize) warn_cannot_recognize(self);
  warn_recognition_problem(self, heard.problem, s.first);
  return push_phonemes(self, heard.phonemes, 0);
}

// The utterance of the text `bytes` starting at `at`, bad UTF-8 and bookmarks warned about.
static pfap::tts::Utterance parse_text(GstPfapAlign* self, const std::string& bytes,
                                       GstClockTime at) {
  Stream& s = *self->stream;
  std::string text = bytes;
  if (!g_utf8_validate(text.data(), static_cast<gssize>(text.size()), nullptr)) {
    GST_ELEMENT_WARNING(
        self, STREAM, DECODE,
        ("The text of the utterance at %" GST_TIME_FORMAT " is not UTF-8", GST_TIME_ARGS(at)),
        ("aligned as an empty text"));
    text.clear();
  }
  std::vector<pfap::tts::BadBookmark> bad;
  const pfap::tts::Utterance utterance = pfap::tts::parse_utterance(text, bad);
  for (const pfap::tts::BadBookmark& b : bad) {
    if (!pfap_warn_at(++s.bad_bookmarks)) continue;
    GST_ELEMENT_WARNING(
        self, STREAM, FORMAT,
        ("Left out a bad bookmark at character %zu of the utterance at %" GST_TIME_FORMAT ": %s",
         b.character + 1, GST_TIME_ARGS(at), pfap::to_string(b.status)),
        ("%" G_GUINT64_FORMAT " so far", s.bad_bookmarks));
  }
  return utterance;
}

// The text property, if set.
static std::optional<std::string> text_property(GstPfapAlign* self) {
  GST_OBJECT_LOCK(self);
  std::optional<std::string> text;
  if (self->text != nullptr) text = self->text;
  GST_OBJECT_UNLOCK(self);
  return text;
}

static pfap::tts::VoiceSettings voice_settings(GstPfapAlign* self) {
  GST_OBJECT_LOCK(self);
  pfap::tts::VoiceSettings voice;
  voice.voice = self->voice;
  GST_OBJECT_UNLOCK(self);
  return voice;
}

// Aligns the utterance `u` of the audio kept and pushes its phonemes on `pfap`.
static GstFlowReturn align_utterance(GstPfapAlign* self, const pfap::align::UtteranceSpan& u) {
  Stream& s = *self->stream;
  const size_t from = u.from;
  const GstClockTime at = pfap::align::sample_time(s.first, from, s.rate);
  const pfap::tts::Utterance utterance = parse_text(self, u.text, at);
  const pfap::tts::VoiceSettings voice = voice_settings(self);

  pfap::align::Alignment alignment;
  std::string error;
  const std::span<const int16_t> audio(s.kept.samples().data() + from, u.to - from);
  if (!pfap::align::align(utterance, voice, audio, s.rate, alignment, error)) {
    GST_ELEMENT_ERROR(self, LIBRARY, FAILED, ("%s", error.c_str()), (nullptr));
    return GST_FLOW_ERROR;
  }
  GST_DEBUG_OBJECT(self, "utterance at %" GST_TIME_FORMAT ": %zu phonemes, %zu samples, cost %.2f",
                   GST_TIME_ARGS(at), alignment.phonemes.size(), audio.size(),
                   alignment.relative_cost);
  if (u.is_text) {
    warn_problem(self, alignment.problem, at, alignment.relative_cost, alignment.heard_agreement);
  }
  PFAP_WARN_INEXACT_PHONEMES(self, alignment.inexact, voice.voice, s.warned_phonemes);

  return push_phonemes(self, alignment.phonemes, from);
}

// The sample, counted from `first`, where a text at `running_time` starts; 0 before the audio,
// none for a text without a time.
static std::optional<size_t> text_sample(GstPfapAlign* self, std::optional<uint64_t> running_time) {
  Stream& s = *self->stream;
  if (!running_time.has_value()) return std::nullopt;
  const guint64 position =
      gst_segment_position_from_running_time(&s.segment, GST_FORMAT_TIME, *running_time);
  if (!GST_CLOCK_TIME_IS_VALID(position)) return 0;
  return pfap::align::sample_at(s.first, position, s.rate);
}

// Aligns the audio kept so far with its texts and pushes the phonemes, then forgets both. At
// the end of the stream (`eos`) it first waits for the text pad's EOS, when it is linked.
static GstFlowReturn align_kept(GstPfapAlign* self, bool eos) {
  Stream& s = *self->stream;
  const std::optional<std::string> property = text_property(self);
  const bool text_linked = gst_pad_is_linked(self->textpad);

  if (!s.texts.ready(eos && text_linked)) return GST_FLOW_FLUSHING;
  // No audio yet (the first caps and segment): the texts wait for it.
  if (s.kept.samples().empty() || s.rate == 0) return GST_FLOW_OK;
  const std::vector<pfap::align::UtteranceSpan> utterances =
      s.texts.take_utterances([self](std::optional<uint64_t> t) { return text_sample(self, t); },
                              text_linked ? std::nullopt : property, s.kept.samples().size(), eos);
  const pfap::align::PhonemeSource source =
      pfap::align::phoneme_source(!utterances.empty(), s.recognizer);
  GstFlowReturn ret = GST_FLOW_OK;
  if (source != pfap::align::PhonemeSource::kTexts) ret = hear_kept(self, source);
  for (const pfap::align::UtteranceSpan& u : utterances) {
    if (ret != GST_FLOW_OK) break;
    ret = align_utterance(self, u);
  }
  s.kept.reset();
  s.first = GST_CLOCK_TIME_NONE;
  return ret;
}

// Live (#GstPfapAlign:live): the phonemes go out as the audio comes, by align/live.h;
// docs/align.md, "Live". One utterance is open at a time: the text property's, each text
// buffer's from its PTS (or from its arrival when it has none or comes late), or a pause for
// the audio before the first; without any text, the recognizer's (align/recognizer.h) over
// the whole stream.

// Where live phonemes come from: the text property, or text_sink when it is linked (even if it
// gives nothing: the audio is then a pause until its first text); else the recognizer.
static pfap::align::PhonemeSource live_source(GstPfapAlign* self) {
  return pfap::align::phoneme_source(
      text_property(self).has_value() || gst_pad_is_linked(self->textpad),
      self->stream->recognizer);
}

// Ends the open utterance at the audio so far and pushes its last phonemes.
static GstFlowReturn live_end_utterance(GstPfapAlign* self) {
  Stream& s = *self->stream;
  const bool recognizing = s.utterances.is_recognizing();
  std::vector<pfap::tts::SpokenPhoneme> phonemes;
  s.utterances.end(phonemes);
  if (recognizing) {
    const GstClockTime at =
        pfap::align::sample_time(s.first, s.utterances.utterance_start(), s.rate);
    warn_recognition_problem(self, s.utterances.recognition_problem(), at);
  }
  return push_phonemes(self, phonemes, 0);
}

// Ends the open utterance and starts that of `bytes` at the audio so far. `is_text` as in
// align_utterance.
static GstFlowReturn live_start_utterance(GstPfapAlign* self, const std::string& bytes,
                                          bool is_text) {
  Stream& s = *self->stream;
  const GstFlowReturn ret = live_end_utterance(self);
  if (ret != GST_FLOW_OK) return ret;
  const GstClockTime at = pfap::align::sample_time(s.first, s.utterances.samples(), s.rate);
  const pfap::tts::Utterance utterance = parse_text(self, bytes, at);
  const pfap::tts::VoiceSettings voice = voice_settings(self);
  std::string error;
  if (!s.utterances.start_text(utterance, voice, s.rate, error)) {
    GST_ELEMENT_ERROR(self, LIBRARY, FAILED, ("%s", error.c_str()), (nullptr));
    return GST_FLOW_ERROR;
  }
  if (is_text) warn_problem(self, s.utterances.problem(), at, 0, -1);
  PFAP_WARN_INEXACT_PHONEMES(self, s.utterances.inexact(), voice.voice, s.warned_phonemes);
  return GST_FLOW_OK;
}

// Gives `samples` to the open utterance and pushes the phonemes now settled.
static GstFlowReturn live_feed(GstPfapAlign* self, std::span<const int16_t> samples) {
  std::vector<pfap::tts::SpokenPhoneme> phonemes;
  self->stream->utterances.push(samples, phonemes);
  return push_phonemes(self, phonemes, 0);
}

// Takes the texts of text_sink that start before sample `end` as utterances in order, none
// before the audio so far.
static std::vector<pfap::align::UtteranceSpan> live_take_texts(GstPfapAlign* self, size_t end) {
  Stream& s = *self->stream;
  return s.texts.take_live_utterances(
      [self](std::optional<uint64_t> t) { return text_sample(self, t); }, s.utterances.samples(),
      end);
}

// The audio of `buffer` to the aligner, cut where utterances start; the audio pushed after
// the phonemes it settles.
static GstFlowReturn live_chain(GstPfapAlign* self, GstBuffer* buffer) {
  Stream& s = *self->stream;
  std::vector<int16_t> samples;
  GstMapInfo map;
  if (gst_buffer_map(buffer, &map, GST_MAP_READ)) {
    pfap::align::append_s16le(std::span(map.data, map.size), map.size, samples);
    gst_buffer_unmap(buffer, &map);
  }
  GstFlowReturn ret = GST_FLOW_OK;
  if (!s.utterances.is_open()) {
    const std::optional<std::string> property = text_property(self);
    const bool from_pad = gst_pad_is_linked(self->textpad);
    const pfap::align::PhonemeSource source = live_source(self);
    std::string error;
    if (source == pfap::align::PhonemeSource::kTexts ||
        source == pfap::align::PhonemeSource::kPause) {
      if (source == pfap::align::PhonemeSource::kPause) warn_cannot_recognize(self);
      ret = live_start_utterance(self, from_pad ? "" : property.value_or(""),
                                 !from_pad && property.has_value());
    } else if (!s.utterances.start_heard(s.recognizer, s.rate, error)) {
      GST_ELEMENT_ERROR(self, LIBRARY, INIT, ("%s", error.c_str()), (nullptr));  // no model
      ret = GST_FLOW_ERROR;
    }
  }
  size_t done = 0;
  for (const pfap::align::UtteranceSpan& u :
       live_take_texts(self, s.utterances.samples() + samples.size())) {
    if (ret != GST_FLOW_OK) break;
    const size_t n = u.from - s.utterances.samples();
    ret = live_feed(self, std::span(samples).subspan(done, n));
    done += n;
    if (ret == GST_FLOW_OK) ret = live_start_utterance(self, u.text, true);
  }
  if (ret == GST_FLOW_OK) ret = live_feed(self, std::span(samples).subspan(done));
  if (ret != GST_FLOW_OK) {
    gst_buffer_unref(buffer);
    return ret;
  }
  return gst_flow_combiner_update_pad_flow(self->flow_combiner, self->srcpad,
                                           gst_pad_push(self->srcpad, buffer));
}

// The audio ended (EOS, a new segment or rate): the open utterance's last phonemes.
static GstFlowReturn live_end(GstPfapAlign* self) {
  Stream& s = *self->stream;
  const GstFlowReturn ret = live_end_utterance(self);
  s.first = GST_CLOCK_TIME_NONE;
  s.utterances.reset();
  return ret;
}

// The latency upstream's plus ours: when the phonemes of the audio come at the latest.
static gboolean live_latency_query(GstPfapAlign* self, GstQuery* query) {
  if (!gst_pad_peer_query(self->sinkpad, query)) return FALSE;
  gboolean live = FALSE;
  GstClockTime min = 0, max = GST_CLOCK_TIME_NONE;
  gst_query_parse_latency(query, &live, &min, &max);
  const GstClockTime ours = pfap::align::live_latency_ms(live_source(self)) * GST_MSECOND;
  GST_DEBUG_OBJECT(self, "upstream latency %" GST_TIME_FORMAT ", ours %" GST_TIME_FORMAT,
                   GST_TIME_ARGS(min), GST_TIME_ARGS(ours));
  gst_query_set_latency(query, live, min + ours,
                        GST_CLOCK_TIME_IS_VALID(max) ? max + ours : GST_CLOCK_TIME_NONE);
  return TRUE;
}

static gboolean gst_pfap_align_src_query(GstPad* pad, GstObject* parent, GstQuery* query) {
  GstPfapAlign* self = GST_PFAP_ALIGN(parent);
  if (GST_QUERY_TYPE(query) == GST_QUERY_LATENCY && self->stream->live) {
    return live_latency_query(self, query);
  }
  return gst_pad_query_default(pad, parent, query);
}

static GstFlowReturn chain_audio(GstPfapAlign* self, GstBuffer* buffer) {
  Stream& s = *self->stream;
  if (s.rate == 0) {
    gst_buffer_unref(buffer);
    GST_ELEMENT_ERROR(self, CORE, NEGOTIATION, (nullptr), ("audio before caps"));
    return GST_FLOW_NOT_NEGOTIATED;
  }
  if (!GST_CLOCK_TIME_IS_VALID(s.first)) {
    s.first = GST_BUFFER_PTS_IS_VALID(buffer) ? GST_BUFFER_PTS(buffer) : s.segment.start;
    // The phonemes come when the audio ends: a gap meanwhile lets sinks after `pfap` preroll
    // (and the audio sink, which waits for the pipeline, start).
    gst_pad_push_event(self->pfappad, gst_event_new_gap(s.first, 0));
  }
  if (s.live) return live_chain(self, buffer);
  GstMapInfo map;
  if (gst_buffer_map(buffer, &map, GST_MAP_READ)) {
    if (s.kept.append(std::span(map.data, map.size), s.rate)) {
      GST_ELEMENT_WARNING(self, STREAM, TOO_LAZY,
                          ("More than %u s of audio in one stream: the rest is not aligned",
                           pfap::align::kMaxAudioSeconds),
                          ("give the text as utterances with PTS on text_sink"));
    }
    gst_buffer_unmap(buffer, &map);
  }
  return gst_flow_combiner_update_pad_flow(self->flow_combiner, self->srcpad,
                                           gst_pad_push(self->srcpad, buffer));
}

static GstFlowReturn gst_pfap_align_chain(GstPad*, GstObject* parent, GstBuffer* buffer) {
  GstPfapAlign* self = GST_PFAP_ALIGN(parent);
  return guarded(self, [&] { return chain_audio(self, buffer); });
}

// The audio ended (EOS, a new segment or rate): its phonemes, aligned now or the live
// utterance's last. An event function cannot return their flow: a fatal one is posted, as
// gst-plugins-good's demuxers post a flow that stops their task (GST_FLOW_ERROR was posted
// where it arose). False then, and the event still goes on.
static bool end_audio(GstPfapAlign* self, bool eos) {
  const GstFlowReturn ret =
      guarded(self, [&] { return self->stream->live ? live_end(self) : align_kept(self, eos); });
  if (ret == GST_FLOW_OK || ret == GST_FLOW_FLUSHING || ret == GST_FLOW_EOS) return true;
  GST_DEBUG_OBJECT(self, "phonemes at the audio's end: %s", gst_flow_get_name(ret));
  if (ret != GST_FLOW_ERROR) GST_ELEMENT_FLOW_ERROR(self, ret);
  return false;
}

// `pfap`'s stream-start (in the audio's group, sparse) and caps, when the audio's stream starts.
static void push_pfap_start(GstPfapAlign* self, GstEvent* audio_start) {
  const gchar* audio_id = nullptr;
  gst_event_parse_stream_start(audio_start, &audio_id);
  gchar* id = g_strdup_printf("%s/pfap", audio_id != nullptr ? audio_id : "pfapalign");
  GstEvent* start = gst_event_new_stream_start(id);
  g_free(id);
  guint group = 0;
  if (gst_event_parse_group_id(audio_start, &group)) gst_event_set_group_id(start, group);
  gst_pad_push_event(self->pfappad, pfap_make_sparse(start));
  // The stream's phonemes are the detector's when it has no text: its alphabet, from now on.
  Stream& s = *self->stream;
  GST_OBJECT_LOCK(self);
  s.recognizer = self->recognizer;
  GST_OBJECT_UNLOCK(self);
  const pfap::align::PhonemeSource source = live_source(self);
  if (source != pfap::align::PhonemeSource::kVisemes) {
    s.recognizer = pfap::align::Recognizer::kPhonemes;
  }
  const std::string alphabet(pfap::align::alphabet_of(source));
  GstCaps* caps = gst_caps_from_string(PFAP_MARKUP_CAPS);
  gst_caps_set_simple(caps, "alphabet", G_TYPE_STRING, alphabet.c_str(), nullptr);
  gst_pad_push_event(self->pfappad, gst_event_new_caps(caps));
  gst_caps_unref(caps);
}

static gboolean gst_pfap_align_sink_event(GstPad* pad, GstObject* parent, GstEvent* event) {
  GstPfapAlign* self = GST_PFAP_ALIGN(parent);
  Stream& s = *self->stream;
  bool ended = true;  // the phonemes of audio that ended here were pushed
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_STREAM_START:
      push_pfap_start(self, event);
      break;
    case GST_EVENT_CAPS: {
      GstCaps* caps = nullptr;
      gst_event_parse_caps(event, &caps);
      gint rate = 0;
      gst_structure_get_int(gst_caps_get_structure(caps, 0), "rate", &rate);
      if (static_cast<unsigned>(rate) != s.rate) {
        ended = end_audio(self, false);
        s.rate = static_cast<unsigned>(rate);
        const pfap::align::RateProblem problem = pfap::align::rate_problem(s.rate, s.recognizer);
        if (problem == pfap::align::RateProblem::kCannotDetectVisemes) {
          GST_ELEMENT_WARNING(
              self, STREAM, FORMAT,
              ("Audio at %u Hz: the viseme detector cannot take it, its phonemes are pauses",
               s.rate),
              ("the detector takes %u to %u Hz: put audioresample before",
               pfap::align::kMinVisemeInputRate, pfap::align::kMaxVisemeInputRate));
        } else if (problem == pfap::align::RateProblem::kCannotAlign) {
          GST_ELEMENT_WARNING(self, STREAM, FORMAT,
                              ("Audio at %u Hz cannot be aligned: its phonemes are pauses", s.rate),
                              ("the alignment takes %u to %u Hz: put audioresample before",
                               pfap::align::kMinRate, pfap::align::kMaxRate));
        }
      }
      break;
    }
    case GST_EVENT_SEGMENT: {
      ended = end_audio(self, false);
      const GstSegment* segment = nullptr;
      gst_event_parse_segment(event, &segment);
      gst_segment_copy_into(segment, &s.segment);
      gst_pad_push_event(self->pfappad, gst_event_new_segment(segment));
      break;
    }
    case GST_EVENT_GAP:
      gst_pad_push_event(self->pfappad, gst_event_ref(event));
      break;
    case GST_EVENT_EOS:
      ended = end_audio(self, true);
      gst_pad_push_event(self->pfappad, gst_event_new_eos());
      break;
    case GST_EVENT_FLUSH_START:
      s.texts.flush();
      gst_pad_push_event(self->pfappad, gst_event_ref(event));
      break;
    case GST_EVENT_FLUSH_STOP:
      reset(self);
      gst_pad_push_event(self->pfappad, gst_event_ref(event));
      break;
    default:
      break;
  }
  return gst_pad_event_default(pad, parent, event) && ended;
}

static GstFlowReturn gst_pfap_align_text_chain(GstPad*, GstObject* parent, GstBuffer* buffer) {
  GstPfapAlign* self = GST_PFAP_ALIGN(parent);
  Stream& s = *self->stream;
  pfap::align::PadText t;
  GstMapInfo map;
  if (gst_buffer_map(buffer, &map, GST_MAP_READ)) {
    t.bytes.assign(reinterpret_cast<const char*>(map.data), map.size);
    gst_buffer_unmap(buffer, &map);
  }
  if (GST_BUFFER_PTS_IS_VALID(buffer) && s.text_segment.format == GST_FORMAT_TIME) {
    const guint64 running_time =
        gst_segment_to_running_time(&s.text_segment, GST_FORMAT_TIME, GST_BUFFER_PTS(buffer));
    if (GST_CLOCK_TIME_IS_VALID(running_time)) t.running_time = running_time;
  }
  s.texts.add(std::move(t));
  gst_buffer_unref(buffer);
  return GST_FLOW_OK;
}

// The text pad's events end here: its segment times the utterances, its EOS lets the
// alignment at the audio's end go on.
static gboolean gst_pfap_align_text_event(GstPad*, GstObject* parent, GstEvent* event) {
  GstPfapAlign* self = GST_PFAP_ALIGN(parent);
  Stream& s = *self->stream;
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_SEGMENT: {
      const GstSegment* segment = nullptr;
      gst_event_parse_segment(event, &segment);
      gst_segment_copy_into(segment, &s.text_segment);
      break;
    }
    case GST_EVENT_EOS:
      s.texts.end();
      break;
    case GST_EVENT_FLUSH_STOP:
      s.texts.clear();
      break;
    default:
      break;
  }
  gst_event_unref(event);
  return TRUE;
}

// `src` and `sink` are a pass-through pair; `text_sink` and `pfap` link to no other pad.
static GstIterator* gst_pfap_align_internal_links(GstPad* pad, GstObject* parent) {
  GstPfapAlign* self = GST_PFAP_ALIGN(parent);
  GstPad* other = pad == self->sinkpad  ? self->srcpad
                  : pad == self->srcpad ? self->sinkpad
                                        : nullptr;
  if (other == nullptr) return nullptr;
  GValue value = G_VALUE_INIT;
  g_value_init(&value, GST_TYPE_PAD);
  g_value_set_object(&value, other);
  GstIterator* it = gst_iterator_new_single(GST_TYPE_PAD, &value);
  g_value_unset(&value);
  return it;
}

static GstStateChangeReturn gst_pfap_align_change_state(GstElement* element,
                                                        GstStateChange transition) {
  GstPfapAlign* self = GST_PFAP_ALIGN(element);
  Stream& s = *self->stream;
  if (transition == GST_STATE_CHANGE_READY_TO_PAUSED) {
    reset(self);
    gst_segment_init(&s.text_segment, GST_FORMAT_TIME);
    s.rate = 0;
    s.problems = {};
    s.recognition_problems = {};
    s.bad_bookmarks = 0;
    s.warned_phonemes.clear();
    GST_OBJECT_LOCK(self);
    s.live = self->live;
    s.recognizer = self->recognizer;
    GST_OBJECT_UNLOCK(self);
    unsigned rate = 0;
    std::string error;
    if (!pfap::tts::check_voice(voice_settings(self), rate, error)) {
      GST_ELEMENT_ERROR(self, RESOURCE, NOT_FOUND, ("%s", error.c_str()), (nullptr));
      return GST_STATE_CHANGE_FAILURE;
    }
  } else if (transition == GST_STATE_CHANGE_PAUSED_TO_READY) {
    // An EOS waiting for the text's stops before the pads deactivate.
    s.texts.flush();
  }
  return GST_ELEMENT_CLASS(gst_pfap_align_parent_class)->change_state(element, transition);
}

static void gst_pfap_align_set_property(GObject* object, guint prop_id, const GValue* value,
                                        GParamSpec* pspec) {
  GstPfapAlign* self = GST_PFAP_ALIGN(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_TEXT:
      g_free(self->text);
      self->text = g_value_dup_string(value);
      break;
    case PROP_VOICE:
      g_free(self->voice);
      self->voice = g_value_dup_string(value);
      if (self->voice == nullptr) self->voice = g_strdup(kDefaultVoice);
      break;
    case PROP_LIVE:
      self->live = g_value_get_boolean(value);
      break;
    case PROP_RECOGNIZER:
      self->recognizer = static_cast<pfap::align::Recognizer>(g_value_get_enum(value));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_align_get_property(GObject* object, guint prop_id, GValue* value,
                                        GParamSpec* pspec) {
  GstPfapAlign* self = GST_PFAP_ALIGN(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_TEXT:
      g_value_set_string(value, self->text);
      break;
    case PROP_VOICE:
      g_value_set_string(value, self->voice);
      break;
    case PROP_LIVE:
      g_value_set_boolean(value, self->live);
      break;
    case PROP_RECOGNIZER:
      g_value_set_enum(value, static_cast<gint>(self->recognizer));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_align_finalize(GObject* object) {
  GstPfapAlign* self = GST_PFAP_ALIGN(object);
  delete self->stream;
  gst_flow_combiner_free(self->flow_combiner);
  g_free(self->text);
  g_free(self->voice);
  G_OBJECT_CLASS(gst_pfap_align_parent_class)->finalize(object);
}

static void gst_pfap_align_class_init(GstPfapAlignClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);

  GST_DEBUG_CATEGORY_INIT(pfapalign_debug, "pfapalign", 0, "PFAP forced alignment");

  gobject_class->set_property = gst_pfap_align_set_property;
  gobject_class->get_property = gst_pfap_align_get_property;
  gobject_class->finalize = gst_pfap_align_finalize;

  constexpr auto kReady = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                   GST_PARAM_MUTABLE_READY);
  /**
   * GstPfapAlign:text:
   *
   * The text of the whole stream, with MPEG-4 bookmarks `<FAP ...>`, when `text_sink` is not
   * linked. Ignored when it is.
   */
  g_object_class_install_property(
      gobject_class, PROP_TEXT,
      g_param_spec_string("text", "Text",
                          "What the audio says, with <FAP ...> bookmarks, when text_sink is not "
                          "linked",
                          nullptr, kReady));
  /**
   * GstPfapAlign:voice:
   *
   * The espeak-ng voice that speaks the text to align against: the recording's language
   * ("en", "en-us", "de", ...). Its phonemes go to x-pfap-arpabet as pfaptts's do.
   */
  g_object_class_install_property(
      gobject_class, PROP_VOICE,
      g_param_spec_string("voice", "Voice", "espeak-ng voice of the recording's language",
                          kDefaultVoice, kReady));
  /**
   * GstPfapAlign:live:
   *
   * Aligns (or, without a text, recognizes) as the audio comes, for live sources: each
   * phoneme goes out by the time 350 ms (and one upstream buffer) more than its start has
   * come, and the LATENCY query says 400 ms more than upstream's, 700 ms when it recognizes
   * (docs/align.md, "Live" and "Live without the text"); with #GstPfapAlign:recognizer
   * `visemes` and no text, 89.75 ms and 95 ms. Off: the phonemes come when the audio
   * ends, aligned on it whole. Read when the element goes to PAUSED.
   */
  g_object_class_install_property(
      gobject_class, PROP_LIVE,
      g_param_spec_boolean("live", "Live",
                           "Align (or recognize) as the audio comes, each phoneme out within "
                           "the latency it declares (400 ms; 700 ms when it recognizes; 95 ms "
                           "with recognizer=visemes), "
                           "instead of when the audio ends",
                           FALSE, kReady));
  /**
   * GstPfapAlign:recognizer:
   *
   * Without a text, what hears the audio. `phonemes`: pocketsphinx's all-phone search,
   * x-pfap-arpabet, the accurate choice (its visemes right on 56 % of the frames of human
   * speech offline, 52 % live; the detector's on 48 %), which declares 700 ms live.
   * `visemes`: the frame-level viseme detector, x-pfap-oculus-viseme, each run of 10 ms
   * frames one phoneme standing for its viseme; live it declares 95 ms (docs/align.md, "The
   * viseme detector in pfapalign"), for lips on live speech in a conversation. Ignored when
   * there is a text. Read when the element goes to PAUSED; the stream's alphabet is chosen
   * when it starts.
   */
  g_object_class_install_property(
      gobject_class, PROP_RECOGNIZER,
      g_param_spec_enum("recognizer", "Recognizer",
                        "Without a text: pocketsphinx's phonemes (accurate, 700 ms live) or the "
                        "viseme detector's visemes (95 ms live)",
                        GST_TYPE_PFAP_ALIGN_RECOGNIZER,
                        static_cast<gint>(pfap::align::Recognizer::kPhonemes), kReady));

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &text_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_add_static_pad_template(element_class, &pfap_template);
  gst_element_class_set_static_metadata(
      element_class, "PFAP forced alignment", "Filter/Analyzer/Audio",
      "Aligns the phonemes of a text to a recording of it, or recognizes them without the text: "
      "the audio unchanged, and its phonemes with bookmarks' facial animation parameters (PFAP) "
      "as application/x-pfap",
      "gst-pfap developers");

  element_class->change_state = gst_pfap_align_change_state;
}

static void gst_pfap_align_init(GstPfapAlign* self) {
  self->sinkpad = gst_pad_new_from_static_template(&sink_template, "sink");
  gst_pad_set_chain_function(self->sinkpad, gst_pfap_align_chain);
  gst_pad_set_event_function(self->sinkpad, gst_pfap_align_sink_event);
  self->textpad = gst_pad_new_from_static_template(&text_template, "text_sink");
  gst_pad_set_chain_function(self->textpad, gst_pfap_align_text_chain);
  gst_pad_set_event_function(self->textpad, gst_pfap_align_text_event);
  self->srcpad = gst_pad_new_from_static_template(&src_template, "src");
  self->pfappad = gst_pad_new_from_static_template(&pfap_template, "pfap");
  gst_pad_set_query_function(self->srcpad, gst_pfap_align_src_query);
  gst_pad_set_query_function(self->pfappad, gst_pfap_align_src_query);
  gst_pad_use_fixed_caps(self->pfappad);
  for (GstPad* pad : {self->sinkpad, self->srcpad}) {
    GST_PAD_SET_PROXY_CAPS(pad);
    GST_PAD_SET_PROXY_ALLOCATION(pad);
    gst_pad_set_iterate_internal_links_function(pad, gst_pfap_align_internal_links);
  }
  for (GstPad* pad : {self->sinkpad, self->textpad, self->srcpad, self->pfappad}) {
    gst_element_add_pad(GST_ELEMENT(self), pad);
  }
  self->flow_combiner = gst_flow_combiner_new();
  gst_flow_combiner_add_pad(self->flow_combiner, self->srcpad);
  gst_flow_combiner_add_pad(self->flow_combiner, self->pfappad);

  self->text = nullptr;
  self->voice = g_strdup(kDefaultVoice);
  self->live = FALSE;
  self->recognizer = pfap::align::Recognizer::kPhonemes;
  self->stream = new Stream{};
  gst_segment_init(&self->stream->segment, GST_FORMAT_TIME);
  gst_segment_init(&self->stream->text_segment, GST_FORMAT_TIME);
}
