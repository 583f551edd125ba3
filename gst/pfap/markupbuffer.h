/* SPDX-License-Identifier: LGPL-2.1-or-later */
// application/x-pfap GstBuffers from and to pfap::MarkupEvent: the one path between them, for
// the plugins' elements and libgstpfap-1.0's GstPfapEvent.
#pragma once

#include <gst/gst.h>

#include <cstdint>
#include <span>

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

// The bytes of `buffer`, mapped for reading while this lives. A buffer of one memory, as
// events are made, is read through that memory's map, which costs less than the buffer's; only
// a buffer of several memories needs them merged.
class PfapBufferBytes {
 public:
  explicit PfapBufferBytes(GstBuffer* buffer) {
    if (gst_buffer_n_memory(buffer) == 1) {
      memory_ = gst_buffer_peek_memory(buffer, 0);
      mapped_ = gst_memory_map(memory_, &map_, GST_MAP_READ);
    } else {
      buffer_ = buffer;
      mapped_ = gst_buffer_map(buffer, &map_, GST_MAP_READ);
    }
  }
  ~PfapBufferBytes() {
    if (!mapped_) return;
    if (memory_ != nullptr) {
      gst_memory_unmap(memory_, &map_);
    } else {
      gst_buffer_unmap(buffer_, &map_);
    }
  }
  PfapBufferBytes(const PfapBufferBytes&) = delete;
  PfapBufferBytes& operator=(const PfapBufferBytes&) = delete;

  // False when the buffer cannot be mapped for reading; then there are no bytes.
  bool mapped() const { return mapped_; }
  std::span<const uint8_t> bytes() const {
    return mapped_ ? std::span<const uint8_t>(map_.data, map_.size) : std::span<const uint8_t>();
  }

 private:
  GstMemory* memory_ = nullptr;  // the one memory mapped, or nullptr for the buffer
  GstBuffer* buffer_ = nullptr;
  GstMapInfo map_;
  bool mapped_ = false;
};

// Reads the event in `buffer`; false when it cannot be mapped or is not a valid x-pfap event.
inline bool pfap_buffer_read(GstBuffer* buffer, pfap::MarkupEvent& event) {
  const PfapBufferBytes bytes(buffer);
  return bytes.mapped() && pfap::read_markup(bytes.bytes(), event);
}
