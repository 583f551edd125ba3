// SPDX-License-Identifier: LGPL-2.1-or-later
// The example pipelines stay on one line, to be copied.
// clang-format off
/**
 * SECTION:element-pfapface
 * @title: pfapface
 * @see_also: pfaptextparse, rtppfapdepay
 *
 * Renders a phoneme / facial animation parameter (PFAP) stream as a talking head: an
 * application/x-pfap stream in, raw video out, one frame per frame time of the negotiated
 * rate from the start of the segment, each drawn with cairo from the face's state at its own
 * time (docs/face.md).
 *
 * - FAP bookmarks move the face through pfap::FapState: each amplitude follows its curve
 *   (linear, triangle, spline) and starting rule. Lips (FAPs 3..18, 51..60), eyelids
 *   (19..22), eyeballs (23..26), eyebrows (31..38), cheeks (39..42), head pitch, yaw and roll
 *   (48..50) and the six expressions (69..74) are drawn, amplitudes scaled by the drawn
 *   face's own FAP units.
 * - Phonemes shape the mouth: the `alphabet` field of the input caps names the symbol table
 *   (pfap/phoneme_table.h, e.g. x-pfap-arpabet), whose MPEG-4 visemes the mouth eases
 *   between; it closes in pauses. Without a known alphabet, or for a symbol the alphabet
 *   lacks, the mouth opens and closes once over each phoneme, with one warning per stream.
 * - A recovered state applies its entries at its PTS with their remaining transition times;
 *   a complete state sets every FAP (those not listed to 0). A flush or a new stream brings
 *   back the neutral face.
 *
 * The element is a live renderer: between events it keeps drawing the resting face, which
 * holds the FAP state. It is a #GstAggregator: with a live source it produces each frame on
 * time (at its running time plus the latency) whether or not markup came; otherwise it draws
 * a frame as soon as a later event, a GAP event or EOS shows that nothing before that frame
 * can still come, so a file renders as fast as the machine draws. A face at rest (no phoneme,
 * no transition) for 10 s draws no more frames until its next markup: a GAP event covers that
 * time instead, so a far-off event costs one event, not a frame per frame period. The stream
 * ends with the frame in which its last phoneme, transition or gap ends. A malformed buffer is
 * dropped with a warning and the frames go on.
 *
 * ## Example pipelines
 * |[
 * gst-launch-1.0 filesrc location=docs/examples/hello.pfap ! pfaptextparse alphabet=x-pfap-arpabet ! pfapface ! videoconvert ! autovideosink
 * ]| Shows a talking head saying "Hello there. How are you?" (drawn as fast as it can go,
 * the sink paces it).
 * |[
 * gst-launch-1.0 -e filesrc location=docs/examples/face.pfap ! pfaptextparse alphabet=x-pfap-arpabet ! pfapface style=line debug-overlay=true ! video/x-raw,width=320,height=240 ! videoconvert ! vp8enc deadline=1 ! webmmux ! filesink location=face.webm
 * ]| Renders the session to a 320x240 video file with the phoneme and active FAPs written on
 * each frame.
 */
// clang-format on
#include "gstpfapface.h"

#include <gst/video/video.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include "face/animator.h"
#include "face/renderer.h"
#include "markupbuffer.h"
#include "pfap/phoneme_table.h"
#include "pfap/timeline.h"
#include "warning.h"

GST_DEBUG_CATEGORY_STATIC(pfapface_debug);
#define GST_CAT_DEFAULT pfapface_debug

namespace {

constexpr int kDefaultWidth = 640;
constexpr int kDefaultHeight = 480;
constexpr int kDefaultFpsN = 25;
constexpr int kDefaultFpsD = 1;
constexpr pfap::face::Style kDefaultStyle = pfap::face::Style::kCartoon;
constexpr gboolean kDefaultDebugOverlay = FALSE;
// A face at rest for this long draws no more frames until its next markup: one GAP event
// covers the rest (docs/face.md, "Long silences"), so that a far-off event costs one event,
// not a frame per frame period.
constexpr int64_t kMaxRestNs = 10 * GST_SECOND;

// What the streaming thread keeps between frames. GObject runs no C++ constructors, so it
// lives behind a pointer made in init and deleted in finalize.
struct Stream {
  pfap::face::Animator animator;
  GstVideoInfo info{};
  bool negotiated = false;
  uint64_t frame = 0;            // the next frame's number since the output segment's start
  int64_t covered_until = -1;    // running time up to which a GAP said no markup comes
  bool warned_mouth = false;     // the warning for phonemes without a mouth shape was posted
  bool untimed_input = false;    // a segment not in TIME came: an error was posted
  pfap::MarkupEvent event;       // reused, so that steady streaming does not allocate
  pfap::EventTimeline timeline;  // the input events' running times
  uint64_t malformed = 0;        // input buffers dropped, for the warning's rate limit
};

}  // namespace

