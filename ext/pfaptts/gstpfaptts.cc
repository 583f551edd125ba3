// SPDX-License-Identifier: LGPL-2.1-or-later
// The example pipelines stay on one line, to be copied.
// clang-format off
/**
 * SECTION:element-pfaptts
 * @title: pfaptts
 * @see_also: rtppfappay, pfaptextenc
 *
 * A text-to-speech server's heart (draft-ietf-avt-rtp-pfap-00, section 3): speaks text with
 * MPEG-4 bookmarks `<FAP ...>` inline through espeak-ng, and outputs the speech on `audio`
 * (audio/x-raw, S16LE mono at espeak-ng's rate, 22050 Hz for Debian's voices) and its
 * phonemes on `pfap` (application/x-pfap, `alphabet=x-pfap-arpabet`), one phoneme event per
 * buffer with the FAPs of the bookmarks that start with it (docs/tts.md).
 *
 * The text comes from the sink pad (text/x-raw or text/plain, one utterance per buffer), or,
 * when the sink pad is not linked, from #GstPfapTts:text, which the element then speaks from
 * its own thread before it sends EOS. Both outputs are one TIME segment from 0: audio
 * timestamps come from the sample count, a phoneme's PTS is the audio position of its start.
 * An utterance whose PTS (running time) is later than the audio so far is preceded by
 * silence up to it, zero samples on `audio` and a GAP event on `pfap`; one without a PTS
 * follows the audio before it at once. The `pfap` stream is sparse.
 *
 * A bad bookmark is an error naming its character (counted from 1 in the utterance); with
 * #GstPfapTts:skip-bad-bookmarks it is a warning (at the 1st, 2nd, 4th, ... only, counted in
 * #GstPfapTts:stats), and the bookmark is left out.
 *
 * An utterance is spoken a piece (about a sentence) at a time: a long text starts speaking
 * after its first sentence, the speech held is one piece's whatever the text's length, and a
 * flush or a state change stops it within one piece (docs/tts.md, "Long texts").
 *
 * Both source pads are pushed from one thread: put a queue on each branch, as after a demuxer.
 *
 * ## Example pipelines
 * |[
 * gst-launch-1.0 pfaptts text="Hello <FAP 2 1 40 0 0 500 1> world." name=t t.audio ! queue ! audioconvert ! autoaudiosink t.pfap ! queue ! pfaptextenc ! fdsink
 * ]| Speaks a sentence, smiling from "world" on, and prints its phonemes as .pfap text.
 * |[
 * gst-launch-1.0 fdsrc ! text/x-raw,format=utf8 ! pfaptts name=t t.audio ! queue ! audioconvert ! autoaudiosink t.pfap ! queue ! fakesink
 * ]| Speaks what comes on standard input, one read at a time.
 */
// clang-format on
#include "gstpfaptts.h"

#include <gst/base/gstflowcombiner.h>

#include <algorithm>
#include <atomic>
#include <set>
#include <string>
#include <vector>

#include "inexact.h"
#include "markupbuffer.h"
#include "noseek.h"
#include "pfap/markup.h"
#include "pieces.h"
#include "ratelimit.h"
#include "sparse.h"
#include "speech.h"

GST_DEBUG_CATEGORY_STATIC(pfaptts_debug);
#define GST_CAT_DEFAULT pfaptts_debug

