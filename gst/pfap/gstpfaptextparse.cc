// SPDX-License-Identifier: LGPL-2.1-or-later
// The example pipelines stay on one line, to be copied.
// clang-format off
/**
 * SECTION:element-pfaptextparse
 * @title: pfaptextparse
 * @see_also: pfaptextenc, rtppfappay
 *
 * Reads the .pfap text format (docs/text-format.md: UTF-8, one phoneme or FAP state event per
 * line) and outputs one application/x-pfap buffer per event, laid out as pfap/markup.h
 * describes. A buffer's PTS is the time on its line, counted from the start of the stream;
 * a phoneme's DURATION is its duration, a state event has none. The first phoneme and the
 * one after an end of text (flag E) have the SENTENCE_START flag; the first buffer after a
 * start or flush is DISCONT. The output is a TIME segment from 0, so a sink with sync=true
 * plays the events in real time. Upstream segments and gaps are dropped: the times come from
 * the text.
 *
 * The input may come in any chunks (filesrc's 4096-byte blocks, or a byte at a time); lines
 * end at '\n' or "\r\n", and a last line without one is read at EOS. Blank and comment
 * lines give nothing.
 *
 * A bad line (a field that does not parse, time going back, bad bookmarks, invalid UTF-8,
 * more than 65536 bytes without its line end, or a time past about 292 years) is an error
 * naming its line, its column (in bytes, from 1) and what is wrong, and nothing after it is
 * read; with #GstPfapTextParse:skip-bad-lines it is a warning instead (at the 1st, 2nd, 4th, ...
 * bad line, all counted in the stats property's bad-lines), and the lines after it are read
 * as usual. Input
 * that arrives from sources without caps (filesrc, fdsrc) is taken as .pfap text; caps, when
 * given, must be text/x-pfap (the typefinder's, for decodebin) or text/x-raw,format=utf8.
 *
 * Seeking is not supported: the text must be read from its start, as times and sentence
 * starts depend on the lines before. A flush starts the text anew: the next line is line 1,
 * may be earlier than the lines before, and its phoneme starts a sentence.
 *
 * ## Example pipelines
 * |[
 * gst-launch-1.0 filesrc location=docs/examples/hello.pfap ! pfaptextparse ! rtppfappay ! udpsink host=127.0.0.1 port=5004
 * ]| Sends the phonemes and FAPs of hello.pfap as PFAP RTP packets to port 5004, in real time.
 * |[
 * cat docs/examples/hello.pfap | gst-launch-1.0 fdsrc ! pfaptextparse skip-bad-lines=true ! fakesink dump=true
 * ]| Reads .pfap text from standard input, warns about bad lines and dumps each event.
 */
// clang-format on
#include "gstpfaptextparse.h"

#include <string>
#include <string_view>

#include "gstpfaptypefind.h"
#include "markupbuffer.h"
#include "pfap/model.h"
#include "pfap/text.h"

GST_DEBUG_CATEGORY_STATIC(pfapparse_debug);
#define GST_CAT_DEFAULT pfapparse_debug

namespace {

enum { PROP_0, PROP_SKIP_BAD_LINES, PROP_ALPHABET, PROP_BAD_LINES };

}  // namespace

struct _GstPfapTextParse {
  GstPfapBaseParse parent;
  gchar* alphabet;  // under the object lock; NULL when unset
  // The streaming thread's. GObject runs no C++ constructors, so it lives behind a pointer
  // made in init and deleted in finalize.
  pfap::TextReader* reader;
};

// No caps from filesrc and fdsrc: the template only matters to sources that send caps.
// Not text/plain: decodebin would plug the parser into every text file it meets; the
// typefinder gives .pfap text its own type.
static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS,
                            GST_STATIC_CAPS(PFAP_TEXT_CAPS "; text/x-raw, format = (string) utf8"));

static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

G_DEFINE_TYPE(GstPfapTextParse, gst_pfap_text_parse, GST_TYPE_PFAP_BASE_PARSE)
// A rank, so that decodebin plugs it for text/x-pfap (gst-play-1.0 file.pfap).
GST_ELEMENT_REGISTER_DEFINE(pfaptextparse, "pfaptextparse", GST_RANK_SECONDARY,
                            GST_TYPE_PFAP_TEXT_PARSE)

// Back to the start of a stream (READY to PAUSED, FLUSH_STOP).
static void gst_pfap_text_parse_reset(GstPfapBaseParse* parse) {
  GST_PFAP_TEXT_PARSE(parse)->reader->reset();
}

static GstCaps* gst_pfap_text_parse_output_caps(GstPfapBaseParse* parse) {
  GstPfapTextParse* self = GST_PFAP_TEXT_PARSE(parse);
  GstCaps* caps = gst_static_pad_template_get_caps(&src_template);
  GST_OBJECT_LOCK(self);
  if (self->alphabet != nullptr) {
    caps = gst_caps_make_writable(caps);
    gst_caps_set_simple(caps, "alphabet", G_TYPE_STRING, self->alphabet, nullptr);
  }
  GST_OBJECT_UNLOCK(self);
  return caps;
}

