// SPDX-License-Identifier: LGPL-2.1-or-later
#include "baseparse.h"

#include <optional>

#include "basepads.h"
#include "markupbuffer.h"
#include "noseek.h"
#include "ratelimit.h"
#include "sparse.h"

GST_DEBUG_CATEGORY_STATIC(pfapbaseparse_debug);
#define GST_CAT_DEFAULT pfapbaseparse_debug

namespace {

// What the streaming thread keeps of the text between buffers. GObject runs no C++
// constructors, so it lives behind a pointer made in init and deleted in finalize.
struct Text {
  bool at_start = true;   // the bytes read so far may be the start of a byte order mark
  size_t mark_bytes = 0;  // how many of them there are
  std::string tail;       // the start of a line whose end has not come yet
  guint64 line = 1;       // the number of the line being read, from 1
  bool skipping = false;  // dropping the rest of an over-long line
  bool failed = false;    // an error was posted: the rest of the stream is dropped
  // For messages, asked once: the upstream file or URI, and whether it is a file.
  std::optional<std::pair<std::string, bool>> source;
};

struct GstPfapBaseParsePrivate {
  GstPad* sinkpad;
  GstPad* srcpad;
  gboolean need_events;  // stream-start, caps or segment still to send
  gboolean discont;
  Text* text;
  gboolean skip_bad_lines;  // under the object lock
  // Under the object lock, since READY to PAUSED (a flush keeps them): the stats.
  guint64 events;
  guint64 bad_lines;
};

enum { PROP_0, PROP_STATS };

// A UTF-8 byte order mark (U+FEFF), which editors on Windows put at the start of a text file,
// is no part of any format read here: it is dropped before the subclass reads.
constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

// Far above any real line (a .pfap state listing every FAP is about 2 KiB); bounds the memory
// a stream without line ends takes, and the FAPs of one .pfap event to what x-pfap holds.
constexpr size_t kMaxLineBytes = 64 * 1024;

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

gboolean gst_pfap_base_parse_skips_bad_lines(GstPfapBaseParse* parse) {
  GST_OBJECT_LOCK(parse);
  const gboolean skip = priv(parse)->skip_bad_lines;
  GST_OBJECT_UNLOCK(parse);
  return skip;
}

void gst_pfap_base_parse_set_skip_bad_lines(GstPfapBaseParse* parse, gboolean skip) {
  GST_OBJECT_LOCK(parse);
  priv(parse)->skip_bad_lines = skip;
  GST_OBJECT_UNLOCK(parse);
}

GParamSpec* gst_pfap_base_parse_skip_bad_lines_spec() {
  return g_param_spec_boolean("skip-bad-lines", "Skip bad lines",
                              "Warn about a bad line and go on, instead of an error", FALSE,
                              static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                       GST_PARAM_MUTABLE_PLAYING));
}

guint64 gst_pfap_base_parse_bad_lines(GstPfapBaseParse* parse) {
  GST_OBJECT_LOCK(parse);
  const guint64 count = priv(parse)->bad_lines;
  GST_OBJECT_UNLOCK(parse);
  return count;
}

const std::string& gst_pfap_base_parse_source(GstPfapBaseParse* parse, bool* is_file) {
  Text& t = *priv(parse)->text;
  if (!t.source) {
    GstQuery* query = gst_query_new_uri();
    gchar* uri = nullptr;
    if (gst_pad_peer_query(priv(parse)->sinkpad, query)) gst_query_parse_uri(query, &uri);
    gst_query_unref(query);
    gchar* path = uri != nullptr ? g_filename_from_uri(uri, nullptr, nullptr) : nullptr;
    gchar* display = path != nullptr ? g_filename_display_name(path) : nullptr;
    t.source.emplace(display != nullptr ? display : uri != nullptr ? uri : "", path != nullptr);
    g_free(display);
    g_free(path);
    g_free(uri);
  }
  if (is_file != nullptr) *is_file = t.source->second;
  return t.source->first;
}

