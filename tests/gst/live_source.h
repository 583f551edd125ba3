// SPDX-License-Identifier: LGPL-2.1-or-later
// A live phoneme source for pipeline tests: phonemes pushed into an appsrc at their time.
#pragma once

#include <gst/gst.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "pfap_buffers.h"
#include "pipeline.h"

namespace pfap::testing {

// Pushes each phoneme when the pipeline's running time (`clock` less `base_time`) reaches its
// start, as a live TTS source would; returns early when `stop` is set or a push fails.
inline void push_live(GstElement* appsrc, GstClock* clock, GstClockTime base_time,
                      const std::vector<Event>& events, const std::atomic<bool>& stop) {
  for (const Event& e : events) {
    for (;;) {
      if (stop) return;
      const GstClockTime now = gst_clock_get_time(clock);
      if (now >= base_time + e.pts) break;
      const GstClockTime wait = std::min<GstClockTime>(base_time + e.pts - now, 20 * GST_MSECOND);
      std::this_thread::sleep_for(std::chrono::nanoseconds(wait));
    }
    if (push(appsrc, phoneme_buffer(e)) != GST_FLOW_OK) return;
  }
}

}  // namespace pfap::testing
