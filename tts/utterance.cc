// SPDX-License-Identifier: LGPL-2.1-or-later
#include "utterance.h"

#include <cassert>

#include "pfap/utf8.h"

namespace pfap::tts {
namespace {

bool is_continuation(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }

size_t code_points(std::string_view utf8) {
  size_t n = 0;
  for (char c : utf8) n += is_continuation(c) ? 0 : 1;
  return n;
}

// Appends the code points of `utf8` (valid UTF-8) to `out`.
void append_utf8(std::string_view utf8, std::u32string& out) {
  for (size_t i = 0; i < utf8.size();) {
    const auto lead = static_cast<unsigned char>(utf8[i]);
    const int extra = lead < 0x80 ? 0 : lead < 0xE0 ? 1 : lead < 0xF0 ? 2 : 3;
    char32_t c = extra == 0 ? lead : lead & (0x3F >> extra);
    for (int k = 1; k <= extra && i + k < utf8.size(); ++k) {
      c = (c << 6) | (static_cast<unsigned char>(utf8[i + k]) & 0x3F);
    }
    out.push_back(c);
    i += 1 + extra;
  }
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

}  // namespace

std::string Utterance::text_utf8() const {
  std::string out;
  for (char32_t c : text) encode_utf8(c, out);
  return out;
}

Utterance parse_utterance(std::string_view input, std::vector<BadBookmark>& bad) {
  Utterance u;
  size_t pos = 0;
  size_t text_from = 0;  // start of the text not yet copied to u.text
  int consecutive = 0;   // bookmarks in the current run
  // Code points before byte `counted_bytes`: bookmarks and their errors come in byte order,
  // so each offset only counts on from the one before.
  size_t counted_bytes = 0;
  size_t counted = 0;
  auto code_point_offset = [&](size_t byte) {
    assert(byte >= counted_bytes);
    counted += code_points(input.substr(counted_bytes, byte - counted_bytes));
    counted_bytes = byte;
    return counted;
  };
  auto flush_text = [&](size_t end) {
    append_utf8(input.substr(text_from, end - text_from), u.text);
    text_from = end;
  };
  while ((pos = input.find("<FAP", pos)) != std::string_view::npos) {
    // White space alone since the last bookmark keeps the run going.
    bool only_space = true;
    for (size_t i = text_from; i < pos && only_space; ++i) only_space = is_space(input[i]);
    if (!only_space) consecutive = 0;
    flush_text(pos);
    const size_t start = pos;
    std::vector<Fap> faps;
    BookmarkResult result = parse_bookmark(input, pos, faps);
    if (result.ok() && ++consecutive > kMaxBookmarksPerPhoneme) {
      result = {BookmarkStatus::kTooManyBookmarks, start};
    }
    if (result.ok()) {
      u.bookmarks.push_back({u.text.size(), code_point_offset(start), std::move(faps)});
    } else {
      bad.push_back({result.status, code_point_offset(result.position)});
      const size_t close = input.find('>', start);
      const size_t next = input.find('<', start + 1);
      pos = close != std::string_view::npos && close < next ? close + 1
            : next != std::string_view::npos                ? next
                                                            : input.size();
    }
    text_from = pos;
  }
  flush_text(input.size());
  return u;
}

}  // namespace pfap::tts
