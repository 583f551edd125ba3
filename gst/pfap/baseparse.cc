// SPDX-License-Identifier: LGPL-2.1-or-later
#include "baseparse.h"

#include "basepads.h"
#include "markupbuffer.h"
#include "noseek.h"
#include "sparse.h"

GST_DEBUG_CATEGORY_STATIC(pfapbaseparse_debug);
#define GST_CAT_DEFAULT pfapbaseparse_debug

namespace {

struct GstPfapBaseParsePrivate {
  GstPad* sinkpad;
  GstPad* srcpad;
  gboolean need_events;  // stream-start, caps or segment still to send
  gboolean discont;
  gboolean at_start;  // the bytes read so far may be the start of a byte order mark
  gsize mark_bytes;   // how many of them there are
  // Under the object lock, since READY to PAUSED (a flush keeps them): the stats.
  guint64 events;
  guint64 bad_lines;
};

enum { PROP_0, PROP_STATS };

// A UTF-8 byte order mark (U+FEFF), which editors on Windows put at the start of a text file,
// is no part of any format read here: it is dropped before the subclass reads.
constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

}  // namespace

G_DEFINE_ABSTRACT_TYPE_WITH_CODE(GstPfapBaseParse, gst_pfap_base_parse, GST_TYPE_ELEMENT,
                                 G_ADD_PRIVATE(GstPfapBaseParse)
                                     GST_DEBUG_CATEGORY_INIT(pfapbaseparse_debug, "pfapbaseparse",
                                                             0, "PFAP text parser base class"))

static GstPfapBaseParsePrivate* priv(GstPfapBaseParse* parse) {
  return static_cast<GstPfapBaseParsePrivate*>(gst_pfap_base_parse_get_instance_private(parse));
}

GstPad* gst_pfap_base_parse_sinkpad(GstPfapBaseParse* parse) { return priv(parse)->sinkpad; }
GstPad* gst_pfap_base_parse_srcpad(GstPfapBaseParse* parse) { return priv(parse)->srcpad; }

guint64 gst_pfap_base_parse_count_bad_line(GstPfapBaseParse* parse) {
  GST_OBJECT_LOCK(parse);
  const guint64 count = ++priv(parse)->bad_lines;
  GST_OBJECT_UNLOCK(parse);
  return count;
}

guint64 gst_pfap_base_parse_bad_lines(GstPfapBaseParse* parse) {
  GST_OBJECT_LOCK(parse);
  const guint64 count = priv(parse)->bad_lines;
  GST_OBJECT_UNLOCK(parse);
  return count;
}

static void reset(GstPfapBaseParse* parse) {
  priv(parse)->need_events = TRUE;
  priv(parse)->discont = TRUE;
  priv(parse)->at_start = TRUE;
  priv(parse)->mark_bytes = 0;
  GstPfapBaseParseClass* klass = GST_PFAP_BASE_PARSE_GET_CLASS(parse);
  if (klass->reset != nullptr) klass->reset(parse);
}

// Upstream's stream-start was forwarded if there was one; caps stay across a flush, the
// segment does not.
void gst_pfap_base_parse_start_output(GstPfapBaseParse* parse) {
  GstPfapBaseParsePrivate& p = *priv(parse);
  if (!p.need_events) return;
  p.need_events = FALSE;
  if (GstEvent* start = gst_pad_get_sticky_event(p.srcpad, GST_EVENT_STREAM_START, 0)) {
    gst_event_unref(start);
  } else {
    gchar* id = gst_pad_create_stream_id(p.srcpad, GST_ELEMENT(parse), nullptr);
    gst_pad_push_event(p.srcpad, pfap_make_sparse(gst_event_new_stream_start(id)));
    g_free(id);
  }
  if (!gst_pad_has_current_caps(p.srcpad)) {
    GstPfapBaseParseClass* klass = GST_PFAP_BASE_PARSE_GET_CLASS(parse);
    GstCaps* caps = klass->output_caps != nullptr ? klass->output_caps(parse)
                                                  : gst_pad_get_pad_template_caps(p.srcpad);
    gst_pad_push_event(p.srcpad, gst_event_new_caps(caps));
    gst_caps_unref(caps);
  }
  GstSegment segment;
  gst_segment_init(&segment, GST_FORMAT_TIME);
  gst_pad_push_event(p.srcpad, gst_event_new_segment(&segment));
}