GstFlowReturn gst_pfap_base_parse_bad_item(GstPfapBaseParse* parse, const std::string& item,
                                           gsize column, const std::string& what) {
  bool is_file = false;
  const std::string& name = gst_pfap_base_parse_source(parse, &is_file);
  const std::string source = name.empty() ? ""
                             : is_file    ? " of file \"" + name + "\""
                                          : " of \"" + name + "\"";
  if (!gst_pfap_base_parse_skips_bad_lines(parse)) {
    GST_ELEMENT_ERROR(
        parse, STREAM, DECODE,
        ("Bad %s, column %zu%s: %s", item.c_str(), column + 1, source.c_str(), what.c_str()),
        ("set skip-bad-lines to warn and go on"));
    return GST_FLOW_ERROR;
  }
  GST_OBJECT_LOCK(parse);
  const guint64 count = ++priv(parse)->bad_lines;
  GST_OBJECT_UNLOCK(parse);
  GST_DEBUG_OBJECT(parse, "skipped %s, column %zu%s: %s", item.c_str(), column + 1, source.c_str(),
                   what.c_str());
  // Random bytes are a bad line every few hundred bytes: warn at the 1st, 2nd, 4th, ...
  if (pfap_warn_at(count)) {
    GST_ELEMENT_WARNING(parse, STREAM, DECODE,
                        ("Skipped %s, column %zu%s: %s (%" G_GUINT64_FORMAT " bad so far)",
                         item.c_str(), column + 1, source.c_str(), what.c_str(), count),
                        ("warned at the 1st, 2nd, 4th, 8th, ... bad line; the stats property's "
                         "bad-lines counts them all"));
  }
  return GST_FLOW_OK;
}

GstFlowReturn gst_pfap_base_parse_bad_line(GstPfapBaseParse* parse, gsize column,
                                           const std::string& what) {
  const std::string item = std::string(GST_PFAP_BASE_PARSE_GET_CLASS(parse)->line_name) + " " +
                           std::to_string(priv(parse)->text->line);
  return gst_pfap_base_parse_bad_item(parse, item, column, what);
}