struct _GstPfapFace {
  GstAggregator parent;
  GstAggregatorPad* sinkpad;
  Stream* stream;
  // Properties, under the object lock.
  int width;
  int height;
  pfap::face::Style style;
  gboolean debug_overlay;
};

enum { PROP_0, PROP_WIDTH, PROP_HEIGHT, PROP_STYLE, PROP_DEBUG_OVERLAY };

GType gst_pfap_face_style_get_type() {
  static gsize type = 0;
  static const GEnumValue values[] = {
      {static_cast<gint>(pfap::face::Style::kCartoon), "Flat colours: skin, hair, lips", "cartoon"},
      {static_cast<gint>(pfap::face::Style::kLine), "Black lines on white, like a sketch", "line"},
      {0, nullptr, nullptr},
  };
  if (g_once_init_enter(&type)) {
    g_once_init_leave(&type, g_enum_register_static("GstPfapFaceStyle", values));
  }
  return type;
}

// cairo's 32-bit formats are native-endian words: BGRx and BGRA in memory on little-endian
// machines.
#if G_BYTE_ORDER == G_LITTLE_ENDIAN
#define PFAP_FACE_FORMATS "{ BGRx, BGRA }"
#else
#define PFAP_FACE_FORMATS "{ xRGB, ARGB }"
#endif

