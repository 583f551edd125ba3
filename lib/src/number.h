// SPDX-License-Identifier: LGPL-2.1-or-later
// Decimal integers as the text formats write them (bookmark fields, .pfap line fields).
// Internal to libpfap, not installed.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string_view>

namespace pfap {

// Larger than every field's limit, and small enough that one more digit cannot overflow: a
// longer digit string saturates here, and the caller's range check refuses it.
inline constexpr int64_t kSaturatedMagnitude = (INT64_MAX - 9) / 10;

// Optional sign, then one or more decimal digits, nothing else. `value` is set only on
// success; a magnitude over kSaturatedMagnitude is read as kSaturatedMagnitude.
inline bool parse_decimal(std::string_view text, int64_t& value) {
  size_t i = 0;
  const bool negative = !text.empty() && text[0] == '-';
  if (!text.empty() && (text[0] == '-' || text[0] == '+')) i = 1;
  if (i == text.size()) return false;
  int64_t magnitude = 0;
  for (; i < text.size(); ++i) {
    if (text[i] < '0' || text[i] > '9') return false;
    magnitude = std::min(magnitude * 10 + (text[i] - '0'), kSaturatedMagnitude);
  }
  value = negative ? -magnitude : magnitude;
  return true;
}

}  // namespace pfap
