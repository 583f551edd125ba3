// SPDX-License-Identifier: LGPL-2.1-or-later
#include "baseenc.h"

#include <algorithm>
#include <new>
#include <optional>

#include "basepads.h"
#include "markupbuffer.h"
#include "pfap/model.h"
#include "pfap/timeline.h"
#include "runningtime.h"
#include "warning.h"

GST_DEBUG_CATEGORY_STATIC(pfapbaseenc_debug);
#define GST_CAT_DEFAULT pfapbaseenc_debug

namespace {

// GObject runs no C++ constructors: made in place in init, destroyed in finalize.
struct GstPfapBaseEncPrivate {
  GstPfapBaseEncPrivate() { gst_segment_init(&segment, GST_FORMAT_TIME); }

  GstPad* sinkpad = nullptr;
  GstPad* srcpad = nullptr;
  GstSegment segment;
  pfap::EventTimeline timeline;   // the events' running times
  pfap::MarkupEvent event;        // reused for every buffer
  bool pushed = false;            // the subclass pushed output for the event in hand
  std::optional<int64_t> origin;  // file time less running time, from the first event's segment
  // Under the object lock, since READY to PAUSED (a flush keeps them): the stats.
  guint64 events = 0;
  guint64 malformed = 0;
  guint64 earlier = 0;
};

enum { PROP_0, PROP_STATS };

}  // namespace

G_DEFINE_ABSTRACT_TYPE_WITH_CODE(GstPfapBaseEnc, gst_pfap_base_enc, GST_TYPE_ELEMENT,
                                 G_ADD_PRIVATE(GstPfapBaseEnc)
                                     GST_DEBUG_CATEGORY_INIT(pfapbaseenc_debug, "pfapbaseenc", 0,
                                                             "PFAP writer base class"))

static GstPfapBaseEncPrivate* priv(GstPfapBaseEnc* enc) {
  return static_cast<GstPfapBaseEncPrivate*>(gst_pfap_base_enc_get_instance_private(enc));
}

GstPad* gst_pfap_base_enc_sinkpad(GstPfapBaseEnc* enc) { return priv(enc)->sinkpad; }
GstPad* gst_pfap_base_enc_srcpad(GstPfapBaseEnc* enc) { return priv(enc)->srcpad; }

GstFlowReturn gst_pfap_base_enc_push(GstPfapBaseEnc* enc, GstBuffer* buffer) {
  priv(enc)->pushed = true;
  return gst_pad_push(priv(enc)->srcpad, buffer);
}

// How long `event` lasts: a phoneme its duration, a state event nothing.
static int64_t event_duration_ns(const pfap::MarkupEvent& event) {
  return event.kind == PFAP_EVENT_PHONEME ? event.phoneme.duration_ms * pfap::kNsPerMs : 0;
}

// Stream time less running time at the start of `segment` (rate 1, as x-pfap streams are).
static int64_t stream_less_running(const GstSegment& segment) {
  const guint64 start = segment.start + segment.offset;
  guint64 running = 0;
  guint64 stream = 0;
  if (gst_segment_to_running_time_full(&segment, GST_FORMAT_TIME, start, &running) != 1 ||
      gst_segment_to_stream_time_full(&segment, GST_FORMAT_TIME, start, &stream) != 1) {
    return -static_cast<int64_t>(segment.base);
  }
  return static_cast<int64_t>(stream) - static_cast<int64_t>(running);
}

// The time in the file (ns) of an event at running time `running`: its stream time in the
// segment of the stream's first event, where a reader put the file's times; later segments
// go on from there in running time, so that the file's times never go back. Before 0, 0.
static int64_t file_time(GstPfapBaseEncPrivate& p, int64_t running) {
  if (!p.origin) p.origin = stream_less_running(p.segment);
  return std::max<int64_t>(running + *p.origin, 0);
}