static GstStaticPadTemplate sink_template = GST_STATIC_PAD_TEMPLATE(
    "sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

static GstStaticPadTemplate src_template = GST_STATIC_PAD_TEMPLATE(
    "src", GST_PAD_SRC, GST_PAD_ALWAYS,
    GST_STATIC_CAPS("video/x-raw, format = (string) " PFAP_FACE_FORMATS
                    ", width = (int) [ 16, 8192 ], height = (int) [ 16, 8192 ], "
                    "framerate = (fraction) [ 1/1000, 1000/1 ], "
                    "pixel-aspect-ratio = (fraction) 1/1"));

G_DEFINE_TYPE(GstPfapFace, gst_pfap_face, GST_TYPE_AGGREGATOR)
// Codec/Decoder/Video with a rank: decodebin (playbin, uridecodebin) plugs it to show an
// application/x-pfap stream, the only caps it takes. SECONDARY leaves PRIMARY to a renderer
// an application prefers (docs/elements.md, "Playing a stream").
GST_ELEMENT_REGISTER_DEFINE(pfapface, "pfapface", GST_RANK_SECONDARY, GST_TYPE_PFAP_FACE)

// The neutral face and the first frame again (start, flush, new stream).
static void reset(GstPfapFace* self) {
  Stream& s = *self->stream;
  s.animator.reset();
  s.timeline.reset();
  s.frame = 0;
  s.covered_until = -1;
  s.warned_mouth = false;
  s.untimed_input = false;
  GstAggregatorPad* srcpad = GST_AGGREGATOR_PAD(GST_AGGREGATOR_SRC_PAD(self));
  GST_OBJECT_LOCK(self);
  srcpad->segment.position = GST_CLOCK_TIME_NONE;
  GST_OBJECT_UNLOCK(self);
}

// The running time of `time` in the sink pad's segment; -1 when it has none.
static int64_t input_running_time(GstPfapFace* self, GstClockTime time) {
  GST_OBJECT_LOCK(self->sinkpad);
  const GstClockTime running =
      gst_segment_to_running_time(&self->sinkpad->segment, GST_FORMAT_TIME, time);
  GST_OBJECT_UNLOCK(self->sinkpad);
  return GST_CLOCK_TIME_IS_VALID(running) ? static_cast<int64_t>(running) : -1;
}

// Applies the markup event in `buffer` (running time `at`, or the last event's when it has
// none).
static void apply_event(GstPfapFace* self, GstBuffer* buffer, int64_t at) {
  Stream& s = *self->stream;
  pfap::MarkupEvent& event = s.event;
  if (!pfap_buffer_read(buffer, event)) {
    PFAP_WARN_MALFORMED_EVENT(self, buffer, ++s.malformed);
    return;
  }
  if (at < 0) at = s.animator.last_ns();
  if (s.timeline.earlier(at)) {
    PFAP_WARN_EARLIER_EVENT(self, "applied", at, s.timeline.previous_ns(),
                            s.timeline.earlier_count());
    at = s.timeline.previous_ns();
  }
  s.timeline.add(at, 0);
  if (!s.animator.apply(event, at) && !s.warned_mouth) {
    s.warned_mouth = true;
    GST_ELEMENT_WARNING(self, STREAM, FORMAT,
                        ("Phonemes without a known mouth shape: the mouth only opens and "
                         "closes with them."),
                        ("symbol %u; set the alphabet field of the input caps to one "
                         "pfap/phoneme_table.h knows (e.g. %s)",
                         event.phoneme.symbol, pfap::kArpabetAlphabet.data()));
  }
}

// The output time of frame `n` since the segment start.
static GstClockTime frame_time(const GstPfapFace* self, const GstSegment& segment, uint64_t n) {
  const GstVideoInfo& info = self->stream->info;
  return segment.start + gst_util_uint64_scale(n, GST_SECOND * static_cast<guint64>(info.fps_d),
                                               static_cast<guint64>(info.fps_n));
}

// Draws frame number s.frame at output time `pts` and pushes it.
static GstFlowReturn push_frame(GstPfapFace* self, GstClockTime pts, GstClockTime next,
                                int64_t at) {
  Stream& s = *self->stream;
  GST_OBJECT_LOCK(self);
  const pfap::face::Style style = self->style;
  const bool overlay = self->debug_overlay;
  GST_OBJECT_UNLOCK(self);

  GstBuffer* out = gst_buffer_new_allocate(nullptr, GST_VIDEO_INFO_SIZE(&s.info), nullptr);
  GstMapInfo map;
  gst_buffer_map(out, &map, GST_MAP_WRITE);
  const pfap::face::Frame frame{
      map.data, GST_VIDEO_INFO_WIDTH(&s.info), GST_VIDEO_INFO_HEIGHT(&s.info),
      GST_VIDEO_INFO_PLANE_STRIDE(&s.info, 0), GST_VIDEO_INFO_HAS_ALPHA(&s.info) != FALSE};
  pfap::face::render(s.animator.pose(at), style, overlay ? s.animator.describe(at) : std::string(),
                     frame);
  gst_buffer_unmap(out, &map);
  GST_BUFFER_PTS(out) = pts;
  GST_BUFFER_DURATION(out) = next - pts;
  if (s.frame == 0) GST_BUFFER_FLAG_SET(out, GST_BUFFER_FLAG_DISCONT);
  GST_LOG_OBJECT(self, "frame %" G_GUINT64_FORMAT " at %" GST_TIME_FORMAT, s.frame,
                 GST_TIME_ARGS(pts));

  ++s.frame;
  GST_OBJECT_LOCK(self);
  GST_AGGREGATOR_PAD(GST_AGGREGATOR_SRC_PAD(self))->segment.position = next;
  GST_OBJECT_UNLOCK(self);
  GstAggregator* agg = GST_AGGREGATOR(self);
  gst_aggregator_selected_samples(agg, pts, GST_CLOCK_TIME_NONE, next - pts, nullptr);
  return gst_aggregator_finish_buffer(agg, out);
}

// Whether frames from `at` on would all show the face at rest for more than kMaxRestNs before
// `until` (the running time of the next markup, or the end of a GAP): then the frames up to
// `until` are left out and one GAP event covers them. Returns the number of the frame that
// holds `until`, or 0 when frames are to be drawn.
static uint64_t rest_until_frame(GstPfapFace* self, const GstSegment& segment, int64_t at,
                                 int64_t until) {
  Stream& s = *self->stream;
  const int64_t rest_from = std::max(s.animator.end_ns(), s.animator.last_ns());
  // Both are running times, 0 or more: the difference cannot overflow, a sum near the end of
  // time (292 years) could.
  if (s.frame == 0 || at - rest_from < kMaxRestNs || until <= at) return 0;
  const GstClockTime position = gst_segment_position_from_running_time(
      &segment, GST_FORMAT_TIME, static_cast<GstClockTime>(until));
  if (!GST_CLOCK_TIME_IS_VALID(position) || position < segment.start) return 0;
  const GstVideoInfo& info = s.info;
  const uint64_t frame =
      gst_util_uint64_scale(position - segment.start, static_cast<guint64>(info.fps_n),
                            GST_SECOND * static_cast<guint64>(info.fps_d));
  return frame > s.frame ? frame : 0;
}

// Leaves out the frames from s.frame to `frame` (excluded) with a GAP event over their time.
static void skip_to_frame(GstPfapFace* self, const GstSegment& segment, uint64_t frame) {
  Stream& s = *self->stream;
  const GstClockTime from = frame_time(self, segment, s.frame);
  const GstClockTime to = frame_time(self, segment, frame);
  GST_DEBUG_OBJECT(self, "face at rest: a gap from %" GST_TIME_FORMAT " to %" GST_TIME_FORMAT,
                   GST_TIME_ARGS(from), GST_TIME_ARGS(to));
  s.frame = frame;
  GST_OBJECT_LOCK(self);
  GST_AGGREGATOR_PAD(GST_AGGREGATOR_SRC_PAD(self))->segment.position = to;
  GST_OBJECT_UNLOCK(self);
  // A frame went out before (s.frame > 0), so the stream's start, caps and segment have too.
  gst_pad_push_event(GST_AGGREGATOR_SRC_PAD(self), gst_event_new_gap(from, to - from));
}

// Draws every frame whose markup is known: all of it has come when a later buffer is
// queued, a GAP covers the frame's time, or the input ended. The base class calls this only
// while input is queued or has ended, so one call draws all the frames a GAP covers. A
// live timeout draws the frame that is due whether or not its markup is known.
static GstFlowReturn gst_pfap_face_aggregate(GstAggregator* agg, gboolean timeout) {
  GstPfapFace* self = GST_PFAP_FACE(agg);
  Stream& s = *self->stream;
  if (s.untimed_input) return GST_FLOW_ERROR;
  if (!s.negotiated) return GST_FLOW_NOT_NEGOTIATED;

  for (;;) {
    GST_OBJECT_LOCK(self);
    const GstSegment segment = GST_AGGREGATOR_PAD(agg->srcpad)->segment;
    GST_OBJECT_UNLOCK(self);
    const GstClockTime pts = frame_time(self, segment, s.frame);
    const GstClockTime next = frame_time(self, segment, s.frame + 1);
    const auto at =
        static_cast<int64_t>(gst_segment_to_running_time(&segment, GST_FORMAT_TIME, pts));

    // Apply everything up to this frame's time.
    bool later_input = false;
    int64_t next_input = -1;
    while (GstBuffer* buffer = gst_aggregator_pad_peek_buffer(self->sinkpad)) {
      const int64_t start = input_running_time(self, GST_BUFFER_PTS(buffer));
      if (start > at) {
        later_input = true;
        next_input = start;
        gst_buffer_unref(buffer);
        break;
      }
      if (GST_BUFFER_FLAG_IS_SET(buffer, GST_BUFFER_FLAG_GAP) && gst_buffer_get_size(buffer) == 0) {
        if (start >= 0 && GST_BUFFER_DURATION_IS_VALID(buffer)) {
          s.covered_until =
              std::max(s.covered_until, start + static_cast<int64_t>(GST_BUFFER_DURATION(buffer)));
        }
      } else {
        apply_event(self, buffer, start);
      }
      gst_buffer_unref(buffer);
      gst_aggregator_pad_drop_buffer(self->sinkpad);
    }

    const bool ended = gst_aggregator_pad_is_eos(self->sinkpad);
    const bool known = later_input || s.covered_until > at || (ended && at < s.animator.end_ns());
    if (!known && (ended || !timeout)) {
      return ended ? GST_FLOW_EOS : GST_AGGREGATOR_FLOW_NEED_DATA;
    }

    if (known) {
      const uint64_t rest_end =
          rest_until_frame(self, segment, at, later_input ? next_input : s.covered_until);
      if (rest_end > 0) {
        skip_to_frame(self, segment, rest_end);
        continue;
      }
    }

    const GstFlowReturn ret = push_frame(self, pts, next, at);
    if (ret != GST_FLOW_OK || !known) return ret;
  }
}

static gboolean gst_pfap_face_sink_event(GstAggregator* agg, GstAggregatorPad* pad,
                                         GstEvent* event) {
  GstPfapFace* self = GST_PFAP_FACE(agg);
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_CAPS: {
      // The input's caps only name the phoneme alphabet; the output's are negotiated apart.
      GstCaps* caps;
      gst_event_parse_caps(event, &caps);
      const gchar* name = gst_structure_get_string(gst_caps_get_structure(caps, 0), "alphabet");
      const pfap::PhonemeAlphabet* alphabet = name ? pfap::find_alphabet(name) : nullptr;
      GST_INFO_OBJECT(self, "alphabet %s%s", name ? name : "(none)",
                      name && !alphabet ? " (unknown)" : "");
      self->stream->animator.set_alphabet(alphabet);
      gst_event_unref(event);
      return TRUE;
    }
    case GST_EVENT_STREAM_START:
      reset(self);
      break;
    case GST_EVENT_SEGMENT: {
      // Bytes (filesrc without pfaptextparse) have no times to draw at.
      const GstSegment* segment;
      gst_event_parse_segment(event, &segment);
      if (segment->format != GST_FORMAT_TIME) {
        self->stream->untimed_input = true;
        GST_ELEMENT_ERROR(self, STREAM, WRONG_TYPE,
                          ("The input is not a timed PFAP stream: read .pfap files through "
                           "pfaptextparse (filesrc ! pfaptextparse ! pfapface)."),
                          ("%s segment: x-pfap streams have TIME segments",
                           gst_format_get_name(segment->format)));
        gst_event_unref(event);
        return FALSE;
      }
      break;
    }
    default:
      break;
  }
  return GST_AGGREGATOR_CLASS(gst_pfap_face_parent_class)->sink_event(agg, pad, event);
}

