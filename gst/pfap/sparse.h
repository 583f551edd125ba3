/* SPDX-License-Identifier: LGPL-2.1-or-later */
// The sparse stream flag that the plugins' x-pfap outputs carry.
#pragma once

#include <gst/gst.h>

// `event`, a stream-start, with the sparse flag. Phonemes come only while someone speaks:
// sparse tells queues, muxers and aggregators downstream not to wait for our data.
inline GstEvent* pfap_make_sparse(GstEvent* event) {
  event = gst_event_make_writable(event);
  GstStreamFlags flags;
  gst_event_parse_stream_flags(event, &flags);
  gst_event_set_stream_flags(event, static_cast<GstStreamFlags>(flags | GST_STREAM_FLAG_SPARSE));
  return event;
}
