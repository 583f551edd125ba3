// SPDX-License-Identifier: LGPL-2.1-or-later
// The example pipelines stay on one line, to be copied.
// clang-format off
/**
 * SECTION:element-pfapmarksenc
 * @title: pfapmarksenc
 * @see_also: pfapmarksparse, pfaptextenc
 *
 * Writes a phoneme / facial animation parameter (PFAP) stream in the vocabularies avatars
 * and TTS services speak (docs/visemes.md), chosen by #GstPfapMarksEnc:format:
 *
 * - `polly`: Amazon Polly speech marks, JSON lines of sentence, word and viseme marks;
 * - `rhubarb-tsv`, `rhubarb-json`: Rhubarb Lip Sync's mouth shapes A..H and X;
 * - `talkinghead`: one JSON object per utterance with the `visemes`, `vtimes`, `vdurations`,
 *   `words`, `wtimes`, `wdurations` (ms) that met4citizen/TalkingHead's speakAudio and
 *   streamAudio take;
 * - `azure`: Azure Speech viseme events, JSON lines of `audioOffset` (100 ns ticks) and
 *   `visemeId`;
 * - `arkit-json`, `arkit-csv`: ARKit's 52 blendshape weights and the head's pitch, yaw and roll,
 *   one line per frame at #GstPfapMarksEnc:frame-rate, from the FAP state and the viseme
 *   sounding.
 *
 * The `alphabet` field of the input caps names the phoneme table (x-pfap-arpabet, or one of
 * the viseme alphabets pfapmarksparse makes); a phoneme with no known viseme is written as a
 * half-open mouth, with a warning. Times are the events' stream times, as pfaptextenc's.
 * Marks come out per utterance (at each end of text), Rhubarb JSON as one document at EOS,
 * blendshape frames as time passes. Once nothing moves, frames go on for 1 s of rest at most;
 * the frames after a longer rest keep their times, with a warning (the 1st, 2nd, 4th, ...), so
 * that a gap costs no more frames. A malformed buffer is dropped with a warning.
 *
 * ## Example pipelines
 * |[
 * gst-launch-1.0 filesrc location=docs/examples/hello.pfap ! pfaptextparse alphabet=x-pfap-arpabet ! pfapmarksenc format=polly ! filesink location=hello.marks
 * ]| Writes hello.pfap as Polly speech marks.
 * |[
 * gst-launch-1.0 filesrc location=docs/examples/hello.pfap ! pfaptextparse alphabet=x-pfap-arpabet ! pfapmarksenc format=arkit-csv frame-rate=60 ! filesink location=hello.csv
 * ]| Writes ARKit blendshape weights at 60 frames per second.
 */
// clang-format on
#include "gstpfapmarksenc.h"

#include <cstdint>
#include <string>

#include "pfap/model.h"
#include "pfap/speech_marks.h"
#include "ratelimit.h"

GST_DEBUG_CATEGORY_STATIC(pfapmarksenc_debug);
#define GST_CAT_DEFAULT pfapmarksenc_debug

namespace {

enum { PROP_0, PROP_FORMAT, PROP_FRAME_RATE };

constexpr pfap::MarksFormat kDefaultFormat = pfap::MarksFormat::kPolly;
constexpr int kDefaultFrameRateN = 30;  // frames a second, as a fraction
constexpr int kDefaultFrameRateD = 1;

// What the streaming thread keeps between buffers, made at READY to PAUSED from the
// properties. GObject runs no C++ constructors, so it lives behind a pointer.
struct Stream {
  Stream(pfap::MarksFormat format, int rate_n, int rate_d) : writer(format, rate_n, rate_d) {}

  pfap::MarksWriter writer;
  uint64_t unknown_warned = 0;  // unknown phonemes already counted in a warning
  uint64_t unknown_warnings = 0;
  uint64_t cut_rests = 0;  // the writer's count when last looked at
  GstFlowReturn flow = GST_FLOW_OK;
};

}  // namespace

struct _GstPfapMarksEnc {
  GstPfapBaseEnc parent;
  pfap::MarksFormat format;  // under the object lock
  int frame_rate_n;          // under the object lock
  int frame_rate_d;          // under the object lock
  Stream* stream;
};