namespace {

constexpr int kDefaultRate = 175;
constexpr int kDefaultPitch = 50;
constexpr int kDefaultVolume = 100;
constexpr const char* kDefaultVoice = "en";
// Audio goes out in buffers of at most this many samples (186 ms at 22050 Hz), interleaved
// with the phonemes, so that queues downstream hold both streams over the same time.
constexpr size_t kMaxBufferSamples = 4096;

enum {
  PROP_0,
  PROP_TEXT,
  PROP_VOICE,
  PROP_RATE,
  PROP_PITCH,
  PROP_VOLUME,
  PROP_SKIP_BAD_BOOKMARKS,
  PROP_BAD_BOOKMARKS,
  PROP_STATS,
};

// The output timeline: a position is `base` plus `samples` at `rate`, so that a change of rate
// (another voice) starts a new count and no rounding accumulates.
struct Stream {
  bool need_start = true;    // stream-start and caps still to send
  bool need_segment = true;  // a segment still to send
  unsigned rate = 0;         // of the audio caps sent
  GstClockTime base = 0;
  uint64_t samples = 0;
  bool audio_discont = true;  // the next buffer on each pad is the first since a start or flush
  bool pfap_discont = true;
  GstSegment input_segment;               // the sink pad's, for utterance running times
  std::set<std::string> warned_phonemes;  // inexact mnemonics already warned about
  // Set from other threads (flush-start, PAUSED to READY) to stop a synthesis at once;
  // cleared by reset().
  std::atomic<bool> cancel{false};

  // The time of sample number `n` of the current count.
  GstClockTime time_at(uint64_t n) const {
    return base + (rate == 0 ? 0 : gst_util_uint64_scale(n, GST_SECOND, rate));
  }
  GstClockTime position() const { return time_at(samples); }
};

}  // namespace

struct _GstPfapTts {
  GstElement parent;
  GstPad* sinkpad;
  GstPad* audiopad;
  GstPad* pfappad;
  GstFlowCombiner* flow_combiner;

  // Properties, under the object lock.
  gchar* text;
  gchar* voice;
  gint rate;
  gint pitch;
  gint volume;
  gboolean skip_bad_bookmarks;
  guint64 bad_bookmarks;  // left out since READY to PAUSED

  Stream* stream;  // the streaming thread's
};

static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS,
                            GST_STATIC_CAPS("text/x-raw, format = (string) utf8; text/plain"));

static GstStaticPadTemplate audio_template = GST_STATIC_PAD_TEMPLATE(
    "audio", GST_PAD_SRC, GST_PAD_ALWAYS,
    GST_STATIC_CAPS("audio/x-raw, format = (string) S16LE, layout = (string) interleaved, "
                    "rate = (int) [ 1, MAX ], channels = (int) 1"));

static GstStaticPadTemplate pfap_template = GST_STATIC_PAD_TEMPLATE(
    "pfap", GST_PAD_SRC, GST_PAD_ALWAYS,
    GST_STATIC_CAPS(PFAP_MARKUP_CAPS ", alphabet = (string) x-pfap-arpabet"));

G_DEFINE_TYPE(GstPfapTts, gst_pfap_tts, GST_TYPE_ELEMENT)
// Text in, speech out, as festival is classified; rank NONE so that decodebin never speaks a
// text file it meets.
GST_ELEMENT_REGISTER_DEFINE(pfaptts, "pfaptts", GST_RANK_NONE, GST_TYPE_PFAP_TTS)

// Back to the start of the timeline: a new stream (READY to PAUSED), or after FLUSH_STOP the
// same stream, whose stream-start and caps stay.
static void reset(GstPfapTts* self, bool new_stream) {
  Stream& s = *self->stream;
  if (new_stream) {
    s.need_start = true;
    s.rate = 0;
  }
  s.need_segment = true;
  s.base = 0;
  s.samples = 0;
  s.audio_discont = true;
  s.pfap_discont = true;
  gst_segment_init(&s.input_segment, GST_FORMAT_TIME);
  s.warned_phonemes.clear();
  s.cancel = false;
  gst_flow_combiner_reset(self->flow_combiner);
}

static pfap::tts::VoiceSettings voice_settings(GstPfapTts* self) {
  GST_OBJECT_LOCK(self);
  pfap::tts::VoiceSettings v{self->voice, self->rate, self->pitch, self->volume};
  GST_OBJECT_UNLOCK(self);
  return v;
}

static void push_audio_caps(GstPfapTts* self, unsigned rate) {
  GstCaps* caps = gst_caps_new_simple("audio/x-raw", "format", G_TYPE_STRING, "S16LE", "layout",
                                      G_TYPE_STRING, "interleaved", "rate", G_TYPE_INT,
                                      static_cast<gint>(rate), "channels", G_TYPE_INT, 1, nullptr);
  gst_pad_push_event(self->audiopad, gst_event_new_caps(caps));
  gst_caps_unref(caps);
}