static GstFlowReturn gst_pfap_text_parse_read_line(GstPfapBaseParse* parse, std::string_view line) {
  const gchar* valid_end = nullptr;
  if (!g_utf8_validate(line.data(), static_cast<gssize>(line.size()), &valid_end)) {
    return gst_pfap_base_parse_bad_line(parse, static_cast<size_t>(valid_end - line.data()),
                                        "not UTF-8");
  }
  pfap::TextEvent event;
  bool has_event = false;
  const pfap::TextResult result =
      GST_PFAP_TEXT_PARSE(parse)->reader->read_line(line, event, has_event);
  if (!result.ok()) {
    std::string what = pfap::to_string(result.status);
    if (result.status == pfap::TextStatus::kBadBookmark) {
      what.append(": ").append(pfap::to_string(result.bookmark));
    }
    return gst_pfap_base_parse_bad_line(parse, result.column, what);
  }
  return has_event ? gst_pfap_base_parse_push(parse, event) : GST_FLOW_OK;
}

static void gst_pfap_text_parse_set_property(GObject* object, guint prop_id, const GValue* value,
                                             GParamSpec* pspec) {
  GstPfapTextParse* self = GST_PFAP_TEXT_PARSE(object);
  switch (prop_id) {
    case PROP_SKIP_BAD_LINES:
      gst_pfap_base_parse_set_skip_bad_lines(GST_PFAP_BASE_PARSE(self), g_value_get_boolean(value));
      break;
    case PROP_ALPHABET:
      GST_OBJECT_LOCK(self);
      g_free(self->alphabet);
      self->alphabet = g_value_dup_string(value);
      GST_OBJECT_UNLOCK(self);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
}

static void gst_pfap_text_parse_get_property(GObject* object, guint prop_id, GValue* value,
                                             GParamSpec* pspec) {
  GstPfapTextParse* self = GST_PFAP_TEXT_PARSE(object);
  switch (prop_id) {
    case PROP_SKIP_BAD_LINES:
      g_value_set_boolean(value, gst_pfap_base_parse_skips_bad_lines(GST_PFAP_BASE_PARSE(self)));
      break;
    case PROP_ALPHABET:
      GST_OBJECT_LOCK(self);
      g_value_set_string(value, self->alphabet);
      GST_OBJECT_UNLOCK(self);
      break;
    case PROP_BAD_LINES:
      g_value_set_uint64(value, gst_pfap_base_parse_bad_lines(GST_PFAP_BASE_PARSE(self)));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
      break;
  }
}

static void gst_pfap_text_parse_finalize(GObject* object) {
  delete GST_PFAP_TEXT_PARSE(object)->reader;
  g_free(GST_PFAP_TEXT_PARSE(object)->alphabet);
  G_OBJECT_CLASS(gst_pfap_text_parse_parent_class)->finalize(object);
}

static void gst_pfap_text_parse_class_init(GstPfapTextParseClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstPfapBaseParseClass* parse_class = GST_PFAP_BASE_PARSE_CLASS(klass);

  GST_DEBUG_CATEGORY_INIT(pfapparse_debug, "pfaptextparse", 0, "PFAP text parser");

  gobject_class->set_property = gst_pfap_text_parse_set_property;
  gobject_class->get_property = gst_pfap_text_parse_get_property;
  gobject_class->finalize = gst_pfap_text_parse_finalize;

  /**
   * GstPfapTextParse:skip-bad-lines:
   *
   * What a bad line does: FALSE (the default) posts an error and stops the stream; TRUE
   * posts a warning naming the line and what is wrong with it (at the 1st, 2nd, 4th, 8th,
   * ... bad line only), drops the line and reads on.
   */
  g_object_class_install_property(gobject_class, PROP_SKIP_BAD_LINES,
                                  gst_pfap_base_parse_skip_bad_lines_spec());

  /**
   * GstPfapTextParse:alphabet:
   *
   * The name of the phoneme alphabet the file's symbol numbers come from (a .pfap file holds
   * numbers only). Set, it becomes the `alphabet` field of the output caps, which
   * rtppfappay carries to the SDP as an fmtp parameter.
   */
  g_object_class_install_property(
      gobject_class, PROP_ALPHABET,
      g_param_spec_string("alphabet", "Phoneme alphabet",
                          "Name of the phoneme alphabet of the symbol numbers, for the caps "
                          "and SDP (unset: none)",
                          nullptr,
                          static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                   GST_PARAM_MUTABLE_READY)));

  /**
   * GstPfapTextParse:bad-lines:
   *
   * The bad lines skipped (#GstPfapTextParse:skip-bad-lines) since the element last went from
   * READY to PAUSED: the bad-lines field of the stats property, which every parser has.
   *
   * Deprecated: read bad-lines in the stats property.
   */
  g_object_class_install_property(
      gobject_class, PROP_BAD_LINES,
      g_param_spec_uint64("bad-lines", "Bad lines",
                          "Bad lines skipped since READY to PAUSED (deprecated: the stats "
                          "property's bad-lines)",
                          0, G_MAXUINT64, 0,
                          static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS |
                                                   G_PARAM_DEPRECATED)));

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_set_static_metadata(
      element_class, "PFAP text parser", "Codec/Parser/Text",
      "Reads phonemes and facial animation parameters (PFAP) from .pfap text as "
      "application/x-pfap events",
      "gst-pfap developers");

  parse_class->line_name = ".pfap line";
  parse_class->read_line = gst_pfap_text_parse_read_line;
  parse_class->reset = gst_pfap_text_parse_reset;
  parse_class->output_caps = gst_pfap_text_parse_output_caps;
}

static void gst_pfap_text_parse_init(GstPfapTextParse* self) {
  self->alphabet = nullptr;
  self->reader = new pfap::TextReader{};
}
