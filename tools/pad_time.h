// SPDX-License-Identifier: LGPL-2.1-or-later
// The running time of a buffer as it passes a pad, for pad probes: pfap-web and pfap-broadcast
// stamp the speech's level with it, examples/pfap-rtsp-server ends and aligns its audio with
// it, and tests/gst measure lip sync with it. (The elements place events by the segments they
// hold, signed: gst/pfap/runningtime.h.)
#pragma once

#include <gst/gst.h>

// The running time of `buffer`'s PTS in the segment `pad` holds; none without either.
inline GstClockTime running_time_of(GstPad* pad, GstBuffer* buffer) {
  if (!GST_BUFFER_PTS_IS_VALID(buffer)) return GST_CLOCK_TIME_NONE;
  GstEvent* event = gst_pad_get_sticky_event(pad, GST_EVENT_SEGMENT, 0);
  if (event == nullptr) return GST_CLOCK_TIME_NONE;
  const GstSegment* segment = nullptr;
  gst_event_parse_segment(event, &segment);
  const GstClockTime running =
      gst_segment_to_running_time(segment, GST_FORMAT_TIME, GST_BUFFER_PTS(buffer));
  gst_event_unref(event);
  return running;
}