// Before the first output: stream-start (one group; `pfap` sparse) and caps on both pads;
// new audio caps whenever the rate changes (another voice); a segment at the start and after a
// flush.
static void send_events(GstPfapTts* self, unsigned rate) {
  Stream& s = *self->stream;
  if (s.need_start) {
    s.need_start = false;
    const guint group = gst_util_group_id_next();
    for (GstPad* pad : {self->audiopad, self->pfappad}) {
      gchar* id = gst_pad_create_stream_id(pad, GST_ELEMENT(self), GST_PAD_NAME(pad));
      GstEvent* start = gst_event_new_stream_start(id);
      g_free(id);
      gst_event_set_group_id(start, group);
      if (pad == self->pfappad) start = pfap_make_sparse(start);
      gst_pad_push_event(pad, start);
    }
    GstCaps* caps = gst_static_pad_template_get_caps(&pfap_template);
    gst_pad_push_event(self->pfappad, gst_event_new_caps(caps));
    gst_caps_unref(caps);
  }
  if (rate != s.rate) {
    s.base = s.position();
    s.samples = 0;
    s.rate = rate;
    push_audio_caps(self, rate);
  }
  if (s.need_segment) {
    s.need_segment = false;
    GstSegment segment;
    gst_segment_init(&segment, GST_FORMAT_TIME);
    for (GstPad* pad : {self->audiopad, self->pfappad}) {
      gst_pad_push_event(pad, gst_event_new_segment(&segment));
    }
  }
}

static GstFlowReturn combine(GstPfapTts* self, GstPad* pad, GstFlowReturn ret) {
  return gst_flow_combiner_update_pad_flow(self->flow_combiner, pad, ret);
}

// Pushes `n` samples (nullptr: silence) as audio buffers timed by the sample count.
static GstFlowReturn push_audio(GstPfapTts* self, const int16_t* data, size_t n) {
  Stream& s = *self->stream;
  GstFlowReturn ret = GST_FLOW_OK;
  while (n > 0 && ret == GST_FLOW_OK) {
    const size_t chunk = std::min(n, kMaxBufferSamples);
    const size_t bytes = chunk * sizeof(int16_t);
    GstBuffer* buffer = gst_buffer_new_allocate(nullptr, bytes, nullptr);
    if (data == nullptr) {
      gst_buffer_memset(buffer, 0, 0, bytes);
    } else {
#if G_BYTE_ORDER == G_LITTLE_ENDIAN
      gst_buffer_fill(buffer, 0, data, bytes);  // native samples are already S16LE
#else
      GstMapInfo map;
      gst_buffer_map(buffer, &map, GST_MAP_WRITE);
      auto* out = reinterpret_cast<int16_t*>(map.data);
      for (size_t i = 0; i < chunk; ++i) out[i] = GINT16_TO_LE(data[i]);
      gst_buffer_unmap(buffer, &map);
#endif
    }
    const GstClockTime start = s.position();
    GST_BUFFER_PTS(buffer) = start;
    GST_BUFFER_OFFSET(buffer) = s.samples;
    s.samples += chunk;
    GST_BUFFER_OFFSET_END(buffer) = s.samples;
    GST_BUFFER_DURATION(buffer) = s.position() - start;
    if (s.audio_discont) GST_BUFFER_FLAG_SET(buffer, GST_BUFFER_FLAG_DISCONT);
    s.audio_discont = false;
    ret = combine(self, self->audiopad, gst_pad_push(self->audiopad, buffer));
    if (data != nullptr) data += chunk;
    n -= chunk;
  }
  return ret;
}

// Silence up to running time `until`: zero samples on `audio`, a GAP on `pfap`.
static GstFlowReturn push_silence(GstPfapTts* self, GstClockTime until) {
  Stream& s = *self->stream;
  const GstClockTime from = s.position();
  if (until <= from) return GST_FLOW_OK;
  const uint64_t n = gst_util_uint64_scale_round(until - s.base, s.rate, GST_SECOND) - s.samples;
  gst_pad_push_event(self->pfappad, gst_event_new_gap(from, until - from));
  return push_audio(self, nullptr, n);
}