GstFlowReturn gst_pfap_base_parse_push(GstPfapBaseParse* parse, const pfap::TextEvent& event) {
  GstPfapBaseParsePrivate& p = *priv(parse);
  GstBuffer* buffer = pfap_buffer_new(event.event);
  if (buffer == nullptr) {
    // The readers give values within range and bound the FAPs of an event: a bug.
    GST_ELEMENT_ERROR(
        parse, STREAM, FAILED, (nullptr),
        ("the event at %" G_GINT64_FORMAT " ms is one x-pfap cannot hold", event.time_ms));
    return GST_FLOW_ERROR;
  }
  GST_BUFFER_PTS(buffer) = event.time_ms * GST_MSECOND;
  if (event.event.kind == PFAP_EVENT_PHONEME) {
    GST_BUFFER_DURATION(buffer) = event.event.phoneme.duration_ms * GST_MSECOND;
  }
  if (p.discont) GST_BUFFER_FLAG_SET(buffer, GST_BUFFER_FLAG_DISCONT);
  p.discont = FALSE;
  gst_pfap_base_parse_start_output(parse);
  GST_OBJECT_LOCK(parse);
  p.events++;
  GST_OBJECT_UNLOCK(parse);
  GST_LOG_OBJECT(parse, "event kind %d at %" GST_TIME_FORMAT, event.event.kind,
                 GST_TIME_ARGS(GST_BUFFER_PTS(buffer)));
  return gst_pad_push(p.srcpad, buffer);
}

// Hands `data` to the subclass without a byte order mark at the start of the text, even one
// split across buffers. `end`: the input has ended (`data` empty).
static GstFlowReturn read_text(GstPfapBaseParse* parse, std::string_view data, bool end) {
  GstPfapBaseParsePrivate& p = *priv(parse);
  GstPfapBaseParseClass* klass = GST_PFAP_BASE_PARSE_GET_CLASS(parse);
  if (p.at_start) {
    while (!data.empty() && p.mark_bytes < kByteOrderMark.size() &&
           data[0] == kByteOrderMark[p.mark_bytes]) {
      data.remove_prefix(1);
      ++p.mark_bytes;
    }
    if (p.mark_bytes == kByteOrderMark.size()) {
      p.at_start = FALSE;
    } else if (data.empty() && !end) {
      return GST_FLOW_OK;  // the rest of a mark may come with the next buffer
    } else {
      // Not a mark: the bytes held back are text.
      p.at_start = FALSE;
      if (p.mark_bytes > 0) {
        const GstFlowReturn ret = klass->read_chunk(parse, kByteOrderMark.substr(0, p.mark_bytes));
        if (ret != GST_FLOW_OK) return ret;
      }
    }
  }
  return data.empty() ? GST_FLOW_OK : klass->read_chunk(parse, data);
}

static GstFlowReturn gst_pfap_base_parse_chain(GstPad*, GstObject* parent, GstBuffer* buffer) {
  GstPfapBaseParse* parse = GST_PFAP_BASE_PARSE(parent);
  GstMapInfo map;
  if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) {
    gst_buffer_unref(buffer);
    GST_ELEMENT_ERROR(parse, RESOURCE, READ, (nullptr), ("cannot map the input buffer"));
    return GST_FLOW_ERROR;
  }
  const GstFlowReturn ret =
      read_text(parse, {reinterpret_cast<const char*>(map.data), map.size}, false);
  gst_buffer_unmap(buffer, &map);
  gst_buffer_unref(buffer);
  return ret;
}

