// SPDX-License-Identifier: LGPL-2.1-or-later
// The example pipelines stay on one line, to be copied.
// clang-format off
/**
 * SECTION:element-pfapfapenc
 * @title: pfapfapenc
 * @see_also: pfapfapparse, pfaptextenc, rtppfapdepay
 *
 * Writes a phoneme / facial animation parameter (PFAP) stream as an MPEG-4 FAP file (.fap,
 * version 2.1, the format Xface, Greta and other MPEG-4 face players read;
 * docs/fap-files.md): the receiver's FAP state, built from the application/x-pfap events as
 * pfapface builds it (phoneme FAPs at their start, recovered entries at their time, a
 * complete state replacing everything), sampled at #GstPfapFapEnc:frame-rate. Frame 0 is
 * stream time 0, as every writer's times count (docs/elements.md), so that pfapfapparse's frames
 * come back as the same frames even when the first events are lost; a stream whose first
 * event comes later starts with neutral frames, the receiver's state until then. Frame k is k / frame rate seconds
 * after frame 0, rounded to the ms; the file ends with the last frame before the end of the
 * last phoneme received, or later, once the last transition is over. Each amplitude is rounded
 * to the nearest whole unit.
 *
 * FAPs 3..68 are written as they are; FAPs 69..74 (expressions) as FAP 2 with the two
 * strongest in each frame, intensities clamped to MPEG-4's 0..63 (a warning says how many
 * were dropped or clamped). Every FAP that is ever non-zero is set in every frame's mask, so
 * that readers that hold a FAP the mask leaves out and readers that take it for 0 agree.
 *
 * The header line holds the number of frames, so the file is written at EOS, in buffers of
 * about 64 KiB; until then up to #GstPfapFapEnc:max-frames frames are kept, 300 bytes each (a
 * warning says when later events are not written), and a GAP event for each event held lets
 * the sinks downstream preroll. A malformed buffer is dropped with a warning and the stream
 * goes on. An event
 * without a PTS starts where the previous one ended; one earlier than the one before it is
 * taken at that one's time, with a warning at the 1st, 2nd, 4th, 8th, ... such event. A
 * flush, or going from READY to PAUSED, starts a new file.
 *
 * ## Example pipelines
 * |[
 * gst-launch-1.0 pfaptts text="Hello <FAP 2 1 40 0 0 500 1> world." name=t t.pfap ! pfapfapenc ! filesink location=hello.fap
 * ]| Writes the animation of a spoken sentence as hello.fap, 25 frames a second.
 * |[
 * gst-launch-1.0 -e udpsrc port=5004 caps="application/x-rtp,media=application,clock-rate=44100,encoding-name=PFAP" ! rtpjitterbuffer ! rtppfapdepay ! pfapfapenc frame-rate=30 ! filesink location=received.fap
 * ]| Records a received PFAP stream as a 30 frames/s FAP file.
 */
// clang-format on
#include "gstpfapfapenc.h"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>

#include "pfap/fap_animation.h"
#include "pfap/fap_file.h"
#include "ratelimit.h"

GST_DEBUG_CATEGORY_STATIC(pfapfapenc_debug);
#define GST_CAT_DEFAULT pfapfapenc_debug

namespace {

enum { PROP_0, PROP_FRAME_RATE, PROP_NAME, PROP_MAX_FRAMES };

constexpr int kDefaultFrameRateN = 25;  // frames a second, as a fraction
constexpr int kDefaultFrameRateD = 1;
constexpr const char* kDefaultName = "gst-pfap";
// The file's text goes out in buffers of about this size.
constexpr size_t kPieceBytes = 64 * 1024;

// What the streaming thread keeps between buffers. GObject runs no C++ constructors, so it
// lives behind a pointer made in init and deleted in finalize.
struct Stream {
  std::optional<pfap::FapRecorder> recorder;  // made at the first event, with the properties
  int64_t end_ns = 0;                         // where the last phoneme ends, from frame 0
  uint64_t over_limit = 0;                    // events after max-frames
};

}  // namespace

struct _GstPfapFapEnc {
  GstPfapBaseEnc parent;
  gint frame_rate_n;  // under the object lock
  gint frame_rate_d;  // under the object lock
  gchar* name;        // under the object lock
  guint max_frames;   // under the object lock
  Stream* stream;
};