static GstFlowReturn gst_pfap_face_flush(GstAggregator* agg) {
  reset(GST_PFAP_FACE(agg));
  return GST_FLOW_OK;
}

static gboolean gst_pfap_face_start(GstAggregator* agg) {
  reset(GST_PFAP_FACE(agg));
  return TRUE;
}

static GstFlowReturn gst_pfap_face_update_src_caps(GstAggregator*, GstCaps* caps, GstCaps** ret) {
  // Whatever downstream takes within the template: the face draws at any size and rate.
  *ret = gst_caps_ref(caps);
  return GST_FLOW_OK;
}

static GstCaps* gst_pfap_face_fixate_src_caps(GstAggregator* agg, GstCaps* caps) {
  GstPfapFace* self = GST_PFAP_FACE(agg);
  GST_OBJECT_LOCK(self);
  const int width = self->width, height = self->height;
  GST_OBJECT_UNLOCK(self);
  caps = gst_caps_truncate(gst_caps_make_writable(caps));
  GstStructure* s = gst_caps_get_structure(caps, 0);
  gst_structure_fixate_field_nearest_int(s, "width", width);
  gst_structure_fixate_field_nearest_int(s, "height", height);
  gst_structure_fixate_field_nearest_fraction(s, "framerate", kDefaultFpsN, kDefaultFpsD);
  return gst_caps_fixate(caps);
}

