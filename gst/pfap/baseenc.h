/* SPDX-License-Identifier: LGPL-2.1-or-later */
// GstPfapBaseEnc: the base class of the plugins' x-pfap writers (pfaptextenc, pfapfapenc,
// pfapmarksenc), which turn application/x-pfap events into text. As GstAudioEncoder does
// for its encoders, it holds the pads and the stream's frame: each buffer is read as an
// event and handed to handle_event, a malformed one dropped with a rate-limited warning
// (warning.h) and counted; the input caps set the src template's caps; a segment must be
// TIME and is kept; at EOS finish writes what is held, then EOS goes on; a flush or READY
// to PAUSED calls reset. Each event gets its time in the file by the writers' one rule: its
// running time placed by pfap::EventTimeline, as stream time of the stream's first segment
// (a file read by the readers keeps its times; docs/elements.md). A writer that holds an event
// (writes it later) lets downstream preroll and sync all the same: the base sends a GAP event for
// it. The `stats` property counts for every writer. A subclass adds pad templates "sink" and "src"
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

  // Writes `event`, read from `buffer` (the base unrefs it after), at `time_ns` in the file
  // (never negative, never earlier than the event before). Output goes through
  // gst_pfap_base_enc_push. Required.
  GstFlowReturn (*handle_event)(GstPfapBaseEnc* enc, GstBuffer* buffer,
                                const pfap::MarkupEvent& event, int64_t time_ns);
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

// Pushes output on the src pad: what the subclass writes goes through here, so that the base
// knows which events it held.
GstFlowReturn gst_pfap_base_enc_push(GstPfapBaseEnc* enc, GstBuffer* buffer);
