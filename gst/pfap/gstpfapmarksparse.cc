// SPDX-License-Identifier: LGPL-2.1-or-later
// The example pipelines stay on one line, to be copied.
// clang-format off
/**
 * SECTION:element-pfapmarksparse
 * @title: pfapmarksparse
 * @see_also: pfapmarksenc, pfaptextparse, rtppfappay
 *
 * Reads the visemes of a TTS service or lip-sync tool and outputs them as application/x-pfap
 * phoneme events, so that a stream from a service we do not run becomes PFAP
 * (docs/visemes.md). #GstPfapMarksParse:format says what comes in:
 *
 * - `polly`: Amazon Polly speech marks (JSON lines); word and sentence marks become the
 *   word-begin, sentence-start and end-of-text flags, ssml marks are skipped;
 * - `rhubarb`: Rhubarb Lip Sync output, TSV lines or (when the input starts with '{') its JSON
 *   document, read whole at EOS;
 * - `azure`: Azure Speech viseme events as JSON lines of `audioOffset` (100 ns ticks) and
 *   `visemeId` (also the C# and Python spellings AudioOffset/VisemeId, audio_offset/viseme_id).
 *
 * Each viseme becomes a phoneme of an alphabet that says what it is, set as the `alphabet`
 * field of the output caps: x-pfap-polly-viseme, x-pfap-rhubarb-shape or x-pfap-azure-viseme
 * (pfapface and pfapmarksenc know them; rtppfappay carries the name to the SDP). A viseme
 * lasts until the next one; the last one (with no end given) lasts 150 ms. A PTS is the
 * viseme's time from the start of the input. The output is a TIME segment from 0.
 *
 * A bad line (not JSON, a missing field, an unknown viseme, time going back, more than 64 KiB)
 * is an error naming its line, its column (bytes, from 1), the file when upstream reads one,
 * and what is wrong; with #GstPfapMarksParse:skip-bad-lines it is a warning (rate-limited: the
 * 1st, 2nd, 4th, ...) and reading goes on. In a Rhubarb JSON document the bad item is a cue: skipped, every other cue
 * is kept (the time it held is a rest); a document past 16 MiB is one bad item. A UTF-8 byte
 * order mark at the start of the input is skipped.
 *
 * ## Example pipeline
 * |[
 * gst-launch-1.0 filesrc location=docs/examples/marks/hello.polly.jsonl ! pfapmarksparse format=polly ! rtppfappay ! udpsink host=127.0.0.1 port=5004
 * ]| Sends the visemes of Polly speech marks as a PFAP RTP stream.
 */
// clang-format on
#include "gstpfapmarksparse.h"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "markupbuffer.h"
#include "pfap/speech_marks.h"

GST_DEBUG_CATEGORY_STATIC(pfapmarksparse_debug);
#define GST_CAT_DEFAULT pfapmarksparse_debug

namespace {

enum { PROP_0, PROP_FORMAT, PROP_SKIP_BAD_LINES };

constexpr pfap::MarksInput kDefaultFormat = pfap::MarksInput::kPolly;

struct Stream {
  explicit Stream(pfap::MarksInput input) : reader(input) {}

  pfap::MarksReader reader;
  std::string text;        // Rhubarb JSON: the document so far
  bool started = false;    // the first non-blank byte has been seen
  bool document = false;   // Rhubarb JSON: the input is kept whole until EOS
  bool oversized = false;  // the document grew past its limit: one bad item, the rest dropped
  std::vector<pfap::TextEvent> events;
};

}  // namespace

struct _GstPfapMarksParse {
  GstPfapBaseParse parent;
  pfap::MarksInput format;  // under the object lock
  Stream* stream;
};

static GstStaticPadTemplate sink_template = GST_STATIC_PAD_TEMPLATE(
    "sink", GST_PAD_SINK, GST_PAD_ALWAYS,
    GST_STATIC_CAPS("text/x-raw, format = (string) utf8; text/plain; application/json"));

static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

G_DEFINE_TYPE(GstPfapMarksParse, gst_pfap_marks_parse, GST_TYPE_PFAP_BASE_PARSE)
GST_ELEMENT_REGISTER_DEFINE(pfapmarksparse, "pfapmarksparse", GST_RANK_NONE,
                            GST_TYPE_PFAP_MARKS_PARSE)