// Speaks one piece of an utterance starting at running time `at` (GST_CLOCK_TIME_NONE: right
// after the audio before it) and pushes it on both pads, phonemes interleaved with their audio.
static GstFlowReturn speak_piece(GstPfapTts* self, const pfap::tts::Utterance& piece,
                                 const pfap::tts::VoiceSettings& settings, GstClockTime at) {
  Stream& s = *self->stream;
  pfap::tts::Speech speech;
  std::string error;
  if (!pfap::tts::speak(piece, settings, speech, error, &s.cancel)) {
    GST_ELEMENT_ERROR(self, LIBRARY, FAILED, ("%s", error.c_str()), (nullptr));
    return GST_FLOW_ERROR;
  }
  if (s.cancel) return GST_FLOW_FLUSHING;
  PFAP_WARN_INEXACT_PHONEMES(self, speech.inexact, settings.voice, s.warned_phonemes);

  send_events(self, speech.sample_rate);
  GstFlowReturn ret = GST_FLOW_OK;
  if (GST_CLOCK_TIME_IS_VALID(at)) ret = push_silence(self, at);
  const uint64_t first = s.samples;
  GST_DEBUG_OBJECT(self, "piece of %zu phonemes, %zu samples at %" GST_TIME_FORMAT,
                   speech.phonemes.size(), speech.samples.size(), GST_TIME_ARGS(s.position()));
  for (const pfap::tts::SpokenPhoneme& p : speech.phonemes) {
    if (ret != GST_FLOW_OK) break;
    const GstClockTime start = s.time_at(first + p.start);
    const GstClockTime end = s.time_at(first + p.start + p.n_samples);
    // The duration on the stream's ms grid, as the PTS: a piece starts between two ms, and on
    // its own grid (speak()'s) a phoneme could end 1 ms from where the next one starts. A split
    // phoneme's 4095 ms piece may round to 4096 here: it stays 4095.
    pfap::MarkupEvent event = p.event;
    const auto ms = [](GstClockTime t) { return (t + GST_MSECOND / 2) / GST_MSECOND; };
    event.phoneme.duration_ms = static_cast<uint16_t>(
        std::min<GstClockTime>(ms(end) - ms(start), pfap::kMaxPhonemeDurationMs));
    GstBuffer* buffer = pfap_buffer_new(event);
    if (buffer == nullptr) {
      // speak() keeps every value in range: a bug.
      GST_ELEMENT_ERROR(self, STREAM, FAILED, (nullptr), ("a phoneme x-pfap cannot hold"));
      return GST_FLOW_ERROR;
    }
    GST_BUFFER_PTS(buffer) = start;
    GST_BUFFER_DURATION(buffer) = end - start;
    if (s.pfap_discont) GST_BUFFER_FLAG_SET(buffer, GST_BUFFER_FLAG_DISCONT);
    s.pfap_discont = false;
    ret = combine(self, self->pfappad, gst_pad_push(self->pfappad, buffer));
    if (ret == GST_FLOW_OK) ret = push_audio(self, speech.samples.data() + p.start, p.n_samples);
  }
  return ret;
}

// A bad bookmark: an error, or with skip-bad-bookmarks a warning at the 1st, 2nd, 4th, ...
// (one text can hold thousands) and the bookmark left out. False when it is an error.
static bool handle_bad_bookmark(GstPfapTts* self, const pfap::tts::BadBookmark& b) {
  GST_OBJECT_LOCK(self);
  const bool skip = self->skip_bad_bookmarks;
  const guint64 count = skip ? ++self->bad_bookmarks : self->bad_bookmarks;
  GST_OBJECT_UNLOCK(self);
  if (!skip) {
    GST_ELEMENT_ERROR(
        self, STREAM, FORMAT,
        ("Bad bookmark at character %zu: %s", b.character + 1, pfap::to_string(b.status)),
        ("set skip-bad-bookmarks to warn and leave it out"));
    return false;
  }
  GST_DEBUG_OBJECT(self, "left out a bad bookmark at character %zu: %s", b.character + 1,
                   pfap::to_string(b.status));
  if (pfap_warn_at(count)) {
    GST_ELEMENT_WARNING(self, STREAM, FORMAT,
                        ("Left out a bad bookmark at character %zu: %s", b.character + 1,
                         pfap::to_string(b.status)),
                        ("%" G_GUINT64_FORMAT
                         " bad bookmarks left out so far (warned at the 1st, 2nd, 4th, 8th, ...; "
                         "the stats property's bad-bookmarks counts them)",
                         count));
  }
  return true;
}