static void reset(GstPfapBaseParse* parse) {
  priv(parse)->need_events = TRUE;
  priv(parse)->discont = TRUE;
  *priv(parse)->text = Text{};
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

// A line grew past the limit: reported once, and the rest of it is dropped.
static GstFlowReturn line_too_long(GstPfapBaseParse* parse) {
  Text& t = *priv(parse)->text;
  GstPfapBaseParseClass* klass = GST_PFAP_BASE_PARSE_GET_CLASS(parse);
  t.tail.clear();
  t.skipping = true;
  if (klass->line_too_long != nullptr) return klass->line_too_long(parse);
  return gst_pfap_base_parse_bad_line(
      parse, klass->max_line_bytes,
      "longer than " + std::to_string(klass->max_line_bytes) + " bytes");
}

// Whether `tail` then `piece`, a line so far, are past the limit. A last '\r' does not count:
// it may be the start of a "\r\n".
static bool too_long(GstPfapBaseParse* parse, std::string_view tail, std::string_view piece) {
  const std::string_view last = piece.empty() ? tail : piece;
  const size_t bytes = tail.size() + piece.size() - (last.ends_with('\r') ? 1 : 0);
  return bytes > GST_PFAP_BASE_PARSE_GET_CLASS(parse)->max_line_bytes;
}

// Reads one whole line, without its '\n', and without the '\r' of a "\r\n".
static GstFlowReturn read_line(GstPfapBaseParse* parse, std::string_view line) {
  if (line.ends_with('\r')) line.remove_suffix(1);
  return GST_PFAP_BASE_PARSE_GET_CLASS(parse)->read_line(parse, line);
}

GstFlowReturn gst_pfap_base_parse_read_lines(GstPfapBaseParse* parse, std::string_view data) {
  Text& t = *priv(parse)->text;
  while (!data.empty()) {
    const size_t end = data.find('\n');
    const std::string_view piece = data.substr(0, end);
    GstFlowReturn ret = GST_FLOW_OK;
    if (t.skipping) {
      // Nothing: the line was reported when it grew too long.
    } else if (too_long(parse, t.tail, piece)) {
      ret = line_too_long(parse);
    } else if (end == std::string_view::npos) {
      t.tail.append(piece);
    } else if (t.tail.empty()) {
      ret = read_line(parse, piece);  // whole in this chunk: no copy
    } else {
      t.tail.append(piece);
      ret = read_line(parse, t.tail);
      t.tail.clear();
    }
    if (ret != GST_FLOW_OK || end == std::string_view::npos) return ret;
    ++t.line;
    t.skipping = false;
    data.remove_prefix(end + 1);
  }
  return GST_FLOW_OK;
}

// Hands `data` to the subclass without a byte order mark at the start of the text, even one
// split across buffers. `end`: the input has ended (`data` empty).
static GstFlowReturn read_text(GstPfapBaseParse* parse, std::string_view data, bool end) {
  Text& t = *priv(parse)->text;
  GstPfapBaseParseClass* klass = GST_PFAP_BASE_PARSE_GET_CLASS(parse);
  if (t.at_start) {
    while (!data.empty() && t.mark_bytes < kByteOrderMark.size() &&
           data[0] == kByteOrderMark[t.mark_bytes]) {
      data.remove_prefix(1);
      ++t.mark_bytes;
    }
    if (t.mark_bytes == kByteOrderMark.size()) {
      t.at_start = false;
    } else if (data.empty() && !end) {
      return GST_FLOW_OK;  // the rest of a mark may come with the next buffer
    } else {
      // Not a mark: the bytes held back are text.
      t.at_start = false;
      if (t.mark_bytes > 0) {
        const GstFlowReturn ret = klass->read_chunk(parse, kByteOrderMark.substr(0, t.mark_bytes));
        if (ret != GST_FLOW_OK) return ret;
      }
    }
  }
  return data.empty() ? GST_FLOW_OK : klass->read_chunk(parse, data);
}

// At EOS: the rest of a byte order mark's bytes, the last line, which may have no line end,
// then the subclass's finish.
static GstFlowReturn read_end(GstPfapBaseParse* parse) {
  Text& t = *priv(parse)->text;
  GstPfapBaseParseClass* klass = GST_PFAP_BASE_PARSE_GET_CLASS(parse);
  GstFlowReturn ret = read_text(parse, {}, true);
  if (ret == GST_FLOW_OK && !t.skipping && !t.tail.empty()) ret = read_line(parse, t.tail);
  t.tail.clear();
  if (ret == GST_FLOW_OK && klass->finish != nullptr) ret = klass->finish(parse);
  return ret;
}

static GstFlowReturn gst_pfap_base_parse_chain(GstPad*, GstObject* parent, GstBuffer* buffer) {
  GstPfapBaseParse* parse = GST_PFAP_BASE_PARSE(parent);
  Text& t = *priv(parse)->text;
  GstMapInfo map;
  if (t.failed) {
    gst_buffer_unref(buffer);
    return GST_FLOW_ERROR;
  }
  if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) {
    gst_buffer_unref(buffer);
    GST_ELEMENT_ERROR(parse, RESOURCE, READ, (nullptr), ("cannot map the input buffer"));
    return GST_FLOW_ERROR;
  }
  const GstFlowReturn ret =
      read_text(parse, {reinterpret_cast<const char*>(map.data), map.size}, false);
  gst_buffer_unmap(buffer, &map);
  gst_buffer_unref(buffer);
  t.failed = ret == GST_FLOW_ERROR;
  return ret;
}

static gboolean gst_pfap_base_parse_sink_event(GstPad* pad, GstObject* parent, GstEvent* event) {
  GstPfapBaseParse* parse = GST_PFAP_BASE_PARSE(parent);
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
      // After an error nothing more is read; the stream still ends.
      const GstFlowReturn ret = priv(parse)->text->failed ? GST_FLOW_OK : read_end(parse);
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

static void gst_pfap_base_parse_finalize(GObject* object) {
  delete priv(GST_PFAP_BASE_PARSE(object))->text;
  G_OBJECT_CLASS(gst_pfap_base_parse_parent_class)->finalize(object);
}

static void gst_pfap_base_parse_class_init(GstPfapBaseParseClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  klass->line_name = "line";
  klass->max_line_bytes = kMaxLineBytes;
  klass->read_chunk = gst_pfap_base_parse_read_lines;
  gobject_class->constructed = gst_pfap_base_parse_constructed;
  gobject_class->finalize = gst_pfap_base_parse_finalize;
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
  priv(parse)->text = new Text{};
}
