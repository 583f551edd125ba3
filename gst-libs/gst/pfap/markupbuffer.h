/* SPDX-License-Identifier: LGPL-2.1-or-later */
// application/x-pfap GstBuffers from and to pfap::MarkupEvent, for the plugins' elements.
// Header-only, like the rest of this folder, so that each plugin needs only libpfap.
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