// Speaks one utterance starting at running time `at` (GST_CLOCK_TIME_NONE: right after the
// audio before it), a piece (about a sentence) at a time: the first is heard after its own
// synthesis, the speech held is one piece's, and a flush or a state change stops it at the
// next push (docs/tts.md, "Long texts").
static GstFlowReturn speak(GstPfapTts* self, std::string_view input, GstClockTime at) {
  const gchar* bad_utf8 = nullptr;
  if (!g_utf8_validate(input.data(), static_cast<gssize>(input.size()), &bad_utf8)) {
    GST_ELEMENT_ERROR(
        self, STREAM, DECODE,
        ("The text is not UTF-8 at byte %zu", static_cast<size_t>(bad_utf8 - input.data()) + 1),
        (nullptr));
    return GST_FLOW_ERROR;
  }
  std::vector<pfap::tts::BadBookmark> bad;
  const pfap::tts::Utterance utterance = pfap::tts::parse_utterance(input, bad);
  for (const pfap::tts::BadBookmark& b : bad) {
    if (!handle_bad_bookmark(self, b)) return GST_FLOW_ERROR;
  }

  const pfap::tts::VoiceSettings settings = voice_settings(self);
  GstFlowReturn ret = GST_FLOW_OK;
  size_t from = 0;
  size_t next_bookmark = 0;
  do {
    const size_t end = pfap::tts::piece_end(utterance.text, from);
    ret = speak_piece(self, pfap::tts::piece(utterance, from, end, next_bookmark), settings, at);
    at = GST_CLOCK_TIME_NONE;
    from = end;
  } while (ret == GST_FLOW_OK && from < utterance.text.size());
  return ret;
}

static GstFlowReturn gst_pfap_tts_chain(GstPad*, GstObject* parent, GstBuffer* buffer) {
  GstPfapTts* self = GST_PFAP_TTS(parent);
  Stream& s = *self->stream;
  GstClockTime at = GST_CLOCK_TIME_NONE;
  if (GST_BUFFER_PTS_IS_VALID(buffer) && s.input_segment.format == GST_FORMAT_TIME) {
    at = gst_segment_to_running_time(&s.input_segment, GST_FORMAT_TIME, GST_BUFFER_PTS(buffer));
  }
  GstMapInfo map;
  if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) {
    gst_buffer_unref(buffer);
    GST_ELEMENT_ERROR(self, RESOURCE, READ, (nullptr), ("cannot map the input buffer"));
    return GST_FLOW_ERROR;
  }
  const GstFlowReturn ret = speak(self, {reinterpret_cast<const char*>(map.data), map.size}, at);
  gst_buffer_unmap(buffer, &map);
  gst_buffer_unref(buffer);
  return ret;
}

// EOS on both pads, after the events a stream needs (a stream with no speech gets the caps of
// the rate espeak-ng starts with).
static gboolean push_eos(GstPfapTts* self) {
  unsigned rate = self->stream->rate;
  if (rate == 0) {
    std::string error;
    if (!pfap::tts::check_voice(voice_settings(self), rate, error)) {
      GST_ELEMENT_ERROR(self, LIBRARY, INIT, ("%s", error.c_str()), (nullptr));
      return FALSE;
    }
  }
  send_events(self, rate);
  gboolean ok = gst_pad_push_event(self->audiopad, gst_event_new_eos());
  ok &= gst_pad_push_event(self->pfappad, gst_event_new_eos());
  return ok;
}