static GstStaticPadTemplate sink_template = GST_STATIC_PAD_TEMPLATE(
    "sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

static GstStaticPadTemplate src_template = GST_STATIC_PAD_TEMPLATE(
    "src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS("text/x-raw, format = (string) utf8"));

G_DEFINE_TYPE(GstPfapMarksEnc, gst_pfap_marks_enc, GST_TYPE_PFAP_BASE_ENC)
GST_ELEMENT_REGISTER_DEFINE(pfapmarksenc, "pfapmarksenc", GST_RANK_NONE, GST_TYPE_PFAP_MARKS_ENC)

#define GST_TYPE_PFAP_MARKS_FORMAT (gst_pfap_marks_format_get_type())
static GType gst_pfap_marks_format_get_type() {
  static GType type = 0;
  static const GEnumValue values[] = {
      {int(pfap::MarksFormat::kPolly), "Amazon Polly speech marks (JSON lines)", "polly"},
      {int(pfap::MarksFormat::kRhubarbTsv), "Rhubarb Lip Sync TSV", "rhubarb-tsv"},
      {int(pfap::MarksFormat::kRhubarbJson), "Rhubarb Lip Sync JSON", "rhubarb-json"},
      {int(pfap::MarksFormat::kTalkingHead), "TalkingHead visemes and words (JSON lines)",
       "talkinghead"},
      {int(pfap::MarksFormat::kAzure), "Azure viseme events (JSON lines, 100 ns ticks)", "azure"},
      {int(pfap::MarksFormat::kArkitJson), "ARKit blendshapes per frame (JSON lines)",
       "arkit-json"},
      {int(pfap::MarksFormat::kArkitCsv), "ARKit blendshapes per frame (CSV)", "arkit-csv"},
      {0, nullptr, nullptr},
  };
  if (g_once_init_enter(&type)) {
    g_once_init_leave(&type, g_enum_register_static("GstPfapMarksFormat", values));
  }
  return type;
}

// A new stream from the properties (READY to PAUSED, FLUSH_STOP).
static void gst_pfap_marks_enc_reset(GstPfapBaseEnc* enc) {
  GstPfapMarksEnc* self = GST_PFAP_MARKS_ENC(enc);
  GST_OBJECT_LOCK(self);
  const pfap::MarksFormat format = self->format;
  const int rate_n = self->frame_rate_n;
  const int rate_d = self->frame_rate_d;
  GST_OBJECT_UNLOCK(self);
  const pfap::PhonemeAlphabet* alphabet = nullptr;
  if (self->stream != nullptr) {
    // The alphabet comes with the caps, which stay across a flush.
    GstCaps* caps = gst_pad_get_current_caps(gst_pfap_base_enc_sinkpad(enc));
    if (caps != nullptr) {
      const gchar* name = gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet");
      alphabet = name != nullptr ? pfap::find_alphabet(name) : nullptr;
      gst_caps_unref(caps);
    }
  }
  delete self->stream;
  self->stream = new Stream(format, rate_n, rate_d);
  self->stream->writer.set_alphabet(alphabet);
}

static pfap::MarksWriter::Sink make_sink(GstPfapMarksEnc* self) {
  return [self](std::string_view text) {
    if (text.empty()) return true;
    GstBuffer* out = gst_buffer_new_memdup(text.data(), text.size());
    self->stream->flow = gst_pfap_base_enc_push(GST_PFAP_BASE_ENC(self), out);
    return self->stream->flow == GST_FLOW_OK;
  };
}

static GstFlowReturn gst_pfap_marks_enc_handle_event(GstPfapBaseEnc* enc, GstBuffer*,
                                                     const pfap::MarkupEvent& event,
                                                     int64_t time_ns) {
  GstPfapMarksEnc* self = GST_PFAP_MARKS_ENC(enc);
  Stream& s = *self->stream;
  s.flow = GST_FLOW_OK;
  if (!s.writer.add(event, time_ns, make_sink(self))) {
    if (s.writer.overflow()) {
      GST_ELEMENT_ERROR(self, STREAM, FAILED,
                        ("More than %zu phonemes for one Rhubarb JSON document.",
                         pfap::MarksWriter::kMaxDocumentPhonemes),
                        ("use format=rhubarb-tsv for longer streams"));
      return GST_FLOW_ERROR;
    }
    return s.flow;
  }
  // The writer cuts at most one rest per event.
  if (s.writer.cut_rests() != s.cut_rests && pfap_warn_at(s.cut_rests = s.writer.cut_rests())) {
    GST_ELEMENT_WARNING(self, STREAM, ENCODE,
                        ("A rest longer than %" G_GINT64_FORMAT " ms: its frames after that are "
                         "left out, and the next frame's time jumps.",
                         pfap::MarksWriter::kMaxRestNs / pfap::kNsPerMs),
                        ("%" G_GUINT64_FORMAT " rests cut so far (warned at the 1st, 2nd, 4th, "
                         "...); this bounds the frames an event can make",
                         s.cut_rests));
  }
  const uint64_t unknown = s.writer.unknown_phonemes();
  if (unknown > s.unknown_warned && pfap_warn_at(++s.unknown_warnings)) {
    s.unknown_warned = unknown;
    GST_ELEMENT_WARNING(self, STREAM, FORMAT,
                        ("%" G_GUINT64_FORMAT " phonemes have no known viseme; written as a "
                         "half-open mouth.",
                         unknown),
                        ("set the alphabet field of the input caps to a known alphabet, e.g. "
                         "pfaptextparse alphabet=x-pfap-arpabet"));
  }
  return s.flow;
}

static void gst_pfap_marks_enc_set_caps(GstPfapBaseEnc* enc, GstCaps* caps) {
  GstPfapMarksEnc* self = GST_PFAP_MARKS_ENC(enc);
  const gchar* name = gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet");
  const pfap::PhonemeAlphabet* alphabet = name ? pfap::find_alphabet(name) : nullptr;
  GST_INFO_OBJECT(self, "alphabet %s%s", name ? name : "(none)",
                  name && !alphabet ? " (unknown)" : "");
  self->stream->writer.set_alphabet(alphabet);
}

// What is held (the last utterance, the Rhubarb document, the last frames) goes before EOS.
static void gst_pfap_marks_enc_finish(GstPfapBaseEnc* enc) {
  GstPfapMarksEnc* self = GST_PFAP_MARKS_ENC(enc);
  self->stream->flow = GST_FLOW_OK;
  self->stream->writer.finish(make_sink(self));
}

static void gst_pfap_marks_enc_set_property(GObject* object, guint prop_id, const GValue* value,
                                            GParamSpec* pspec) {
  GstPfapMarksEnc* self = GST_PFAP_MARKS_ENC(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_FORMAT:
      self->format = static_cast<pfap::MarksFormat>(g_value_get_enum(value));
      break;
    case PROP_FRAME_RATE:
      self->frame_rate_n = gst_value_get_fraction_numerator(value);
      self->frame_rate_d = gst_value_get_fraction_denominator(value);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_marks_enc_get_property(GObject* object, guint prop_id, GValue* value,
                                            GParamSpec* pspec) {
  GstPfapMarksEnc* self = GST_PFAP_MARKS_ENC(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_FORMAT:
      g_value_set_enum(value, static_cast<int>(self->format));
      break;
    case PROP_FRAME_RATE:
      gst_value_set_fraction(value, self->frame_rate_n, self->frame_rate_d);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_marks_enc_finalize(GObject* object) {
  delete GST_PFAP_MARKS_ENC(object)->stream;
  G_OBJECT_CLASS(gst_pfap_marks_enc_parent_class)->finalize(object);
}

static void gst_pfap_marks_enc_class_init(GstPfapMarksEncClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstPfapBaseEncClass* enc_class = GST_PFAP_BASE_ENC_CLASS(klass);

  GST_DEBUG_CATEGORY_INIT(pfapmarksenc_debug, "pfapmarksenc", 0, "PFAP speech-mark writer");

  gobject_class->set_property = gst_pfap_marks_enc_set_property;
  gobject_class->get_property = gst_pfap_marks_enc_get_property;
  gobject_class->finalize = gst_pfap_marks_enc_finalize;

  const auto flags = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                              GST_PARAM_MUTABLE_READY);
  /**
   * GstPfapMarksEnc:format:
   *
   * What to write (docs/visemes.md has each format). Read when going to PAUSED.
   */
  g_object_class_install_property(
      gobject_class, PROP_FORMAT,
      g_param_spec_enum("format", "Format", "The speech-mark or blendshape format to write",
                        GST_TYPE_PFAP_MARKS_FORMAT, static_cast<int>(kDefaultFormat), flags));
  /**
   * GstPfapMarksEnc:frame-rate:
   *
   * Frames per second of the arkit-json and arkit-csv formats, a fraction as GStreamer's
   * framerates are (`frame-rate=30000/1001`; `frame-rate=30` is 30/1); the other formats
   * ignore it.
   */
  g_object_class_install_property(
      gobject_class, PROP_FRAME_RATE,
      gst_param_spec_fraction("frame-rate", "Frame rate",
                              "Blendshape frames per second (arkit-json, arkit-csv)", 1, 1, 240, 1,
                              kDefaultFrameRateN, kDefaultFrameRateD, flags));

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_set_static_metadata(
      element_class, "PFAP speech-mark encoder", "Codec/Encoder/Text",
      "Writes phoneme and facial animation parameter (PFAP) streams as Polly speech marks, "
      "Rhubarb mouth cues, TalkingHead timing, Azure viseme events or ARKit blendshapes",
      "gst-pfap developers");

  enc_class->handle_event = gst_pfap_marks_enc_handle_event;
  enc_class->set_caps = gst_pfap_marks_enc_set_caps;
  enc_class->finish = gst_pfap_marks_enc_finish;
  enc_class->reset = gst_pfap_marks_enc_reset;
  gst_type_mark_as_plugin_api(GST_TYPE_PFAP_MARKS_FORMAT, static_cast<GstPluginAPIFlags>(0));
}

static void gst_pfap_marks_enc_init(GstPfapMarksEnc* self) {
  self->format = kDefaultFormat;
  self->frame_rate_n = kDefaultFrameRateN;
  self->frame_rate_d = kDefaultFrameRateD;
  self->stream = nullptr;
  gst_pfap_marks_enc_reset(GST_PFAP_BASE_ENC(self));
}
