// SPDX-License-Identifier: LGPL-2.1-or-later
// The .pfap text format: a PFAP session a person can write and read (docs/text-format.md).
//
// UTF-8, one event per line, '#' starts a comment, fields separated by white space:
//   phoneme: <start_ms> <symbol> <duration_ms> <f0_hz> <flags> [<FAP ...> ...]
//   state:   <time_ms> state <recovered|complete> [<FAP ...> ...]
// flags is '-' or any of S (stress), W (word begin), E (end of text) in that order. Times are
// integer ms, non-decreasing from line to line. A sentence starts at the first phoneme and at
// the one after an E.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "pfap/bookmark.h"
#include "pfap/markup_event.h"

namespace pfap {

enum class TextStatus : uint8_t {
  kOk = 0,
  kBadTime,       // not a decimal integer of ms whose end in ns fits an int64 (~292 years)
  kTimeGoesBack,  // earlier than the event before
  kBadSymbol,     // not 0..255
  kBadDuration,   // not 0..4095
  kBadF0,         // not 0..510
  kBadFlags,      // not '-', nor S, W, E in that order
  kBadStateKind,  // not "recovered" or "complete"
  kMissingField,  // the line ends before a required field
  kBadBookmark,   // the bookmarks do not parse: TextResult::bookmark says why
};

const char* to_string(TextStatus status);

struct TextResult {
  TextStatus status = TextStatus::kOk;
  size_t column = 0;                              // byte offset in the line of the field at fault
  BookmarkStatus bookmark = BookmarkStatus::kOk;  // why, for kBadBookmark

  bool ok() const { return status == TextStatus::kOk; }
};

struct TextEvent {
  int64_t time_ms = 0;  // a phoneme's start, a state's time
  MarkupEvent event;    // sentence_start is set by TextReader; uncertain is never set

  bool operator==(const TextEvent&) const = default;
};

// Reads a text stream line by line, keeping what spans lines: the time order and the implied
// sentence starts.
class TextReader {
 public:
  // Parses one line, without its line end. Blank and comment lines give kOk with `has_event`
  // false. On error nothing is kept from the line (it may be skipped and reading go on).
  // A UTF-8 byte order mark at the start of the stream's first line is skipped (columns
  // still count its 3 bytes).
  TextResult read_line(std::string_view line, TextEvent& out, bool& has_event);
  // Back to the start of a stream.
  void reset();

 private:
  int64_t last_time_ms_ = 0;
  bool next_starts_sentence_ = true;
  bool first_line_ = true;  // where a byte order mark may be
};

// How many events `head`, the start of a stream, holds when it reads as .pfap text: every
// whole line in it reads without error (the last line too, without its line end, when
// `whole` says `head` is the whole stream); 0 when a line does not, or when there is no event
// (only comments and blank lines say nothing). For typefinders, which see only a start.
size_t count_text_events(std::string_view head, bool whole);

// Appends the canonical line of `event` (no line end): integers separated by one space, f0
// in Hz (2 × its code), flags in the order S W E or '-', bookmarks in the transformed form
// "<FAP n a T C>" with n in 3..74, one after the other.
void format_text_line(const TextEvent& event, std::string& out);

}  // namespace pfap