static gboolean gst_pfap_tts_sink_event(GstPad* pad, GstObject* parent, GstEvent* event) {
  GstPfapTts* self = GST_PFAP_TTS(parent);
  Stream& s = *self->stream;
  switch (GST_EVENT_TYPE(event)) {
    // Our outputs have their own stream-start, caps and segment; the input's segment times
    // the utterances.
    case GST_EVENT_SEGMENT: {
      const GstSegment* segment = nullptr;
      gst_event_parse_segment(event, &segment);
      gst_segment_copy_into(segment, &s.input_segment);
      gst_event_unref(event);
      return TRUE;
    }
    case GST_EVENT_STREAM_START:
    case GST_EVENT_CAPS:
    case GST_EVENT_GAP:
      gst_event_unref(event);
      return TRUE;
    case GST_EVENT_EOS:
      gst_event_unref(event);
      return push_eos(self);
    case GST_EVENT_FLUSH_START:
      s.cancel = true;
      break;
    case GST_EVENT_FLUSH_STOP:
      reset(self, false);
      break;
    default:
      break;
  }
  return gst_pad_event_default(pad, parent, event);
}

// Speaks the text property once, then EOS (the sink pad is not linked).
static void speak_text_task(GstPfapTts* self) {
  GST_OBJECT_LOCK(self);
  const std::string text = self->text != nullptr ? self->text : "";
  GST_OBJECT_UNLOCK(self);
  const GstFlowReturn ret = speak(self, text, GST_CLOCK_TIME_NONE);
  gst_pad_pause_task(self->audiopad);
  if (ret == GST_FLOW_FLUSHING) return;
  // GST_FLOW_ERROR has been posted, by us or downstream.
  if (ret == GST_FLOW_NOT_LINKED || (ret < GST_FLOW_EOS && ret != GST_FLOW_ERROR)) {
    GST_ELEMENT_FLOW_ERROR(self, ret);
  }
  push_eos(self);
}

static gboolean gst_pfap_tts_audio_activate_mode(GstPad* pad, GstObject*, GstPadMode mode,
                                                 gboolean active) {
  if (mode == GST_PAD_MODE_PUSH && !active) return gst_pad_stop_task(pad);
  return TRUE;
}

static GstStateChangeReturn gst_pfap_tts_change_state(GstElement* element,
                                                      GstStateChange transition) {
  GstPfapTts* self = GST_PFAP_TTS(element);
  // The streaming thread may be inside a synthesis: stop it before the pads wait for it.
  if (transition == GST_STATE_CHANGE_PAUSED_TO_READY) self->stream->cancel = true;
  if (transition == GST_STATE_CHANGE_READY_TO_PAUSED) {
    reset(self, true);
    GST_OBJECT_LOCK(self);
    self->bad_bookmarks = 0;
    GST_OBJECT_UNLOCK(self);
    unsigned rate = 0;
    std::string error;
    if (!pfap::tts::check_voice(voice_settings(self), rate, error)) {
      GST_ELEMENT_ERROR(self, RESOURCE, NOT_FOUND, ("%s", error.c_str()), (nullptr));
      return GST_STATE_CHANGE_FAILURE;
    }
  }
  const GstStateChangeReturn ret =
      GST_ELEMENT_CLASS(gst_pfap_tts_parent_class)->change_state(element, transition);
  if (ret == GST_STATE_CHANGE_FAILURE) return ret;
  if (transition == GST_STATE_CHANGE_READY_TO_PAUSED) {
    GST_OBJECT_LOCK(self);
    const bool has_text = self->text != nullptr;
    GST_OBJECT_UNLOCK(self);
    if (has_text && !gst_pad_is_linked(self->sinkpad)) {
      gst_pad_start_task(self->audiopad, reinterpret_cast<GstTaskFunction>(speak_text_task), self,
                         nullptr);
    }
  }
  return ret;
}

