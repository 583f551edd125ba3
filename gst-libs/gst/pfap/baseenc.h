/* SPDX-License-Identifier: LGPL-2.1-or-later */
// GstPfapBaseEnc: the base class of the plugins' x-pfap writers (pfaptextenc, pfapfapenc,
// pfapmarksenc), which turn application/x-pfap events into text. As GstAudioEncoder does
// for its encoders, it holds the pads and the stream's frame: each buffer is read as an
// event and handed to handle_event, a malformed one dropped with a rate-limited warning
// (warning.h) and counted; the input caps set the src template's caps; a segment must be
// TIME and is kept; at EOS finish writes what is held, then EOS goes on; a flush or READY
// to PAUSED calls reset. gst_pfap_base_enc_place gives each event its running time by the
// writers' one rule (pfap::EventTimeline). A subclass adds pad templates "sink" and "src"
// and keeps only its writer and properties.
#pragma once

#include <gst/gst.h>

#include <cstdint>

#include "pfap/markup_event.h"

G_BEGIN_DECLS

#define GST_TYPE_PFAP_BASE_ENC (gst_pfap_base_enc_get_type())
G_DECLARE_DERIVABLE_TYPE(GstPfapBaseEnc, gst_pfap_base_enc, GST, PFAP_BASE_ENC, GstElement)

struct _GstPfapBaseEncClass {
  GstElementClass parent_class;

  // Writes `event`, read from `buffer` (the base unrefs it after). Required.
  GstFlowReturn (*handle_event)(GstPfapBaseEnc* enc, GstBuffer* buffer,
                                const pfap::MarkupEvent& event);
  // Takes what the subclass needs from the input caps. Optional.
  void (*set_caps)(GstPfapBaseEnc* enc, GstCaps* caps);
  // Given the TIME segment event just kept, returns the event to send downstream instead
  // (default: the same). Optional.
  GstEvent* (*output_segment)(GstPfapBaseEnc* enc, GstEvent* segment);
  // At EOS, before it goes on: writes what is held. Optional.
  void (*finish)(GstPfapBaseEnc* enc);
  // A new stream (READY to PAUSED, FLUSH_STOP). Optional.
  void (*reset)(GstPfapBaseEnc* enc);
  // The sink pad's events; a subclass may handle some and chain up for the rest.
  gboolean (*sink_event)(GstPfapBaseEnc* enc, GstEvent* event);
};

G_END_DECLS

// The pads, for the subclass.
GstPad* gst_pfap_base_enc_sinkpad(GstPfapBaseEnc* enc);
GstPad* gst_pfap_base_enc_srcpad(GstPfapBaseEnc* enc);

// The running time (ns) of `event`, read from a buffer with `pts`: an event without a PTS
// starts where the one before it ended (the first where the segment begins); one earlier
// than the one before it is placed at that one's time, with a rate-limited warning.
int64_t gst_pfap_base_enc_place(GstPfapBaseEnc* enc, GstClockTime pts,
                                const pfap::MarkupEvent& event);

// Since READY to PAUSED (a flush keeps them): input buffers dropped as malformed, and events
// placed later than their time because they were earlier than the one before.
guint64 gst_pfap_base_enc_malformed(GstPfapBaseEnc* enc);
guint64 gst_pfap_base_enc_earlier(GstPfapBaseEnc* enc);