#define GST_TYPE_PFAP_MARKS_INPUT (gst_pfap_marks_input_get_type())
static GType gst_pfap_marks_input_get_type() {
  static GType type = 0;
  static const GEnumValue values[] = {
      {int(pfap::MarksInput::kPolly), "Amazon Polly speech marks (JSON lines)", "polly"},
      {int(pfap::MarksInput::kRhubarb), "Rhubarb Lip Sync TSV or JSON", "rhubarb"},
      {int(pfap::MarksInput::kAzure), "Azure viseme events (JSON lines, 100 ns ticks)", "azure"},
      {0, nullptr, nullptr},
  };
  if (g_once_init_enter(&type)) {
    g_once_init_leave(&type, g_enum_register_static("GstPfapMarksInput", values));
  }
  return type;
}

// A new stream from the properties (READY to PAUSED, FLUSH_STOP).
static void gst_pfap_marks_parse_reset(GstPfapBaseParse* parse) {
  GstPfapMarksParse* self = GST_PFAP_MARKS_PARSE(parse);
  GST_OBJECT_LOCK(self);
  const pfap::MarksInput format = self->format;
  GST_OBJECT_UNLOCK(self);
  delete self->stream;
  self->stream = new Stream(format);
}

static GstCaps* gst_pfap_marks_parse_output_caps(GstPfapBaseParse* parse) {
  GstCaps* caps = gst_caps_make_writable(gst_static_pad_template_get_caps(&src_template));
  const std::string alphabet(GST_PFAP_MARKS_PARSE(parse)->stream->reader.alphabet());
  gst_caps_set_simple(caps, "alphabet", G_TYPE_STRING, alphabet.c_str(), nullptr);
  return caps;
}

static GstFlowReturn push_events(GstPfapMarksParse* self) {
  Stream& s = *self->stream;
  GstFlowReturn ret = GST_FLOW_OK;
  for (const pfap::TextEvent& event : s.events) {
    ret = gst_pfap_base_parse_push(GST_PFAP_BASE_PARSE(self), event);
    if (ret != GST_FLOW_OK) break;
  }
  s.events.clear();
  return ret;
}

// A bad part of a Rhubarb JSON document: `cue` one of its cues, else the whole document.
static GstFlowReturn bad_document(GstPfapMarksParse* self, size_t column, const std::string& what,
                                  bool cue = false) {
  return gst_pfap_base_parse_bad_item(
      GST_PFAP_BASE_PARSE(self), cue ? "cue of Rhubarb JSON document 1" : "Rhubarb JSON document 1",
      column, what);
}

static std::string describe(const pfap::MarksResult& result) {
  std::string what = pfap::to_string(result.status);
  if (result.status == pfap::MarksStatus::kBadJson) what.append(": ").append(result.what);
  return what;
}

static GstFlowReturn gst_pfap_marks_parse_read_line(GstPfapBaseParse* parse,
                                                    std::string_view line) {
  GstPfapMarksParse* self = GST_PFAP_MARKS_PARSE(parse);
  Stream& s = *self->stream;
  const pfap::MarksResult result = s.reader.read_line(line, s.events);
  if (!result.ok()) return gst_pfap_base_parse_bad_line(parse, result.column, describe(result));
  return push_events(self);
}

// Lines, but for a Rhubarb JSON document, which is kept whole to be read at EOS.
static GstFlowReturn gst_pfap_marks_parse_read_chunk(GstPfapBaseParse* parse,
                                                     std::string_view data) {
  GstPfapMarksParse* self = GST_PFAP_MARKS_PARSE(parse);
  Stream& s = *self->stream;
  if (!s.started) {
    const size_t first = data.find_first_not_of(" \t\r\n");
    // Blank lines still count (a document's are only white space before it).
    if (first == std::string_view::npos) return gst_pfap_base_parse_read_lines(parse, data);
    s.started = true;
    s.document = data[first] == '{' && s.reader.alphabet() == pfap::kRhubarbShapeAlphabet;
  }
  if (!s.document) return gst_pfap_base_parse_read_lines(parse, data);
  if (s.oversized) return GST_FLOW_OK;
  if (s.text.size() + data.size() > pfap::MarksReader::kMaxDocumentBytes) {
    s.oversized = true;
    s.text.clear();
    return bad_document(self, pfap::MarksReader::kMaxDocumentBytes, "larger than 16 MiB");
  }
  s.text.append(data);
  return GST_FLOW_OK;
}

