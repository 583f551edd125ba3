// SPDX-License-Identifier: LGPL-2.1-or-later
// What the tools that build gst_parse_launch descriptions from user text share.
#pragma once

#include <string>

// A launch description's string value, double-quoted with its quotes and backslashes escaped,
// so that any text (a sentence, a path with spaces) stays one property value.
inline std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}
