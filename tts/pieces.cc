// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pieces.h"

#include <algorithm>

namespace pfap::tts {
namespace {

bool is_space(char32_t c) {
  return c == U' ' || c == U'\t' || c == U'\r' || c == U'\n' || c == U'\u00A0' ||
         c == U'\u3000';
}
bool ends_sentence(char32_t c) { return c == U'.' || c == U'!' || c == U'?' || c == U'\u2026'; }
bool closes(char32_t c) {
  return c == U'"' || c == U'\'' || c == U')' || c == U']' || c == U'}' || c == U'\u201D' ||
         c == U'\u2019' || c == U'\u00BB';
}

}  // namespace

size_t piece_end(const std::u32string& text, size_t from) {
  const size_t limit = std::min(text.size(), from + kMaxPieceCodePoints);
  size_t last_space = SIZE_MAX;
  for (size_t i = from; i < limit; ++i) {
    if (is_space(text[i])) {
      last_space = i;
      continue;
    }
    if (!ends_sentence(text[i])) continue;
    size_t j = i + 1;
    while (j < text.size() && (ends_sentence(text[j]) || closes(text[j]))) ++j;
    if (j == text.size()) return j;
    if (!is_space(text[j])) continue;
    while (j < text.size() && is_space(text[j])) ++j;
    return j;
  }
  if (limit == text.size()) return limit;
  if (last_space != SIZE_MAX && last_space > from) {
    size_t j = last_space;
    while (j < text.size() && is_space(text[j])) ++j;
    return j;
  }
  return limit;
}

Utterance piece(const Utterance& utterance, size_t from, size_t end, size_t& next_bookmark) {
  Utterance out;
  out.text = utterance.text.substr(from, end - from);
  const bool last = end >= utterance.text.size();
  // Where the piece's own text ends: bookmarks after it stand before the next piece's words.
  size_t content_end = end;
  while (content_end > from && is_space(utterance.text[content_end - 1])) --content_end;
  const std::vector<Bookmark>& all = utterance.bookmarks;
  for (; next_bookmark < all.size(); ++next_bookmark) {
    const Bookmark& b = all[next_bookmark];
    if (!last && b.position >= content_end) break;
    Bookmark local = b;
    local.position = std::clamp(b.position, from, end) - from;
    out.bookmarks.push_back(std::move(local));
  }
  return out;
}

}  // namespace pfap::tts
