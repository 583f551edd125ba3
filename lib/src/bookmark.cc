// SPDX-License-Identifier: LGPL-2.1-or-later
// MPEG-4 bookmarks (draft section 5) and their transformed form (section 6.3).
//
// A bookmark is checked in three steps, so that every error has one position:
//   1. "<", optional white space, "FAP"           else kNotABookmark at the '<'
//   2. a '>' before the next '<' or the end        else kUnterminated at the '<'
//   3. the fields, left to right: each one is a number, then within its range; the first
//      bad field is reported at its first byte, a missing field at the '>'.
#include "pfap/bookmark.h"

#include <array>
#include <charconv>
#include <cstdint>
#include <iterator>

#include "number.h"

namespace pfap {
namespace {

constexpr std::string_view kKeyword = "FAP";
constexpr int kExpressionBookmark = 2;  // n = 2: "e1 a1 e2 a2"
constexpr int kMaxExpression = 6;

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

size_t skip_space(std::string_view text, size_t i) {
  while (i < text.size() && is_space(text[i])) ++i;
  return i;
}

enum class Role : uint8_t { kFapNumber, kExpression, kAmplitude, kTransition, kCurve };

// "n a T C" and "2 e1 a1 e2 a2 T C".
constexpr std::array kSingleFields = {Role::kFapNumber, Role::kAmplitude, Role::kTransition,
                                      Role::kCurve};
constexpr std::array kExpressionFields = {Role::kFapNumber,  Role::kExpression, Role::kAmplitude,
                                          Role::kExpression, Role::kAmplitude,  Role::kTransition,
                                          Role::kCurve};

BookmarkStatus check_range(Role role, int64_t v) {
  switch (role) {
    case Role::kFapNumber:
      return v >= kExpressionBookmark && v <= kMaxFapIndex ? BookmarkStatus::kOk
                                                           : BookmarkStatus::kUnknownFap;
    case Role::kExpression:
      // 0 (neutral) is checked against its amplitude once that is known.
      return v >= 0 && v <= kMaxExpression ? BookmarkStatus::kOk
                                           : BookmarkStatus::kExpressionOutOfRange;
    case Role::kAmplitude:
      return v >= -kMaxAmplitude && v <= kMaxAmplitude ? BookmarkStatus::kOk
                                                       : BookmarkStatus::kAmplitudeOutOfRange;
    case Role::kTransition:
      return v >= 0 && v <= kMaxTransitionMs ? BookmarkStatus::kOk
                                             : BookmarkStatus::kTransitionOutOfRange;
    case Role::kCurve:
      return v >= static_cast<int>(Curve::kLinear) && v <= static_cast<int>(Curve::kSpline)
                 ? BookmarkStatus::kOk
                 : BookmarkStatus::kCurveOutOfRange;
  }
  return BookmarkStatus::kBadNumber;
}

Fap make_fap(int64_t index, int64_t amplitude, int64_t transition, int64_t curve) {
  return Fap{static_cast<uint8_t>(index), static_cast<int32_t>(amplitude),
             static_cast<uint16_t>(transition), static_cast<Curve>(curve)};
}

}  // namespace

const char* to_string(BookmarkStatus status) {
  switch (status) {
    case BookmarkStatus::kOk:
      return "ok";
    case BookmarkStatus::kNotABookmark:
      return "not a bookmark";
    case BookmarkStatus::kUnterminated:
      return "unterminated bookmark";
    case BookmarkStatus::kBadNumber:
      return "bad number or wrong field count";
    case BookmarkStatus::kUnknownFap:
      return "unknown fap number";
    case BookmarkStatus::kExpressionOutOfRange:
      return "expression out of range";
    case BookmarkStatus::kAmplitudeOutOfRange:
      return "amplitude out of range";
    case BookmarkStatus::kTransitionOutOfRange:
      return "transition time out of range";
    case BookmarkStatus::kCurveOutOfRange:
      return "curve out of range";
    case BookmarkStatus::kTooManyBookmarks:
      return "too many bookmarks";
    case BookmarkStatus::kUnexpectedText:
      return "unexpected text between bookmarks";
  }
  return "unknown bookmark status";
}

BookmarkResult parse_bookmark(std::string_view text, size_t& pos, std::vector<Fap>& out) {
  const size_t start = pos;
  if (start >= text.size() || text[start] != '<') {
    return {BookmarkStatus::kNotABookmark, start};
  }
  const size_t keyword = skip_space(text, start + 1);
  if (text.substr(keyword, kKeyword.size()) != kKeyword) {
    return {BookmarkStatus::kNotABookmark, start};
  }
  const size_t fields_begin = keyword + kKeyword.size();
  const size_t close = text.find_first_of("<>", fields_begin);
  if (close == std::string_view::npos || text[close] != '>') {
    return {BookmarkStatus::kUnterminated, start};
  }

  std::span<const Role> roles = kSingleFields;
  std::array<int64_t, kExpressionFields.size()> values{};
  std::array<size_t, kExpressionFields.size()> positions{};
  size_t count = 0;
  for (size_t i = fields_begin;;) {
    const size_t token_begin = skip_space(text, i);
    if (token_begin == close) break;
    // Tokens end at white space or '>', so only text glued to "FAP" lacks a separator.
    if (token_begin == i) return {BookmarkStatus::kBadNumber, token_begin};
    i = token_begin;
    while (i < close && !is_space(text[i])) ++i;
    if (count == roles.size()) return {BookmarkStatus::kBadNumber, token_begin};
    int64_t value = 0;
    if (!parse_decimal(text.substr(token_begin, i - token_begin), value)) {
      return {BookmarkStatus::kBadNumber, token_begin};
    }
    const BookmarkStatus status = check_range(roles[count], value);
    if (status != BookmarkStatus::kOk) return {status, token_begin};
    if (count == 0 && value == kExpressionBookmark) roles = kExpressionFields;
    // Neutral (0) only stands for "no expression", so it must come with amplitude 0.
    if (roles[count] == Role::kAmplitude && roles[count - 1] == Role::kExpression &&
        values[count - 1] == 0 && value != 0) {
      return {BookmarkStatus::kExpressionOutOfRange, positions[count - 1]};
    }
    values[count] = value;
    positions[count] = token_begin;
    ++count;
  }
  if (count < roles.size()) return {BookmarkStatus::kBadNumber, close};

  if (roles.size() == kSingleFields.size()) {
    out.push_back(make_fap(values[0], values[1], values[2], values[3]));
  } else {
    for (size_t slot : {size_t{1}, size_t{3}}) {
      if (values[slot] == 0) continue;
      out.push_back(make_fap(kFirstExpressionIndex - 1 + values[slot], values[slot + 1], values[5],
                             values[6]));
    }
  }
  pos = close + 1;
  return {};
}

BookmarkResult parse_bookmarks(std::string_view text, std::vector<Fap>& out, size_t max_bookmarks) {
  const size_t original_size = out.size();
  size_t bookmarks = 0;
  for (size_t pos = skip_space(text, 0); pos < text.size(); pos = skip_space(text, pos)) {
    const size_t start = pos;
    BookmarkResult result = parse_bookmark(text, pos, out);
    // Between bookmarks nothing claims that one starts here: what is not one is stray text.
    if (result.status == BookmarkStatus::kNotABookmark) {
      result.status = BookmarkStatus::kUnexpectedText;
    } else if (result.ok() && ++bookmarks > max_bookmarks) {
      result = {BookmarkStatus::kTooManyBookmarks, start};
    }
    if (!result.ok()) {
      out.resize(original_size);
      return result;
    }
  }
  return {};
}

void format_bookmarks(std::span<const Fap> faps, std::string& out) {
  char number[12];  // fits "-2147483648"
  for (const Fap& fap : faps) {
    out += "<FAP";
    for (int32_t field : {int32_t{fap.index}, fap.amplitude, int32_t{fap.transition_ms},
                          static_cast<int32_t>(fap.curve)}) {
      out += ' ';
      out.append(number, std::to_chars(std::begin(number), std::end(number), field).ptr);
    }
    out += '>';
  }
}

}  // namespace pfap
