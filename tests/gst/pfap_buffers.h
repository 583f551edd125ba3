// SPDX-License-Identifier: LGPL-2.1-or-later
// application/x-pfap buffers for element tests: make them from the library's types and read
// them back, through the public C API in pfap/markup.h.
#pragma once

#include <gst/gst.h>
#include <gtest/gtest.h>

#include <vector>

#include "pfap/markup.h"
#include "pfap/markup_event.h"
#include "pfap/model.h"

namespace pfap::testing {

struct Event {
  PfapEventKind kind = PFAP_EVENT_PHONEME;
  uint8_t flags = 0;
  Phoneme phoneme;  // end_of_text mirrors PFAP_FLAG_END_OF_TEXT
  std::vector<Fap> faps;
  GstClockTime pts = GST_CLOCK_TIME_NONE;
  GstClockTime duration = GST_CLOCK_TIME_NONE;
  bool discont = false;

  bool operator==(const Event&) const = default;
};

inline uint8_t phoneme_flags(const Phoneme& p, bool sentence_start) {
  return static_cast<uint8_t>((p.stress ? PFAP_FLAG_STRESS : 0) |
                              (p.word_begin ? PFAP_FLAG_WORD_BEGIN : 0) |
                              (p.end_of_text ? PFAP_FLAG_END_OF_TEXT : 0) |
                              (sentence_start ? PFAP_FLAG_SENTENCE_START : 0));
}

// A phoneme event starting at `pts` and lasting its duration.
inline GstBuffer* phoneme_buffer(const Phoneme& p, const std::vector<Fap>& faps, GstClockTime pts,
                                 bool sentence_start) {
  const PfapEventHeader header{PFAP_EVENT_PHONEME, phoneme_flags(p, sentence_start),
                               p.symbol,           p.f0,
                               p.duration_ms,      static_cast<uint16_t>(faps.size())};
  std::vector<PfapFap> records;
  for (const Fap& f : faps) {
    records.push_back({f.index, static_cast<uint8_t>(f.curve), f.transition_ms, f.amplitude});
  }
  const size_t size = pfap_markup_size(header.n_faps);
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, size, nullptr);
  GstMapInfo map;
  gst_buffer_map(buffer, &map, GST_MAP_WRITE);
  EXPECT_EQ(pfap_markup_write(&header, records.data(), map.data, size), 0);
  gst_buffer_unmap(buffer, &map);
  GST_BUFFER_PTS(buffer) = pts;
  GST_BUFFER_DURATION(buffer) = p.duration_ms * GST_MSECOND;
  return buffer;
}

// The phoneme buffer of `e`, a phoneme Event (its flags say whether it starts a sentence).
inline GstBuffer* phoneme_buffer(const Event& e) {
  return phoneme_buffer(e.phoneme, e.faps, e.pts, (e.flags & PFAP_FLAG_SENTENCE_START) != 0);
}

// A buffer of any event at `pts`, made through the library's writer; a phoneme lasts its
// duration.
inline GstBuffer* markup_buffer(const MarkupEvent& event, GstClockTime pts) {
  const size_t size = markup_size(event);
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, size, nullptr);
  GstMapInfo map;
  gst_buffer_map(buffer, &map, GST_MAP_WRITE);
  EXPECT_TRUE(write_markup(event, {map.data, map.size}));
  gst_buffer_unmap(buffer, &map);
  GST_BUFFER_PTS(buffer) = pts;
  if (event.kind == PFAP_EVENT_PHONEME) {
    GST_BUFFER_DURATION(buffer) = event.phoneme.duration_ms * GST_MSECOND;
  }
  return buffer;
}

// Reads an x-pfap buffer (not taking ownership); a malformed one fails the test.
inline Event read_event(GstBuffer* buffer) {
  Event e;
  GstMapInfo map;
  gst_buffer_map(buffer, &map, GST_MAP_READ);
  PfapEventHeader h;
  EXPECT_EQ(pfap_markup_read_header(map.data, map.size, &h), 0) << "malformed x-pfap buffer";
  e.kind = static_cast<PfapEventKind>(h.kind);
  e.flags = h.flags;
  e.phoneme = {h.symbol,
               h.duration_ms,
               h.f0,
               (h.flags & PFAP_FLAG_STRESS) != 0,
               (h.flags & PFAP_FLAG_WORD_BEGIN) != 0,
               (h.flags & PFAP_FLAG_END_OF_TEXT) != 0};
  for (unsigned i = 0; i < h.n_faps; ++i) {
    PfapFap f;
    pfap_markup_read_fap(map.data, i, &f);
    e.faps.push_back({f.index, f.amplitude, f.transition_ms, static_cast<Curve>(f.curve)});
  }
  gst_buffer_unmap(buffer, &map);
  e.pts = GST_BUFFER_PTS(buffer);
  e.duration = GST_BUFFER_DURATION(buffer);
  e.discont = GST_BUFFER_FLAG_IS_SET(buffer, GST_BUFFER_FLAG_DISCONT);
  return e;
}

}  // namespace pfap::testing
