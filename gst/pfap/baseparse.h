/* SPDX-License-Identifier: LGPL-2.1-or-later */
// GstPfapBaseParse: the base class of the plugins' text parsers (pfapparse, fapparse,
// pfapmarksparse), which read text from any chunks and output application/x-pfap events in a
// TIME segment from 0, the times coming from the text. As GstBaseParse does for its
// parsers, it holds the pads and the stream's frame: each buffer is mapped, a UTF-8 byte
// order mark at the start of the text left out, and the text split into lines for read_line
// (a last line without a line end is read at EOS); the upstream stream-start goes on sparse
// (sparse.h); upstream caps, segments and gaps are dropped; at EOS finish reads what is left,
// then the output's first events go if no buffer sent them, then EOS; a flush or READY to
// PAUSED calls reset. A bad line is an error, or with skip-bad-lines a warning, and reading
// goes on (gst_pfap_base_parse_bad_line); after an error the rest of the stream is dropped.
// The output cannot seek (noseek.h). The `stats` property counts the events output and the
// bad lines skipped for every parser. A subclass adds pad templates "sink" and "src" and
// keeps only its reader and properties.
#pragma once

#include <gst/gst.h>

#include <string>
#include <string_view>

#include "pfap/text.h"

G_BEGIN_DECLS

#define GST_TYPE_PFAP_BASE_PARSE (gst_pfap_base_parse_get_type())
G_DECLARE_DERIVABLE_TYPE(GstPfapBaseParse, gst_pfap_base_parse, GST, PFAP_BASE_PARSE, GstElement)

struct _GstPfapBaseParseClass {
  GstElementClass parent_class;

  // What a line is called in messages: "line" by default.
  const gchar* line_name;
  // The longest line read, its line end ("\n" or "\r\n") not counted: 64 KiB by default. A
  // longer one is not kept: it is a bad line as soon as it grows past this.
  gsize max_line_bytes;

  // Reads one line of the text, without its line end. A line that cannot be read is
  // reported with gst_pfap_base_parse_bad_line. Required, unless read_chunk reads the text.
  GstFlowReturn (*read_line)(GstPfapBaseParse* parse, std::string_view line);
  // Reads the next bytes of the text. Optional: gst_pfap_base_parse_read_lines by default,
  // which a subclass that reads some texts whole calls for the others.
  GstFlowReturn (*read_chunk)(GstPfapBaseParse* parse, std::string_view data);
  // A line grew past max_line_bytes. Optional: a bad line "longer than N bytes" by default.
  GstFlowReturn (*line_too_long)(GstPfapBaseParse* parse);
  // At EOS, after the last line: reads what is left. GST_FLOW_ERROR (the error posted) drops
  // the EOS; GST_PFAP_BASE_PARSE_FLOW_EOS_HELD says the subclass sends EOS itself later.
  // Optional.
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

// Splits `data` into lines for read_line, completing the line kept from the chunks before.
GstFlowReturn gst_pfap_base_parse_read_lines(GstPfapBaseParse* parse, std::string_view data);

// A line that cannot be read, `column` bytes into it (from 0), `what` saying why. Without
// skip-bad-lines: an error naming the line (by its number from 1), the column and the source
// file, and GST_FLOW_ERROR. With it: counted (stats: bad-lines), a warning at the 1st, 2nd,
// 4th, ... one, and GST_FLOW_OK: reading goes on.
GstFlowReturn gst_pfap_base_parse_bad_line(GstPfapBaseParse* parse, gsize column,
                                           const std::string& what);
// The same for a bad part of the text named otherwise than as a line: `item` is its name
// ("Rhubarb JSON document 1").
GstFlowReturn gst_pfap_base_parse_bad_item(GstPfapBaseParse* parse, const std::string& item,
                                           gsize column, const std::string& what);

// The skip-bad-lines property of the subclasses that can skip a bad line: its spec, which
// the subclass installs (documenting it), and its value, which the subclass sets and gets.
GParamSpec* gst_pfap_base_parse_skip_bad_lines_spec();
gboolean gst_pfap_base_parse_skips_bad_lines(GstPfapBaseParse* parse);
void gst_pfap_base_parse_set_skip_bad_lines(GstPfapBaseParse* parse, gboolean skip);
// The bad lines skipped since READY to PAUSED.
guint64 gst_pfap_base_parse_bad_lines(GstPfapBaseParse* parse);

// Where the text comes from, for messages, asked upstream once per stream: the file's name
// when upstream reads a file (filesrc answers the URI query), else the URI, else empty
// (appsrc, fdsrc). `is_file` says which of the first two.
const std::string& gst_pfap_base_parse_source(GstPfapBaseParse* parse, bool* is_file = nullptr);

// Sends the output's stream-start (if upstream sent none), caps and TIME segment from 0, once
// per stream; pushing a buffer does it too.
void gst_pfap_base_parse_start_output(GstPfapBaseParse* parse);

// Pushes `event` as an x-pfap buffer at its time from the start of the text (a phoneme
// lasting its duration), the first after a start or flush DISCONT.
GstFlowReturn gst_pfap_base_parse_push(GstPfapBaseParse* parse, const pfap::TextEvent& event);