// At EOS, after the last line: the whole Rhubarb document, or the last viseme.
static GstFlowReturn gst_pfap_marks_parse_finish(GstPfapBaseParse* parse) {
  GstPfapMarksParse* self = GST_PFAP_MARKS_PARSE(parse);
  Stream& s = *self->stream;
  if (!s.document) {
    s.reader.finish(s.events);
    return push_events(self);
  }
  if (s.oversized) return GST_FLOW_OK;
  const bool skip = gst_pfap_base_parse_skips_bad_lines(parse);
  // A bad cue is skipped with a warning, or stops the document after the cues before it.
  const pfap::MarksResult result =
      s.reader.read_document(s.text, s.events, [&](const pfap::MarksResult& bad) {
        if (skip) bad_document(self, bad.column, describe(bad), true);
        return skip;
      });
  s.text.clear();
  const GstFlowReturn ret = push_events(self);
  if (!result.ok() && ret == GST_FLOW_OK)
    return bad_document(self, result.column, describe(result));
  return ret;
}

static void gst_pfap_marks_parse_set_property(GObject* object, guint prop_id, const GValue* value,
                                              GParamSpec* pspec) {
  GstPfapMarksParse* self = GST_PFAP_MARKS_PARSE(object);
  switch (prop_id) {
    case PROP_FORMAT:
      GST_OBJECT_LOCK(self);
      self->format = static_cast<pfap::MarksInput>(g_value_get_enum(value));
      GST_OBJECT_UNLOCK(self);
      break;
    case PROP_SKIP_BAD_LINES:
      gst_pfap_base_parse_set_skip_bad_lines(GST_PFAP_BASE_PARSE(self), g_value_get_boolean(value));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
}

static void gst_pfap_marks_parse_get_property(GObject* object, guint prop_id, GValue* value,
                                              GParamSpec* pspec) {
  GstPfapMarksParse* self = GST_PFAP_MARKS_PARSE(object);
  switch (prop_id) {
    case PROP_FORMAT:
      GST_OBJECT_LOCK(self);
      g_value_set_enum(value, static_cast<int>(self->format));
      GST_OBJECT_UNLOCK(self);
      break;
    case PROP_SKIP_BAD_LINES:
      g_value_set_boolean(value, gst_pfap_base_parse_skips_bad_lines(GST_PFAP_BASE_PARSE(self)));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
}

static void gst_pfap_marks_parse_finalize(GObject* object) {
  delete GST_PFAP_MARKS_PARSE(object)->stream;
  G_OBJECT_CLASS(gst_pfap_marks_parse_parent_class)->finalize(object);
}

static void gst_pfap_marks_parse_class_init(GstPfapMarksParseClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstPfapBaseParseClass* parse_class = GST_PFAP_BASE_PARSE_CLASS(klass);

  GST_DEBUG_CATEGORY_INIT(pfapmarksparse_debug, "pfapmarksparse", 0, "PFAP speech-mark reader");

  gobject_class->set_property = gst_pfap_marks_parse_set_property;
  gobject_class->get_property = gst_pfap_marks_parse_get_property;
  gobject_class->finalize = gst_pfap_marks_parse_finalize;

  /**
   * GstPfapMarksParse:format:
   *
   * What the input is; it sets the output's alphabet. Read when going to PAUSED.
   */
  g_object_class_install_property(
      gobject_class, PROP_FORMAT,
      g_param_spec_enum("format", "Format", "The speech-mark format of the input",
                        GST_TYPE_PFAP_MARKS_INPUT, static_cast<int>(kDefaultFormat),
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_READY)));
  /**
   * GstPfapMarksParse:skip-bad-lines:
   *
   * FALSE (the default): a bad line is an error that stops the stream; TRUE: a warning, the
   * line is dropped and reading goes on.
   */
  g_object_class_install_property(gobject_class, PROP_SKIP_BAD_LINES,
                                  gst_pfap_base_parse_skip_bad_lines_spec());

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_set_static_metadata(
      element_class, "PFAP speech-mark parser", "Codec/Parser/Text",
      "Reads Polly speech marks, Rhubarb mouth cues or Azure viseme events as "
      "application/x-pfap viseme events",
      "gst-pfap developers");

  parse_class->read_line = gst_pfap_marks_parse_read_line;
  parse_class->read_chunk = gst_pfap_marks_parse_read_chunk;
  parse_class->finish = gst_pfap_marks_parse_finish;
  parse_class->reset = gst_pfap_marks_parse_reset;
  parse_class->output_caps = gst_pfap_marks_parse_output_caps;
  gst_type_mark_as_plugin_api(GST_TYPE_PFAP_MARKS_INPUT, static_cast<GstPluginAPIFlags>(0));
}

static void gst_pfap_marks_parse_init(GstPfapMarksParse* self) {
  self->format = kDefaultFormat;
  self->stream = nullptr;
  gst_pfap_marks_parse_reset(GST_PFAP_BASE_PARSE(self));
}
