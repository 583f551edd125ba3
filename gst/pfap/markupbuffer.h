/* SPDX-License-Identifier: LGPL-2.1-or-later */
// application/x-pfap GstBuffers from and to pfap::MarkupEvent, for the plugins' elements.
// Inline: a depayloader makes one buffer per phoneme.
#pragma once

#include <gst/gst.h>

#include "pfap/markup_event.h"

// A buffer holding `event`, or NULL when the event has a value out of range. Its one memory
// is written in place: mapping the memory costs less than mapping the buffer (no reference,
// no writability check), and a depayloader makes one buffer per phoneme.
inline GstBuffer* pfap_buffer_new(const pfap::MarkupEvent& event) {
  const size_t size = pfap::markup_size(event);
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, size, nullptr);
  GstMemory* memory = gst_buffer_peek_memory(buffer, 0);
  GstMapInfo map;
  gst_memory_map(memory, &map, GST_MAP_WRITE);
  const bool ok = pfap::write_markup(event, {map.data, size});
  gst_memory_unmap(memory, &map);
  if (!ok) gst_clear_buffer(&buffer);
  return buffer;
}

// Reads the event in `buffer`; false when it is not a valid x-pfap event. A buffer of one
// memory, as events are made, is read through that memory's map, which costs less than the
// buffer's; only a buffer of several memories needs them merged.
inline bool pfap_buffer_read(GstBuffer* buffer, pfap::MarkupEvent& event) {
  GstMapInfo map;
  if (gst_buffer_n_memory(buffer) == 1) {
    GstMemory* memory = gst_buffer_peek_memory(buffer, 0);
    if (!gst_memory_map(memory, &map, GST_MAP_READ)) return false;
    const bool ok = pfap::read_markup({map.data, map.size}, event);
    gst_memory_unmap(memory, &map);
    return ok;
  }
  if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) return false;
  const bool ok = pfap::read_markup({map.data, map.size}, event);
  gst_buffer_unmap(buffer, &map);
  return ok;
}
