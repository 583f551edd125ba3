/* SPDX-License-Identifier: LGPL-2.1-or-later */
// The warnings several elements post for the same fault, rate-limited (ratelimit.h). Macros
// so that each element's own debug category (GST_CAT_DEFAULT) logs them.
#pragma once

#include <gst/gst.h>

#include "ratelimit.h"

// An input buffer that pfap_buffer_read refused, the `count`th so far.
#define PFAP_WARN_MALFORMED_EVENT(element, buffer, count)                                      \
  G_STMT_START {                                                                               \
    if (pfap_warn_at(count)) {                                                                 \
      GST_ELEMENT_WARNING(element, STREAM, DECODE, ("Dropped a malformed PFAP event."),        \
                          ("%" G_GSIZE_FORMAT " bytes at %" GST_TIME_FORMAT                    \
                           " are not a valid application/x-pfap event; %" G_GUINT64_FORMAT     \
                           " so far (warned at the 1st, 2nd, 4th, 8th, ...)",                  \
                           gst_buffer_get_size(buffer), GST_TIME_ARGS(GST_BUFFER_PTS(buffer)), \
                           static_cast<guint64>(count)));                                      \
    }                                                                                          \
  }                                                                                            \
  G_STMT_END

// An event at running time `time_ns` earlier than the one before it, at `previous_ns`, taken
// at that one's time (pfap::EventTimeline); the `count`th so far. `what` says what the
// element did with it ("written", "applied").
#define PFAP_WARN_EARLIER_EVENT(element, what, time_ns, previous_ns, count)                      \
  G_STMT_START {                                                                                 \
    if (pfap_warn_at(count)) {                                                                   \
      GST_ELEMENT_WARNING(                                                                       \
          element, STREAM, FORMAT,                                                               \
          ("A PFAP event is earlier than the one before it; %s at that "                         \
           "one's time.",                                                                        \
           what),                                                                                \
          ("running time %" GST_STIME_FORMAT " is before %" GST_STIME_FORMAT                     \
           "; %" G_GUINT64_FORMAT " such events so far (warned at the 1st, 2nd, 4th, 8th, ...)", \
           GST_STIME_ARGS(time_ns), GST_STIME_ARGS(previous_ns), static_cast<guint64>(count)));  \
    }                                                                                            \
  }                                                                                              \
  G_STMT_END
