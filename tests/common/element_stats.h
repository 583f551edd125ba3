// SPDX-License-Identifier: LGPL-2.1-or-later
// An element's `stats` property (rtppfappay, rtppfapdepay, rtpjitterbuffer, ...) read by tests
// and benchmarks.
#pragma once

#include <gst/gst.h>

#include <string>

namespace pfap::testing {

// A guint64 field of the element's stats (0 when there is no such field).
inline guint64 stat(GstElement* element, const char* field) {
  GstStructure* s = nullptr;
  g_object_get(element, "stats", &s, nullptr);
  guint64 value = 0;
  if (s != nullptr) {
    gst_structure_get_uint64(s, field, &value);
    gst_structure_free(s);
  }
  return value;
}

// All of the element's stats as text, for failure messages.
inline std::string stats_text(GstElement* element) {
  GstStructure* s = nullptr;
  g_object_get(element, "stats", &s, nullptr);
  if (s == nullptr) return "(no stats)";
  gchar* text = gst_structure_to_string(s);
  std::string out = text;
  g_free(text);
  gst_structure_free(s);
  return out;
}

}  // namespace pfap::testing
