// SPDX-License-Identifier: LGPL-2.1-or-later
// The example pipeline stays on one line, to be copied.
// clang-format off
/**
 * SECTION:element-pfaptextenc
 * @title: pfaptextenc
 * @see_also: pfaptextparse, rtppfapdepay
 *
 * Writes a phoneme / facial animation parameter (PFAP) stream as .pfap text, the format
 * pfaptextparse reads (pfap/text.h): each application/x-pfap buffer becomes one output buffer
 * holding its canonical line and a newline, with the input's PTS and duration. Written to a
 * file, the lines read back with pfaptextparse as the same phonemes, FAPs and state events.
 *
 * A line's time is the event's stream time, in ms rounded to the nearest: a file read by
 * pfaptextparse and written again keeps its times, and a received stream's times count from the
 * receiver's segment start (docs/elements.md, "Times in the files written").
 *
 * An event without a PTS starts where the previous one ended (a phoneme lasts its duration,
 * a state event none), the first one where the segment begins. An event earlier than the
 * one before it is written at that one's time, with a warning: the format wants times that
 * never go back. A malformed buffer is dropped with a warning and the stream goes on. Both
 * faults are counted in the stats property and warned about at their 1st, 2nd, 4th, 8th,
 * ... occurrence, so that a stream of them does not flood the bus.
 *
 * The format has no flag for an event the receiver is unsure of (its FAP state may be
 * incomplete after a loss): such a line ends with the comment `# uncertain`, which readers
 * skip. Sentence starts are not written either: the format implies them at the first
 * phoneme and after each end of text.
 *
 * ## Example pipeline
 * |[
 * gst-launch-1.0 udpsrc port=5004 caps="application/x-rtp,media=application,clock-rate=44100,encoding-name=PFAP" ! rtpjitterbuffer ! rtppfapdepay ! pfaptextenc ! filesink location=received.pfap
 * ]| Receives a PFAP stream on UDP port 5004 and writes it to received.pfap, which
 * `filesrc location=received.pfap ! pfaptextparse` reads back.
 */
// clang-format on
#include "gstpfaptextenc.h"

#include <cstdint>
#include <string>

#include "pfap/model.h"
#include "pfap/text.h"

GST_DEBUG_CATEGORY_STATIC(pfaptextenc_debug);
#define GST_CAT_DEFAULT pfaptextenc_debug

namespace {

// What the streaming thread keeps between buffers. GObject runs no C++ constructors, so it
// lives behind a pointer made in init and deleted in finalize.
struct Stream {
  // Reused for every buffer so that steady streaming does not allocate.
  pfap::TextEvent text;
  std::string line;
};

}  // namespace

struct _GstPfapTextEnc {
  GstPfapBaseEnc parent;
  Stream* stream;
};

static GstStaticPadTemplate sink_template = GST_STATIC_PAD_TEMPLATE(
    "sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(PFAP_MARKUP_CAPS));

static GstStaticPadTemplate src_template = GST_STATIC_PAD_TEMPLATE(
    "src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS("text/x-raw, format = (string) utf8"));

G_DEFINE_TYPE(GstPfapTextEnc, gst_pfap_text_enc, GST_TYPE_PFAP_BASE_ENC)
GST_ELEMENT_REGISTER_DEFINE(pfaptextenc, "pfaptextenc", GST_RANK_NONE, GST_TYPE_PFAP_TEXT_ENC)

static GstFlowReturn gst_pfap_text_enc_handle_event(GstPfapBaseEnc* enc, GstBuffer* buffer,
                                                    const pfap::MarkupEvent& event,
                                                    int64_t time_ns) {
  GstPfapTextEnc* self = GST_PFAP_TEXT_ENC(enc);
  Stream& s = *self->stream;
  s.text.event = event;
  s.text.time_ms = (time_ns + pfap::kNsPerMs / 2) / pfap::kNsPerMs;
  s.line.clear();
  pfap::format_text_line(s.text, s.line);
  // The format has no flag for it; a comment tells the reader and pfaptextparse skips it.
  if (s.text.event.uncertain) s.line += " # uncertain";
  GST_LOG_OBJECT(self, "%s", s.line.c_str());
  s.line += '\n';

  GstBuffer* out = gst_buffer_new_memdup(s.line.data(), s.line.size());
  GST_BUFFER_PTS(out) = GST_BUFFER_PTS(buffer);
  GST_BUFFER_DURATION(out) = GST_BUFFER_DURATION(buffer);
  if (GST_BUFFER_IS_DISCONT(buffer)) GST_BUFFER_FLAG_SET(out, GST_BUFFER_FLAG_DISCONT);
  return gst_pfap_base_enc_push(enc, out);
}

static void gst_pfap_text_enc_finalize(GObject* object) {
  delete GST_PFAP_TEXT_ENC(object)->stream;
  G_OBJECT_CLASS(gst_pfap_text_enc_parent_class)->finalize(object);
}

static void gst_pfap_text_enc_class_init(GstPfapTextEncClass* klass) {
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstPfapBaseEncClass* enc_class = GST_PFAP_BASE_ENC_CLASS(klass);

  GST_DEBUG_CATEGORY_INIT(pfaptextenc_debug, "pfaptextenc", 0, "PFAP text writer");

  gobject_class->finalize = gst_pfap_text_enc_finalize;

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_set_static_metadata(
      element_class, "PFAP text encoder", "Codec/Encoder/Text",
      "Writes phoneme and facial animation parameter (PFAP) streams as .pfap text, one line "
      "per event",
      "gst-pfap developers");

  enc_class->handle_event = gst_pfap_text_enc_handle_event;
}

static void gst_pfap_text_enc_init(GstPfapTextEnc* self) { self->stream = new Stream{}; }