// The running time (ns) of `event`, read from a buffer with `pts`: an event without a PTS
// starts where the one before it ended (the first where the segment begins); one earlier
// than the one before it is placed at that one's time, with a rate-limited warning.
static int64_t place(GstPfapBaseEnc* enc, GstClockTime pts, const pfap::MarkupEvent& event) {
  GstPfapBaseEncPrivate& p = *priv(enc);
  // A first event without a PTS is where the segment begins, whose running time is base.
  int64_t time =
      p.timeline.start(pfap_running_time(p.segment, pts), static_cast<int64_t>(p.segment.base));
  if (p.timeline.earlier(time)) {
    const guint64 count = p.timeline.earlier_count();
    GST_OBJECT_LOCK(enc);
    p.earlier = count;
    GST_OBJECT_UNLOCK(enc);
    PFAP_WARN_EARLIER_EVENT(enc, "written", time, p.timeline.previous_ns(), count);
    time = p.timeline.previous_ns();
  }
  p.timeline.add(time, event_duration_ns(event));
  return time;
}

// A held event's time span, as a GAP, so that the sinks downstream preroll and their running
// time goes on while the writer holds its output (a FAP file, a Rhubarb JSON document, an
// utterance's marks).
static void push_gap(GstPfapBaseEnc* enc, int64_t running, const pfap::MarkupEvent& event) {
  GstPfapBaseEncPrivate& p = *priv(enc);
  guint64 position = 0;
  if (running < 0 || gst_segment_position_from_running_time_full(&p.segment, GST_FORMAT_TIME,
                                                                 running, &position) != 1) {
    return;
  }
  gst_pad_push_event(p.srcpad, gst_event_new_gap(position, event_duration_ns(event)));
}

// Forgets the segment and the events' times (FLUSH_STOP, READY to PAUSED).
static void reset(GstPfapBaseEnc* enc) {
  GstPfapBaseEncPrivate& p = *priv(enc);
  gst_segment_init(&p.segment, GST_FORMAT_TIME);
  p.timeline.reset();
  p.origin.reset();
  GstPfapBaseEncClass* klass = GST_PFAP_BASE_ENC_GET_CLASS(enc);
  if (klass->reset != nullptr) klass->reset(enc);
}

static GstFlowReturn gst_pfap_base_enc_chain(GstPad*, GstObject* parent, GstBuffer* buffer) {
  GstPfapBaseEnc* enc = GST_PFAP_BASE_ENC(parent);
  GstPfapBaseEncPrivate& p = *priv(enc);
  if (!pfap_buffer_read(buffer, p.event)) {
    GST_OBJECT_LOCK(enc);
    const guint64 malformed = ++p.malformed;
    GST_OBJECT_UNLOCK(enc);
    PFAP_WARN_MALFORMED_EVENT(enc, buffer, malformed);
    gst_buffer_unref(buffer);
    return GST_FLOW_OK;
  }
  GST_OBJECT_LOCK(enc);
  p.events++;
  GST_OBJECT_UNLOCK(enc);
  const int64_t running = place(enc, GST_BUFFER_PTS(buffer), p.event);
  p.pushed = false;
  const GstFlowReturn ret =
      GST_PFAP_BASE_ENC_GET_CLASS(enc)->handle_event(enc, buffer, p.event, file_time(p, running));
  gst_buffer_unref(buffer);
  if (ret == GST_FLOW_OK && !p.pushed) push_gap(enc, running, p.event);
  return ret;
}

static gboolean gst_pfap_base_enc_default_sink_event(GstPfapBaseEnc* enc, GstEvent* event) {
  GstPfapBaseEncPrivate& p = *priv(enc);
  GstPfapBaseEncClass* klass = GST_PFAP_BASE_ENC_GET_CLASS(enc);
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_CAPS: {
      if (klass->set_caps != nullptr) {
        GstCaps* caps = nullptr;
        gst_event_parse_caps(event, &caps);
        klass->set_caps(enc, caps);
      }
      gst_event_unref(event);
      // Whatever the input caps say (an alphabet), the output's are the template's.
      GstCaps* caps = gst_pad_get_pad_template_caps(p.srcpad);
      const gboolean ok = gst_pad_set_caps(p.srcpad, caps);
      gst_caps_unref(caps);
      return ok;
    }
    case GST_EVENT_SEGMENT: {
      GstSegment segment;
      gst_event_copy_segment(event, &segment);
      if (segment.format != GST_FORMAT_TIME) {
        GST_ELEMENT_ERROR(
            enc, STREAM, FORMAT, (nullptr),
            ("%s segment: x-pfap streams have TIME segments", gst_format_get_name(segment.format)));
        gst_event_unref(event);
        return FALSE;
      }
      p.segment = segment;
      if (klass->output_segment != nullptr) event = klass->output_segment(enc, event);
      return gst_pad_push_event(p.srcpad, event);
    }
    case GST_EVENT_EOS:
      if (klass->finish != nullptr) klass->finish(enc);
      break;
    case GST_EVENT_FLUSH_STOP:
      reset(enc);
      break;
    default:
      break;
  }
  return gst_pad_event_default(p.sinkpad, GST_OBJECT(enc), event);
}

