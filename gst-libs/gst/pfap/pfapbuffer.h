// application/x-pfap GstBuffers from and to pfap::MarkupEvent, for the plugin's elements and
// their tests, and small helpers the elements share. Header-only so tests need not link the
// plugin.
#pragma once

#include <gst/gst.h>

#include "pfap/markup_event.h"

// A buffer holding `event`, or NULL when the event has a value out of range.
inline GstBuffer* pfap_buffer_new(const pfap::MarkupEvent& event) {
  const size_t size = pfap::markup_size(event);
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, size, nullptr);
  GstMapInfo map;
  gst_buffer_map(buffer, &map, GST_MAP_WRITE);
  const bool ok = pfap::write_markup(event, {map.data, map.size});
  gst_buffer_unmap(buffer, &map);
  if (!ok) gst_clear_buffer(&buffer);
  return buffer;
}

// Reads the event in `buffer`; false when it is not a valid x-pfap event.
inline bool pfap_buffer_read(GstBuffer* buffer, pfap::MarkupEvent& event) {
  GstMapInfo map;
  if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) return false;
  const bool ok = pfap::read_markup({map.data, map.size}, event);
  gst_buffer_unmap(buffer, &map);
  return ok;
}

// Posts the warning for an input buffer that pfap_buffer_read refused. A macro so that the
// element's own debug category (GST_CAT_DEFAULT) logs it.
#define PFAP_WARN_MALFORMED_EVENT(element, buffer)                                  \
  GST_ELEMENT_WARNING(element, STREAM, DECODE, ("Dropped a malformed PFAP event."), \
                      ("%" G_GSIZE_FORMAT " bytes at %" GST_TIME_FORMAT             \
                       " are not a valid application/x-pfap event",                 \
                       gst_buffer_get_size(buffer), GST_TIME_ARGS(GST_BUFFER_PTS(buffer))))

// Whether to warn at the `count`th occurrence (from 1) of a fault that may repeat: at the
// 1st, 2nd, 4th, 8th, ..., so a fault shows at once and a lasting one costs log2(n) messages
// instead of flooding the bus.
inline bool pfap_warn_at(guint64 count) { return (count & (count - 1)) == 0; }

// `event`, a stream-start, with the sparse flag. Phonemes come only while someone speaks:
// sparse tells queues, muxers and aggregators downstream not to wait for our data.
inline GstEvent* pfap_make_sparse(GstEvent* event) {
  event = gst_event_make_writable(event);
  GstStreamFlags flags;
  gst_event_parse_stream_flags(event, &flags);
  gst_event_set_stream_flags(event, static_cast<GstStreamFlags>(flags | GST_STREAM_FLAG_SPARSE));
  return event;
}
