// SPDX-License-Identifier: LGPL-2.1-or-later
// The source pad functions of the plugins' parsers (pfapparse, fapparse, pfapmarksparse),
// whose output depends on all the input before: each event's time and flags on the ones before
// it. So they read from the start only: a seek is refused rather than passed to a source that
// might accept it, and the SEEKING query answers not seekable.
#pragma once

#include <gst/gst.h>

inline gboolean pfap_noseek_src_event(GstPad* pad, GstObject* parent, GstEvent* event) {
  if (GST_EVENT_TYPE(event) == GST_EVENT_SEEK) {
    gst_event_unref(event);
    return FALSE;
  }
  return gst_pad_event_default(pad, parent, event);
}

inline gboolean pfap_noseek_src_query(GstPad* pad, GstObject* parent, GstQuery* query) {
  if (GST_QUERY_TYPE(query) == GST_QUERY_SEEKING) {
    GstFormat format;
    gst_query_parse_seeking(query, &format, nullptr, nullptr, nullptr);
    gst_query_set_seeking(query, format, FALSE, -1, -1);
    return TRUE;
  }
  return gst_pad_query_default(pad, parent, query);
}

// Sets both on `srcpad`.
inline void pfap_noseek_set_src_functions(GstPad* srcpad) {
  gst_pad_set_event_function(srcpad, pfap_noseek_src_event);
  gst_pad_set_query_function(srcpad, pfap_noseek_src_query);
}
