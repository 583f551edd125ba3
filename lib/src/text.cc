// SPDX-License-Identifier: LGPL-2.1-or-later
// The .pfap text format (docs/text-format.md).
//
// A line is read field by field, left to right, into a local event; the first bad field is
// reported at its first byte. Only a whole good line reaches the caller and the reader's state.
#include "pfap/text.h"

#include <array>
#include <charconv>
#include <iterator>
#include <utility>
#include <vector>

#include "number.h"

namespace pfap {
namespace {

// A time and its phoneme's end, in ns, fit an int64 (and a GstClockTime): about 292 years.
constexpr int64_t kMaxTimeMs = INT64_MAX / kNsPerMs - kMaxPhonemeDurationMs;
// The largest field limit: a saturated number must still be over it to be refused.
static_assert(kMaxTimeMs < kSaturatedMagnitude);

constexpr std::string_view kStateKeyword = "state";
constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";  // U+FEFF in UTF-8
constexpr std::string_view kRecovered = "recovered";
constexpr std::string_view kComplete = "complete";
// The flag letters in the order they must appear, and what each one sets.
constexpr std::string_view kFlagLetters = "SWE";
constexpr std::array kFlagMembers = {&Phoneme::stress, &Phoneme::word_begin, &Phoneme::end_of_text};
constexpr std::string_view kNoFlags = "-";

bool is_field_space(char c) { return c == ' ' || c == '\t'; }

struct Field {
  std::string_view text;  // empty when the line has no more fields
  size_t column;          // its first byte; the end of the line when it is missing
};

// The field at or after `pos`; moves `pos` past it.
Field next_field(std::string_view content, size_t& pos) {
  while (pos < content.size() && is_field_space(content[pos])) ++pos;
  const size_t begin = pos;
  while (pos < content.size() && !is_field_space(content[pos])) ++pos;
  return {content.substr(begin, pos - begin), begin};
}

// A decimal integer in 0..max: optional sign, then one or more digits, as in bookmarks.
// `value` is set only on success.
bool parse_number(std::string_view text, int64_t max, int64_t& value) {
  int64_t parsed = 0;
  if (!parse_decimal(text, parsed) || parsed < 0 || parsed > max) return false;
  value = parsed;
  return true;
}

// '-', or a non-empty subset of S, W, E in that order, each at most once.
bool parse_flags(std::string_view text, Phoneme& phoneme) {
  if (text == kNoFlags) return true;
  size_t next = 0;
  for (char c : text) {
    const size_t letter = kFlagLetters.find(c, next);
    if (letter == std::string_view::npos) return false;
    next = letter + 1;
    phoneme.*kFlagMembers[letter] = true;
  }
  return true;
}

// A line's bookmarks, one after the other, with no count limit: the 40 bookmarks MPEG-4
// allows before a phoneme (parse_bookmarks' default limit) can be 80 FAPs, which the canonical
// form writes as 80 bookmarks, and a state lists up to every FAP. The line length bounds them.
BookmarkResult parse_line_bookmarks(std::string_view text, std::vector<Fap>& out) {
  return parse_bookmarks(text, out, SIZE_MAX);
}

TextResult bad_bookmark(BookmarkResult result, size_t offset) {
  return {TextStatus::kBadBookmark, offset + result.position, result.status};
}

TextResult read_phoneme(std::string_view content, Field symbol, size_t& pos, MarkupEvent& event) {
  int64_t value = 0;
  if (!parse_number(symbol.text, UINT8_MAX, value)) return {TextStatus::kBadSymbol, symbol.column};
  event.phoneme.symbol = static_cast<uint8_t>(value);

  const Field duration = next_field(content, pos);
  if (duration.text.empty()) return {TextStatus::kMissingField, duration.column};
  if (!parse_number(duration.text, kMaxPhonemeDurationMs, value)) {
    return {TextStatus::kBadDuration, duration.column};
  }
  event.phoneme.duration_ms = static_cast<uint16_t>(value);

  const Field f0 = next_field(content, pos);
  if (f0.text.empty()) return {TextStatus::kMissingField, f0.column};
  if (!parse_number(f0.text, kMaxF0Hz, value)) return {TextStatus::kBadF0, f0.column};
  event.phoneme.f0 = f0_code(static_cast<unsigned>(value));

  const Field flags = next_field(content, pos);
  if (flags.text.empty()) return {TextStatus::kMissingField, flags.column};
  if (!parse_flags(flags.text, event.phoneme)) return {TextStatus::kBadFlags, flags.column};

  const BookmarkResult bookmarks = parse_line_bookmarks(content.substr(pos), event.faps);
  if (!bookmarks.ok()) return bad_bookmark(bookmarks, pos);
  return {};
}

TextResult read_state(std::string_view content, size_t& pos, MarkupEvent& event) {
  const Field kind = next_field(content, pos);
  if (kind.text.empty()) return {TextStatus::kMissingField, kind.column};
  if (kind.text == kRecovered) {
    event.kind = PFAP_EVENT_RECOVERED;
  } else if (kind.text == kComplete) {
    event.kind = PFAP_EVENT_COMPLETE;
  } else {
    return {TextStatus::kBadStateKind, kind.column};
  }
  const BookmarkResult bookmarks = parse_line_bookmarks(content.substr(pos), event.faps);
  if (!bookmarks.ok()) return bad_bookmark(bookmarks, pos);
  return {};
}

void append_integer(int64_t value, std::string& out) {
  char digits[20];  // fits -2^63
  out.append(digits, std::to_chars(std::begin(digits), std::end(digits), value).ptr);
}

}  // namespace

const char* to_string(TextStatus status) {
  switch (status) {
    case TextStatus::kOk:
      return "ok";
    case TextStatus::kBadTime:
      return "bad time";
    case TextStatus::kTimeGoesBack:
      return "time goes back";
    case TextStatus::kBadSymbol:
      return "bad phoneme symbol";
    case TextStatus::kBadDuration:
      return "bad duration";
    case TextStatus::kBadF0:
      return "bad f0";
    case TextStatus::kBadFlags:
      return "bad flags";
    case TextStatus::kBadStateKind:
      return "unknown state kind";
    case TextStatus::kMissingField:
      return "missing field";
    case TextStatus::kBadBookmark:
      return "bad bookmark";
  }
  return "unknown text status";
}

TextResult TextReader::read_line(std::string_view line, TextEvent& out, bool& has_event) {
  has_event = false;
  if (line.ends_with('\r')) line.remove_suffix(1);
  // No field contains '#', so a comment starts at the first one wherever it is.
  const std::string_view content = line.substr(0, line.find('#'));

  // Editors on Windows start UTF-8 files with a byte order mark; it is no field. Skipping it
  // in place keeps every column a byte offset in the line as given.
  size_t pos = first_line_ && content.starts_with(kByteOrderMark) ? kByteOrderMark.size() : 0;
  first_line_ = false;
  const Field time = next_field(content, pos);
  if (time.text.empty()) return {};  // blank or comment line

  TextEvent parsed;
  if (!parse_number(time.text, kMaxTimeMs, parsed.time_ms)) {
    return {TextStatus::kBadTime, time.column};
  }
  if (parsed.time_ms < last_time_ms_) return {TextStatus::kTimeGoesBack, time.column};

  const Field second = next_field(content, pos);
  if (second.text.empty()) return {TextStatus::kMissingField, second.column};
  const TextResult result = second.text == kStateKeyword
                                ? read_state(content, pos, parsed.event)
                                : read_phoneme(content, second, pos, parsed.event);
  if (!result.ok()) return result;

  if (parsed.event.kind == PFAP_EVENT_PHONEME) {
    parsed.event.sentence_start = next_starts_sentence_;
    next_starts_sentence_ = parsed.event.phoneme.end_of_text;
  }
  last_time_ms_ = parsed.time_ms;
  out = std::move(parsed);
  has_event = true;
  return {};
}

void TextReader::reset() { *this = TextReader(); }

size_t count_text_events(std::string_view head, bool whole) {
  TextReader reader;
  TextEvent event;
  size_t events = 0;
  while (!head.empty()) {
    const size_t end = head.find('\n');
    if (end == std::string_view::npos && !whole) break;  // cut where the head ends
    const std::string_view line = head.substr(0, end);
    bool has_event = false;
    if (!reader.read_line(line, event, has_event).ok()) return 0;
    events += has_event ? 1 : 0;
    head.remove_prefix(end == std::string_view::npos ? head.size() : end + 1);
  }
  return events;
}

void format_text_line(const TextEvent& text_event, std::string& out) {
  const MarkupEvent& event = text_event.event;
  append_integer(text_event.time_ms, out);
  if (event.kind == PFAP_EVENT_RECOVERED || event.kind == PFAP_EVENT_COMPLETE) {
    out += ' ';
    out += kStateKeyword;
    out += ' ';
    out += event.kind == PFAP_EVENT_COMPLETE ? kComplete : kRecovered;
  } else {
    const Phoneme& phoneme = event.phoneme;
    for (unsigned field :
         {unsigned{phoneme.symbol}, unsigned{phoneme.duration_ms}, phoneme.f0_hz()}) {
      out += ' ';
      append_integer(field, out);
    }
    out += ' ';
    const size_t flags_begin = out.size();
    for (size_t i = 0; i < kFlagMembers.size(); ++i) {
      if (phoneme.*kFlagMembers[i]) out += kFlagLetters[i];
    }
    if (out.size() == flags_begin) out += kNoFlags;
  }
  if (!event.faps.empty()) {
    out += ' ';
    format_bookmarks(event.faps, out);
  }
}

}  // namespace pfap