static gboolean gst_pfap_face_negotiated_src_caps(GstAggregator* agg, GstCaps* caps) {
  GstPfapFace* self = GST_PFAP_FACE(agg);
  GstVideoInfo info;
  if (!gst_video_info_from_caps(&info, caps) || info.fps_n <= 0) {
    GST_ERROR_OBJECT(self, "cannot draw into %" GST_PTR_FORMAT, static_cast<gpointer>(caps));
    return FALSE;
  }
  GST_INFO_OBJECT(self, "drawing %" GST_PTR_FORMAT, static_cast<gpointer>(caps));
  self->stream->info = info;
  self->stream->negotiated = true;
  return GST_AGGREGATOR_CLASS(gst_pfap_face_parent_class)->negotiated_src_caps(agg, caps);
}

static void gst_pfap_face_set_property(GObject* object, guint prop_id, const GValue* value,
                                       GParamSpec* pspec) {
  GstPfapFace* self = GST_PFAP_FACE(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_WIDTH:
      self->width = g_value_get_int(value);
      break;
    case PROP_HEIGHT:
      self->height = g_value_get_int(value);
      break;
    case PROP_STYLE:
      self->style = static_cast<pfap::face::Style>(g_value_get_enum(value));
      break;
    case PROP_DEBUG_OVERLAY:
      self->debug_overlay = g_value_get_boolean(value);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_face_get_property(GObject* object, guint prop_id, GValue* value,
                                       GParamSpec* pspec) {
  GstPfapFace* self = GST_PFAP_FACE(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_WIDTH:
      g_value_set_int(value, self->width);
      break;
    case PROP_HEIGHT:
      g_value_set_int(value, self->height);
      break;
    case PROP_STYLE:
      g_value_set_enum(value, static_cast<gint>(self->style));
      break;
    case PROP_DEBUG_OVERLAY:
      g_value_set_boolean(value, self->debug_overlay);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_pfap_face_finalize(GObject* object) {
  delete GST_PFAP_FACE(object)->stream;
  G_OBJECT_CLASS(gst_pfap_face_parent_class)->finalize(object);
}

static void gst_pfap_face_class_init(GstPfapFaceClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstAggregatorClass* aggregator_class = GST_AGGREGATOR_CLASS(klass);

  GST_DEBUG_CATEGORY_INIT(pfapface_debug, "pfapface", 0, "PFAP talking-head renderer");

  gobject_class->set_property = gst_pfap_face_set_property;
  gobject_class->get_property = gst_pfap_face_get_property;
  gobject_class->finalize = gst_pfap_face_finalize;

  /**
   * GstPfapFace:width:
   *
   * The frame width used when downstream leaves it open (the nearest it allows).
   */
  g_object_class_install_property(
      gobject_class, PROP_WIDTH,
      g_param_spec_int("width", "Width", "Frame width when downstream leaves it open", 16, 8192,
                       kDefaultWidth,
                       static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                GST_PARAM_MUTABLE_READY)));
  /**
   * GstPfapFace:height:
   *
   * The frame height used when downstream leaves it open (the nearest it allows).
   */
  g_object_class_install_property(
      gobject_class, PROP_HEIGHT,
      g_param_spec_int("height", "Height", "Frame height when downstream leaves it open", 16, 8192,
                       kDefaultHeight,
                       static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                GST_PARAM_MUTABLE_READY)));
  /**
   * GstPfapFace:style:
   *
   * How the face looks; may change while playing.
   */
  g_object_class_install_property(
      gobject_class, PROP_STYLE,
      g_param_spec_enum("style", "Style", "How the face looks", GST_TYPE_PFAP_FACE_STYLE,
                        static_cast<gint>(kDefaultStyle),
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_PLAYING)));
  /**
   * GstPfapFace:debug-overlay:
   *
   * Writes on each frame the phoneme sounding ("pause" between phonemes) and every FAP whose
   * bookmarked amplitude is not 0, as index:amplitude.
   */
  g_object_class_install_property(
      gobject_class, PROP_DEBUG_OVERLAY,
      g_param_spec_boolean("debug-overlay", "Debug overlay",
                           "Write the current phoneme and the active FAPs on each frame",
                           kDefaultDebugOverlay,
                           static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                    GST_PARAM_MUTABLE_PLAYING)));

  gst_element_class_add_static_pad_template_with_gtype(element_class, &sink_template,
                                                       GST_TYPE_AGGREGATOR_PAD);
  gst_element_class_add_static_pad_template_with_gtype(element_class, &src_template,
                                                       GST_TYPE_AGGREGATOR_PAD);
  gst_element_class_set_static_metadata(
      element_class, "PFAP talking head", "Codec/Decoder/Video",
      "Draws a talking head moved by phoneme and facial animation parameter (PFAP) markup",
      "gst-pfap developers");

  aggregator_class->aggregate = gst_pfap_face_aggregate;
  aggregator_class->sink_event = gst_pfap_face_sink_event;
  aggregator_class->flush = gst_pfap_face_flush;
  aggregator_class->start = gst_pfap_face_start;
  aggregator_class->get_next_time = gst_aggregator_simple_get_next_time;
  aggregator_class->update_src_caps = gst_pfap_face_update_src_caps;
  aggregator_class->fixate_src_caps = gst_pfap_face_fixate_src_caps;
  aggregator_class->negotiated_src_caps = gst_pfap_face_negotiated_src_caps;

  gst_type_mark_as_plugin_api(GST_TYPE_PFAP_FACE_STYLE, static_cast<GstPluginAPIFlags>(0));
}

static void gst_pfap_face_init(GstPfapFace* self) {
  self->stream = new Stream{};
  self->width = kDefaultWidth;
  self->height = kDefaultHeight;
  self->style = kDefaultStyle;
  self->debug_overlay = kDefaultDebugOverlay;
  GstPadTemplate* templ = gst_static_pad_template_get(&sink_template);
  self->sinkpad =
      GST_AGGREGATOR_PAD(g_object_new(GST_TYPE_AGGREGATOR_PAD, "name", "sink", "direction",
                                      GST_PAD_SINK, "template", templ, nullptr));
  gst_object_unref(templ);
  gst_element_add_pad(GST_ELEMENT(self), GST_PAD(self->sinkpad));
}
