// SPDX-License-Identifier: LGPL-2.1-or-later
// MPEG-4 bookmarks `<FAP n FAPfield T C>` (draft section 5, ISO/IEC 14496-2 Annex C).
//
//   n = 2      FAPfield = e1 a1 e2 a2: expressions e1 and e2 (1..6) become FAPs 68+e1 and
//              68+e2 with amplitudes a1 and a2 and the same T and C. An expression 0
//              (neutral) with amplitude 0 leaves its slot empty.
//   n = 3..68  FAPfield = a: one FAP.
//   n = 69..74 the transformed form of section 6.3, one expression FAP.
//
// T over 16383 ms is refused, not clamped: the wire cannot carry it and a silent clamp
// would change the animation. docs/format.md gives the reasons.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pfap/model.h"

namespace pfap {

enum class BookmarkStatus : uint8_t {
  kOk = 0,
  kNotABookmark,          // text at the position does not start with "<FAP"
  kUnterminated,          // "<FAP" without a closing '>'
  kBadNumber,             // a field that is not a decimal integer, or too many/few fields
  kUnknownFap,            // n outside 2..74
  kExpressionOutOfRange,  // e outside 1..6 (or 0 with a non-zero amplitude)
  kAmplitudeOutOfRange,   // |a| > 2529600
  kTransitionOutOfRange,  // T < 0 or T > 16383
  kCurveOutOfRange,       // C outside 1..3
  kTooManyBookmarks,      // more consecutive bookmarks than allowed (40 by default)
  kUnexpectedText,        // something other than white space between bookmarks
};

const char* to_string(BookmarkStatus status);

struct BookmarkResult {
  BookmarkStatus status = BookmarkStatus::kOk;
  size_t position = 0;  // byte offset in the text where the problem is

  bool ok() const { return status == BookmarkStatus::kOk; }
};

// Parses the one bookmark that starts at text[pos] ('<'). On success appends its FAPs (0, 1
// or 2) to `out` and moves `pos` past the closing '>'; on error `out` and `pos` are unchanged.
BookmarkResult parse_bookmark(std::string_view text, size_t& pos, std::vector<Fap>& out);

// Parses a run of at most `max_bookmarks` bookmarks (MPEG-4 allows 40 before a phoneme)
// separated by optional white space, the whole of `text`. On error `out` is unchanged.
BookmarkResult parse_bookmarks(std::string_view text, std::vector<Fap>& out,
                               size_t max_bookmarks = kMaxBookmarksPerPhoneme);

// The transformed single-amplitude form "<FAP n a T C>", n in 3..74, one per FAP, no spaces
// between bookmarks; appended to `out`.
void format_bookmarks(std::span<const Fap> faps, std::string& out);

}  // namespace pfap