static void gst_pfap_tts_set_property(GObject* object, guint prop_id, const GValue* value,
                                      GParamSpec* pspec) {
  GstPfapTts* self = GST_PFAP_TTS(object);
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
    case PROP_RATE:
      self->rate = g_value_get_int(value);
      break;
    case PROP_PITCH:
      self->pitch = g_value_get_int(value);
      break;
    case PROP_VOLUME:
      self->volume = g_value_get_int(value);
      break;
    case PROP_SKIP_BAD_BOOKMARKS:
      self->skip_bad_bookmarks = g_value_get_boolean(value);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_tts_get_property(GObject* object, guint prop_id, GValue* value,
                                      GParamSpec* pspec) {
  GstPfapTts* self = GST_PFAP_TTS(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_TEXT:
      g_value_set_string(value, self->text);
      break;
    case PROP_VOICE:
      g_value_set_string(value, self->voice);
      break;
    case PROP_RATE:
      g_value_set_int(value, self->rate);
      break;
    case PROP_PITCH:
      g_value_set_int(value, self->pitch);
      break;
    case PROP_VOLUME:
      g_value_set_int(value, self->volume);
      break;
    case PROP_SKIP_BAD_BOOKMARKS:
      g_value_set_boolean(value, self->skip_bad_bookmarks);
      break;
    case PROP_BAD_BOOKMARKS:
      g_value_set_uint64(value, self->bad_bookmarks);
      break;
    case PROP_STATS:
      g_value_take_boxed(value, gst_structure_new("application/x-pfap-tts-stats", "bad-bookmarks",
                                                  G_TYPE_UINT64, self->bad_bookmarks, nullptr));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_tts_finalize(GObject* object) {
  GstPfapTts* self = GST_PFAP_TTS(object);
  delete self->stream;
  gst_flow_combiner_free(self->flow_combiner);
  g_free(self->text);
  g_free(self->voice);
  G_OBJECT_CLASS(gst_pfap_tts_parent_class)->finalize(object);
}

static void gst_pfap_tts_class_init(GstPfapTtsClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);

  GST_DEBUG_CATEGORY_INIT(pfaptts_debug, "pfaptts", 0, "PFAP text-to-speech (espeak-ng)");

  gobject_class->set_property = gst_pfap_tts_set_property;
  gobject_class->get_property = gst_pfap_tts_get_property;
  gobject_class->finalize = gst_pfap_tts_finalize;

  constexpr auto kPlaying = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                     GST_PARAM_MUTABLE_PLAYING);

  /**
   * GstPfapTts:text:
   *
   * Text with MPEG-4 bookmarks to speak when the sink pad is not linked: spoken once from
   * PAUSED on, then EOS. Ignored when the sink pad is linked.
   */
  g_object_class_install_property(
      gobject_class, PROP_TEXT,
      g_param_spec_string("text", "Text",
                          "Text with <FAP ...> bookmarks to speak, then EOS, when the sink pad "
                          "is not linked",
                          nullptr,
                          static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                   GST_PARAM_MUTABLE_READY)));
  /**
   * GstPfapTts:voice:
   *
   * The espeak-ng voice (`espeak-ng --voices`), e.g. "en", "en-us", "de". English voices map
   * exactly to x-pfap-arpabet; other voices' phonemes go to the nearest symbol, with a
   * warning for each phoneme that has none of its own (docs/tts.md).
   */
  g_object_class_install_property(
      gobject_class, PROP_VOICE,
      g_param_spec_string("voice", "Voice", "espeak-ng voice name", kDefaultVoice, kPlaying));
  g_object_class_install_property(
      gobject_class, PROP_RATE,
      g_param_spec_int("rate", "Rate", "Speaking rate in words per minute", 80, 450, kDefaultRate,
                       kPlaying));
  g_object_class_install_property(
      gobject_class, PROP_PITCH,
      g_param_spec_int("pitch", "Pitch", "Base pitch, 0 (low) to 100 (high), espeak-ng's scale", 0,
                       100, kDefaultPitch, kPlaying));
  g_object_class_install_property(
      gobject_class, PROP_VOLUME,
      g_param_spec_int("volume", "Volume", "Volume in percent, 0 to 200", 0, 200, kDefaultVolume,
                       kPlaying));
  /**
   * GstPfapTts:skip-bad-bookmarks:
   *
   * What a bad bookmark does: FALSE (the default) posts an error naming its character and
   * stops; TRUE posts a warning and leaves the bookmark out of the speech.
   */
  g_object_class_install_property(
      gobject_class, PROP_SKIP_BAD_BOOKMARKS,
      g_param_spec_boolean("skip-bad-bookmarks", "Skip bad bookmarks",
                           "Warn about a bad bookmark and leave it out, instead of an error", FALSE,
                           kPlaying));
  /**
   * GstPfapTts:bad-bookmarks:
   *
   * The bad bookmarks left out (#GstPfapTts:skip-bad-bookmarks) since the element last went
   * from READY to PAUSED: the bad-bookmarks field of #GstPfapTts:stats.
   *
   * Deprecated: read bad-bookmarks in the stats property.
   */
  g_object_class_install_property(
      gobject_class, PROP_BAD_BOOKMARKS,
      g_param_spec_uint64("bad-bookmarks", "Bad bookmarks",
                          "Bad bookmarks left out since READY to PAUSED (deprecated: the stats "
                          "property's bad-bookmarks)",
                          0, G_MAXUINT64, 0,
                          static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS |
                                                   G_PARAM_DEPRECATED)));
  /**
   * GstPfapTts:stats:
   *
   * Counters since the element last went from READY to PAUSED, guint64, as every element of
   * the plugins has them (docs/elements.md, "Counters"):
   *
   * - bad-bookmarks: bad bookmarks left out (#GstPfapTts:skip-bad-bookmarks); their warnings
   *   come at the 1st, 2nd, 4th, 8th, ... only
   */
  g_object_class_install_property(
      gobject_class, PROP_STATS,
      g_param_spec_boxed("stats", "Statistics",
                         "Counters since READY to PAUSED (guint64): bad-bookmarks (left out)",
                         GST_TYPE_STRUCTURE,
                         static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS)));

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &audio_template);
  gst_element_class_add_static_pad_template(element_class, &pfap_template);
  gst_element_class_set_static_metadata(
      element_class, "PFAP text-to-speech", "Codec/Decoder/Audio",
      "Speaks text with MPEG-4 bookmarks through espeak-ng: audio, and its phonemes with their "
      "facial animation parameters (PFAP) as application/x-pfap",
      "gst-pfap developers");

  element_class->change_state = gst_pfap_tts_change_state;
}

