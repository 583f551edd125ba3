/* SPDX-License-Identifier: LGPL-2.1-or-later */
// GstPfapBaseParse: the base class of the plugins' text parsers (pfapparse, fapparse,
// pfapmarksparse), which read text from any chunks and output application/x-pfap events in a
// TIME segment from 0, the times coming from the text. As GstBaseParse does for its
// parsers, it holds the pads and the stream's frame: each buffer is mapped and handed to
// read_chunk, a UTF-8 byte order mark at the start of the text left out; the upstream
// stream-start goes on sparse (sparse.h); upstream caps, segments and gaps are dropped; at EOS
// finish reads what is left, then the output's first events go if no buffer sent them, then
// EOS; a flush or READY to PAUSED calls reset. The output cannot seek (noseek.h). The `stats`
// property counts the events output and the bad lines skipped for every parser. A subclass
// adds pad templates "sink" and "src" and keeps only its reader and properties.
#pragma once

#include <gst/gst.h>

#include <string_view>

#include "pfap/text.h"

G_BEGIN_DECLS

#define GST_TYPE_PFAP_BASE_PARSE (gst_pfap_base_parse_get_type())
G_DECLARE_DERIVABLE_TYPE(GstPfapBaseParse, gst_pfap_base_parse, GST, PFAP_BASE_PARSE, GstElement)

struct _GstPfapBaseParseClass {
  GstElementClass parent_class;

  // Reads the next bytes of the text. Required.
  GstFlowReturn (*read_chunk)(GstPfapBaseParse* parse, std::string_view data);
  // At EOS: reads what is left. GST_FLOW_ERROR (the error posted) drops the EOS;
  // GST_PFAP_BASE_PARSE_FLOW_EOS_HELD says the subclass sends EOS itself later. Optional.
  GstFlowReturn (*finish)(GstPfapBaseParse* parse);
  // Back to the start of a stream (READY to PAUSED, FLUSH_STOP). Optional.
  void (*reset)(GstPfapBaseParse* parse);
  // The output caps, sent before the first buffer when the pad has none. Optional: the src
  // template's.
  GstCaps* (*output_caps)(GstPfapBaseParse* parse);
};

// From finish: the EOS is taken; the subclass pushes it once it has more to send first.
#define GST_PFAP_BASE_PARSE_FLOW_EOS_HELD GST_FLOW_CUSTOM_SUCCESS

G_END_DECLS

// The pads, for the subclass.
GstPad* gst_pfap_base_parse_sinkpad(GstPfapBaseParse* parse);
GstPad* gst_pfap_base_parse_srcpad(GstPfapBaseParse* parse);

// Sends the output's stream-start (if upstream sent none), caps and TIME segment from 0, once
// per stream; pushing a buffer does it too.
void gst_pfap_base_parse_start_output(GstPfapBaseParse* parse);

// Counts a bad line skipped (stats: bad-lines); returns the count since READY to PAUSED.
guint64 gst_pfap_base_parse_count_bad_line(GstPfapBaseParse* parse);
// The bad lines skipped since READY to PAUSED.
guint64 gst_pfap_base_parse_bad_lines(GstPfapBaseParse* parse);

// Pushes `event` as an x-pfap buffer at its time from the start of the text (a phoneme
// lasting its duration), the first after a start or flush DISCONT.
GstFlowReturn gst_pfap_base_parse_push(GstPfapBaseParse* parse, const pfap::TextEvent& event);
