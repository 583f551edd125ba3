// SPDX-License-Identifier: LGPL-2.1-or-later
#include "baseenc.h"

#include <new>

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
  pfap::EventTimeline timeline;  // the events' running times
  pfap::MarkupEvent event;       // reused for every buffer
  guint64 malformed = 0;         // under the object lock
  guint64 earlier = 0;           // under the object lock
};

}  // namespace

G_DEFINE_ABSTRACT_TYPE_WITH_CODE(GstPfapBaseEnc, gst_pfap_base_enc, GST_TYPE_ELEMENT,
                                 G_ADD_PRIVATE(GstPfapBaseEnc) GST_DEBUG_CATEGORY_INIT(
                                     pfapbaseenc_debug, "pfapbaseenc", 0,
                                     "PFAP writer base class"))

static GstPfapBaseEncPrivate* priv(GstPfapBaseEnc* enc) {
  return static_cast<GstPfapBaseEncPrivate*>(gst_pfap_base_enc_get_instance_private(enc));
}

GstPad* gst_pfap_base_enc_sinkpad(GstPfapBaseEnc* enc) { return priv(enc)->sinkpad; }
GstPad* gst_pfap_base_enc_srcpad(GstPfapBaseEnc* enc) { return priv(enc)->srcpad; }

guint64 gst_pfap_base_enc_malformed(GstPfapBaseEnc* enc) {
  GST_OBJECT_LOCK(enc);
  const guint64 count = priv(enc)->malformed;
  GST_OBJECT_UNLOCK(enc);
  return count;
}

guint64 gst_pfap_base_enc_earlier(GstPfapBaseEnc* enc) {
  GST_OBJECT_LOCK(enc);
  const guint64 count = priv(enc)->earlier;
  GST_OBJECT_UNLOCK(enc);
  return count;
}

int64_t gst_pfap_base_enc_place(GstPfapBaseEnc* enc, GstClockTime pts,
                                const pfap::MarkupEvent& event) {
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
  p.timeline.add(time,
                 event.kind == PFAP_EVENT_PHONEME ? event.phoneme.duration_ms * pfap::kNsPerMs : 0);
  return time;
}

// Forgets the segment and the events' times (FLUSH_STOP, READY to PAUSED).
static void reset(GstPfapBaseEnc* enc) {
  GstPfapBaseEncPrivate& p = *priv(enc);
  gst_segment_init(&p.segment, GST_FORMAT_TIME);
  p.timeline.reset();
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
  const GstFlowReturn ret = GST_PFAP_BASE_ENC_GET_CLASS(enc)->handle_event(enc, buffer, p.event);
  gst_buffer_unref(buffer);
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

static void gst_pfap_base_enc_class_init(GstPfapBaseEncClass* klass) {
  G_OBJECT_CLASS(klass)->constructed = gst_pfap_base_enc_constructed;
  G_OBJECT_CLASS(klass)->finalize = gst_pfap_base_enc_finalize;
  GST_ELEMENT_CLASS(klass)->change_state = gst_pfap_base_enc_change_state;
  klass->sink_event = gst_pfap_base_enc_default_sink_event;
}

static void gst_pfap_base_enc_init(GstPfapBaseEnc* enc) {
  new (priv(enc)) GstPfapBaseEncPrivate();
}
