/* SPDX-License-Identifier: LGPL-2.1-or-later */
// The running time of a buffer's PTS as the x-pfap writers place events (pfap::EventTimeline).
#pragma once

#include <gst/gst.h>

#include <cstdint>
#include <optional>

// The running time of `pts` in `segment`, negative before the segment start; none without a
// PTS.
inline std::optional<int64_t> pfap_running_time(const GstSegment& segment, GstClockTime pts) {
  guint64 time = 0;
  switch (gst_segment_to_running_time_full(&segment, GST_FORMAT_TIME, pts, &time)) {
    case 1:
      return static_cast<int64_t>(time);
    case -1:
      return -static_cast<int64_t>(time);
    default:
      return std::nullopt;
  }
}