static gboolean gst_pfap_base_parse_sink_event(GstPad* pad, GstObject* parent, GstEvent* event) {
  GstPfapBaseParse* parse = GST_PFAP_BASE_PARSE(parent);
  GstPfapBaseParseClass* klass = GST_PFAP_BASE_PARSE_GET_CLASS(parse);
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_STREAM_START:
      return gst_pad_push_event(priv(parse)->srcpad, pfap_make_sparse(event));
    // Text caps and upstream times say nothing about the output: its caps and segment go
    // before the first buffer.
    case GST_EVENT_CAPS:
    case GST_EVENT_SEGMENT:
    case GST_EVENT_GAP:
      gst_event_unref(event);
      return TRUE;
    case GST_EVENT_EOS: {
      GstFlowReturn ret = read_text(parse, {}, true);
      if (ret == GST_FLOW_OK && klass->finish != nullptr) ret = klass->finish(parse);
      // The error is posted; the stream did not end well.
      if (ret == GST_FLOW_ERROR) {
        gst_event_unref(event);
        return FALSE;
      }
      if (ret == GST_PFAP_BASE_PARSE_FLOW_EOS_HELD) {
        gst_event_unref(event);
        return TRUE;
      }
      gst_pfap_base_parse_start_output(parse);
      break;
    }
    case GST_EVENT_FLUSH_STOP:
      reset(parse);
      break;
    default:
      break;
  }
  return gst_pad_event_default(pad, parent, event);
}

static GstStateChangeReturn gst_pfap_base_parse_change_state(GstElement* element,
                                                             GstStateChange transition) {
  if (transition == GST_STATE_CHANGE_READY_TO_PAUSED) {
    GstPfapBaseParse* parse = GST_PFAP_BASE_PARSE(element);
    GST_OBJECT_LOCK(parse);
    priv(parse)->events = 0;
    priv(parse)->bad_lines = 0;
    GST_OBJECT_UNLOCK(parse);
    reset(parse);
  }
  return GST_ELEMENT_CLASS(gst_pfap_base_parse_parent_class)->change_state(element, transition);
}

static void gst_pfap_base_parse_constructed(GObject* object) {
  G_OBJECT_CLASS(gst_pfap_base_parse_parent_class)->constructed(object);
  GstPfapBaseParsePrivate& p = *priv(GST_PFAP_BASE_PARSE(object));
  pfap_base_add_pads(GST_ELEMENT(object), gst_pfap_base_parse_chain, gst_pfap_base_parse_sink_event,
                     &p.sinkpad, &p.srcpad);
  pfap_noseek_set_src_functions(p.srcpad);
}

static void gst_pfap_base_parse_get_property(GObject* object, guint prop_id, GValue* value,
                                             GParamSpec* pspec) {
  GstPfapBaseParsePrivate& p = *priv(GST_PFAP_BASE_PARSE(object));
  switch (prop_id) {
    case PROP_STATS:
      GST_OBJECT_LOCK(object);
      g_value_take_boxed(
          value, gst_structure_new("application/x-pfap-parse-stats", "events", G_TYPE_UINT64,
                                   p.events, "bad-lines", G_TYPE_UINT64, p.bad_lines, nullptr));
      GST_OBJECT_UNLOCK(object);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
}

static void gst_pfap_base_parse_class_init(GstPfapBaseParseClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  gobject_class->constructed = gst_pfap_base_parse_constructed;
  gobject_class->get_property = gst_pfap_base_parse_get_property;
  GST_ELEMENT_CLASS(klass)->change_state = gst_pfap_base_parse_change_state;
  // The same counters, by the same names, as every element of the plugins (docs/elements.md).
  g_object_class_install_property(
      gobject_class, PROP_STATS,
      g_param_spec_boxed("stats", "Statistics",
                         "Counters since READY to PAUSED (guint64): events (output), bad-lines "
                         "(skipped, with skip-bad-lines)",
                         GST_TYPE_STRUCTURE,
                         static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS)));
}

static void gst_pfap_base_parse_init(GstPfapBaseParse* parse) {
  priv(parse)->need_events = TRUE;
  priv(parse)->discont = TRUE;
  priv(parse)->at_start = TRUE;
}