static gboolean gst_pfap_base_enc_sink_event(GstPad*, GstObject* parent, GstEvent* event) {
  GstPfapBaseEnc* enc = GST_PFAP_BASE_ENC(parent);
  return GST_PFAP_BASE_ENC_GET_CLASS(enc)->sink_event(enc, event);
}

static GstStateChangeReturn gst_pfap_base_enc_change_state(GstElement* element,
                                                           GstStateChange transition) {
  if (transition == GST_STATE_CHANGE_READY_TO_PAUSED) {
    GstPfapBaseEnc* enc = GST_PFAP_BASE_ENC(element);
    GstPfapBaseEncPrivate& p = *priv(enc);
    // The counters start again; earlier_count is the timeline's.
    p.timeline = pfap::EventTimeline{};
    GST_OBJECT_LOCK(enc);
    p.events = 0;
    p.malformed = 0;
    p.earlier = 0;
    GST_OBJECT_UNLOCK(enc);
    reset(enc);
  }
  return GST_ELEMENT_CLASS(gst_pfap_base_enc_parent_class)->change_state(element, transition);
}

static void gst_pfap_base_enc_constructed(GObject* object) {
  G_OBJECT_CLASS(gst_pfap_base_enc_parent_class)->constructed(object);
  GstPfapBaseEncPrivate& p = *priv(GST_PFAP_BASE_ENC(object));
  pfap_base_add_pads(GST_ELEMENT(object), gst_pfap_base_enc_chain, gst_pfap_base_enc_sink_event,
                     &p.sinkpad, &p.srcpad);
}

static void gst_pfap_base_enc_finalize(GObject* object) {
  priv(GST_PFAP_BASE_ENC(object))->~GstPfapBaseEncPrivate();
  G_OBJECT_CLASS(gst_pfap_base_enc_parent_class)->finalize(object);
}

static void gst_pfap_base_enc_get_property(GObject* object, guint prop_id, GValue* value,
                                           GParamSpec* pspec) {
  GstPfapBaseEncPrivate& p = *priv(GST_PFAP_BASE_ENC(object));
  switch (prop_id) {
    case PROP_STATS:
      GST_OBJECT_LOCK(object);
      g_value_take_boxed(
          value, gst_structure_new("application/x-pfap-enc-stats", "events", G_TYPE_UINT64,
                                   p.events, "malformed", G_TYPE_UINT64, p.malformed, "earlier",
                                   G_TYPE_UINT64, p.earlier, nullptr));
      GST_OBJECT_UNLOCK(object);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
}

static void gst_pfap_base_enc_class_init(GstPfapBaseEncClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  gobject_class->constructed = gst_pfap_base_enc_constructed;
  gobject_class->finalize = gst_pfap_base_enc_finalize;
  gobject_class->get_property = gst_pfap_base_enc_get_property;
  // The same counters, by the same names, as every element of the plugins (docs/elements.md).
  g_object_class_install_property(
      gobject_class, PROP_STATS,
      g_param_spec_boxed("stats", "Statistics",
                         "Counters since READY to PAUSED (guint64): events (read), malformed "
                         "(input buffers dropped), earlier (events earlier than the one before, "
                         "written at its time)",
                         GST_TYPE_STRUCTURE,
                         static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS)));
  GST_ELEMENT_CLASS(klass)->change_state = gst_pfap_base_enc_change_state;
  klass->sink_event = gst_pfap_base_enc_default_sink_event;
}

static void gst_pfap_base_enc_init(GstPfapBaseEnc* enc) { new (priv(enc)) GstPfapBaseEncPrivate(); }