static GstStaticPadTemplate sink_template = GST_STATIC_PAD_TEMPLATE(
    "sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS("text/plain"));

G_DEFINE_TYPE(GstPfapFapEnc, gst_pfap_fap_enc, GST_TYPE_PFAP_BASE_ENC)
GST_ELEMENT_REGISTER_DEFINE(pfapfapenc, "pfapfapenc", GST_RANK_NONE, GST_TYPE_PFAP_FAP_ENC)

// A new file (FLUSH_STOP, READY to PAUSED).
static void gst_pfap_fap_enc_reset(GstPfapBaseEnc* enc) {
  *GST_PFAP_FAP_ENC(enc)->stream = Stream{};
}

static GstFlowReturn gst_pfap_fap_enc_handle_event(GstPfapBaseEnc* enc, GstBuffer*,
                                                   const pfap::MarkupEvent& event,
                                                   int64_t time_ns) {
  GstPfapFapEnc* self = GST_PFAP_FAP_ENC(enc);
  Stream& s = *self->stream;
  if (!s.recorder) {
    GST_OBJECT_LOCK(self);
    s.recorder.emplace(static_cast<double>(self->frame_rate_n) / self->frame_rate_d,
                       self->max_frames);
    GST_OBJECT_UNLOCK(self);
  }
  // The recorder adds the frames of transitions still running at the end.
  const int64_t end =
      time_ns + (event.kind == PFAP_EVENT_PHONEME ? event.phoneme.duration_ms : 0) * pfap::kNsPerMs;
  if (!s.recorder->apply(event, time_ns)) {
    if (pfap_warn_at(++s.over_limit)) {
      GST_ELEMENT_WARNING(
          self, STREAM, ENCODE,
          ("The FAP file is full (%u frames); later events are not written.", s.recorder->frames()),
          ("%" G_GUINT64_FORMAT " events dropped so far; see max-frames", s.over_limit));
    }
    return GST_FLOW_OK;
  }
  s.end_ns = std::max(s.end_ns, end);
  return GST_FLOW_OK;
}

// Writes the file at EOS: its header needs the number of frames.
// An error is posted by the push; EOS goes on for the sink to finish what it has.
static void gst_pfap_fap_enc_finish(GstPfapBaseEnc* enc) {
  GstPfapFapEnc* self = GST_PFAP_FAP_ENC(enc);
  Stream& s = *self->stream;
  GstPad* srcpad = gst_pfap_base_enc_srcpad(enc);
  if (!gst_pad_has_current_caps(srcpad)) {
    GstCaps* caps = gst_static_pad_template_get_caps(&src_template);
    gst_pad_set_caps(srcpad, caps);
    gst_caps_unref(caps);
  }
  if (!s.recorder) {
    GST_ELEMENT_WARNING(self, STREAM, ENCODE, ("No PFAP events: no FAP file written."),
                        ("a FAP file has at least one frame"));
    return;
  }
  if (!s.recorder->finish(s.end_ns) && pfap_warn_at(++s.over_limit)) {
    GST_ELEMENT_WARNING(
        self, STREAM, ENCODE,
        ("The FAP file is full (%u frames); its end is not written.", s.recorder->frames()),
        ("see max-frames"));
  }
  GST_OBJECT_LOCK(self);
  const std::string name = self->name != nullptr ? self->name : kDefaultName;
  GST_OBJECT_UNLOCK(self);
  // The text goes out in pieces as it is written, so that it is never whole in memory: only
  // the frames' amplitudes are (300 bytes a frame).
  const pfap::FapRecorder& recorder = *s.recorder;
  const pfap::FapRecorder::Mask mask = recorder.mask();
  pfap::NotWritten not_written;
  std::string text;
  pfap::format_fap_header(recorder.header(name), text);
  size_t bytes = 0;
  GstFlowReturn ret = GST_FLOW_OK;
  for (uint32_t k = 0; k < recorder.frames() && ret == GST_FLOW_OK; ++k) {
    pfap::format_fap_frame(recorder.frame(k, mask, not_written), text);
    if (text.size() >= kPieceBytes || k + 1 == recorder.frames()) {
      bytes += text.size();
      ret = gst_pfap_base_enc_push(enc, gst_buffer_new_memdup(text.data(), text.size()));
      text.clear();
    }
  }
  GST_DEBUG_OBJECT(self, "%u frames, %zu bytes", recorder.frames(), bytes);
  if (not_written.expressions_dropped != 0 || not_written.intensities_clamped != 0) {
    GST_ELEMENT_WARNING(
        self, STREAM, ENCODE,
        ("The FAP file holds two expressions a frame with intensities 0..63: %" G_GUINT64_FORMAT
         " expression values dropped, %" G_GUINT64_FORMAT " clamped.",
         not_written.expressions_dropped, not_written.intensities_clamped),
        (nullptr));
  }
}

// The file is bytes from its start.
static GstEvent* gst_pfap_fap_enc_output_segment(GstPfapBaseEnc*, GstEvent* event) {
  gst_event_unref(event);
  GstSegment bytes;
  gst_segment_init(&bytes, GST_FORMAT_BYTES);
  return gst_event_new_segment(&bytes);
}

static void gst_pfap_fap_enc_set_property(GObject* object, guint prop_id, const GValue* value,
                                          GParamSpec* pspec) {
  GstPfapFapEnc* self = GST_PFAP_FAP_ENC(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_FRAME_RATE:
      self->frame_rate_n = gst_value_get_fraction_numerator(value);
      self->frame_rate_d = gst_value_get_fraction_denominator(value);
      break;
    case PROP_NAME:
      g_free(self->name);
      self->name = g_value_dup_string(value);
      break;
    case PROP_MAX_FRAMES:
      self->max_frames = g_value_get_uint(value);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_fap_enc_get_property(GObject* object, guint prop_id, GValue* value,
                                          GParamSpec* pspec) {
  GstPfapFapEnc* self = GST_PFAP_FAP_ENC(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_FRAME_RATE:
      gst_value_set_fraction(value, self->frame_rate_n, self->frame_rate_d);
      break;
    case PROP_NAME:
      g_value_set_string(value, self->name);
      break;
    case PROP_MAX_FRAMES:
      g_value_set_uint(value, self->max_frames);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_fap_enc_finalize(GObject* object) {
  delete GST_PFAP_FAP_ENC(object)->stream;
  g_free(GST_PFAP_FAP_ENC(object)->name);
  G_OBJECT_CLASS(gst_pfap_fap_enc_parent_class)->finalize(object);
}

static void gst_pfap_fap_enc_class_init(GstPfapFapEncClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstPfapBaseEncClass* enc_class = GST_PFAP_BASE_ENC_CLASS(klass);

  GST_DEBUG_CATEGORY_INIT(pfapfapenc_debug, "pfapfapenc", 0, "MPEG-4 FAP file writer");

  gobject_class->set_property = gst_pfap_fap_enc_set_property;
  gobject_class->get_property = gst_pfap_fap_enc_get_property;
  gobject_class->finalize = gst_pfap_fap_enc_finalize;

  /**
   * GstPfapFapEnc:frame-rate:
   *
   * Frames a second of the file: the FAP state is sampled at this rate. A fraction, as
   * GStreamer's framerates are (`frame-rate=30000/1001`; `frame-rate=25` is 25/1), from 1 to
   * 1000 (the draft's times are whole ms); the file's header holds it as a decimal number.
   */
  g_object_class_install_property(
      gobject_class, PROP_FRAME_RATE,
      gst_param_spec_fraction("frame-rate", "Frame rate", "Frames a second of the FAP file",
                              static_cast<int>(pfap::kMinFapFileFrameRate), 1,
                              static_cast<int>(pfap::kMaxFapFileFrameRate), 1, kDefaultFrameRateN,
                              kDefaultFrameRateD,
                              static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                       GST_PARAM_MUTABLE_READY)));

  /**
   * GstPfapFapEnc:name-in-file:
   *
   * The name in the file's header line (white space is written as '_': readers take the
   * name as one word).
   */
  g_object_class_install_property(
      gobject_class, PROP_NAME,
      g_param_spec_string("name-in-file", "Name in file", "The name in the FAP file's header",
                          kDefaultName,
                          static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                   GST_PARAM_MUTABLE_READY)));

  /**
   * GstPfapFapEnc:max-frames:
   *
   * The most frames kept for the file (it is written at EOS): at most pfapfapparse's limit,
   * 360000 (4 hours at 25 frames a second).
   */
  g_object_class_install_property(
      gobject_class, PROP_MAX_FRAMES,
      g_param_spec_uint("max-frames", "Maximum frames", "The most frames the file holds", 1,
                        pfap::kMaxFapFileFrames, pfap::kMaxFapFileFrames,
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_READY)));

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_set_static_metadata(
      element_class, "MPEG-4 FAP file encoder", "Codec/Encoder/Text",
      "Writes the facial animation of a PFAP stream as an MPEG-4 FAP (.fap) file",
      "gst-pfap developers");

  enc_class->handle_event = gst_pfap_fap_enc_handle_event;
  enc_class->output_segment = gst_pfap_fap_enc_output_segment;
  enc_class->finish = gst_pfap_fap_enc_finish;
  enc_class->reset = gst_pfap_fap_enc_reset;
}

static void gst_pfap_fap_enc_init(GstPfapFapEnc* self) {
  self->stream = new Stream{};
  self->frame_rate_n = kDefaultFrameRateN;
  self->frame_rate_d = kDefaultFrameRateD;
  self->name = g_strdup(kDefaultName);
  self->max_frames = pfap::kMaxFapFileFrames;
}