static void gst_pfap_tts_init(GstPfapTts* self) {
  self->sinkpad = gst_pad_new_from_static_template(&sink_template, "sink");
  gst_pad_set_chain_function(self->sinkpad, gst_pfap_tts_chain);
  gst_pad_set_event_function(self->sinkpad, gst_pfap_tts_sink_event);
  gst_element_add_pad(GST_ELEMENT(self), self->sinkpad);

  self->flow_combiner = gst_flow_combiner_new();
  self->audiopad = gst_pad_new_from_static_template(&audio_template, "audio");
  self->pfappad = gst_pad_new_from_static_template(&pfap_template, "pfap");
  gst_pad_set_activatemode_function(self->audiopad, gst_pfap_tts_audio_activate_mode);
  for (GstPad* pad : {self->audiopad, self->pfappad}) {
    gst_pad_use_fixed_caps(pad);
    // The utterances' times come from upstream or from the text alone: seeking cannot work.
    gst_pad_set_event_function(pad, pfap_noseek_src_event);
    gst_element_add_pad(GST_ELEMENT(self), pad);
    gst_flow_combiner_add_pad(self->flow_combiner, pad);
  }

  self->text = nullptr;
  self->voice = g_strdup(kDefaultVoice);
  self->rate = kDefaultRate;
  self->pitch = kDefaultPitch;
  self->volume = kDefaultVolume;
  self->skip_bad_bookmarks = FALSE;
  self->bad_bookmarks = 0;
  self->stream = new Stream{};
}
