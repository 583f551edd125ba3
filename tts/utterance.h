// SPDX-License-Identifier: LGPL-2.1-or-later
// An utterance as pfaptts receives it: plain text with MPEG-4 bookmarks `<FAP ...>` inline
// (pfap/bookmark.h), split into the text espeak-ng speaks and the bookmarks with the
// character positions where they stood.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "pfap/bookmark.h"
#include "pfap/model.h"

namespace pfap::tts {

struct Bookmark {
  size_t position = 0;  // in code points of Utterance::text: the bookmark stood before this one
  size_t source_character = 0;  // its '<' in the input, in code points from 0
  std::vector<Fap> faps;
};

struct Utterance {
  std::u32string text;  // the input without its bookmarks
  std::vector<Bookmark> bookmarks;

  std::string text_utf8() const;
};

// A bookmark that could not be read: what is wrong and where (code points from 0 in the
// input, at the field at fault as pfap::parse_bookmark reports it).
struct BadBookmark {
  BookmarkStatus status = BookmarkStatus::kOk;
  size_t character = 0;
};

// Splits `input` (valid UTF-8) into text and bookmarks. A bookmark starts at "<FAP"; any
// other '<' is text. Bookmarks separated only by white space are consecutive, at most
// kMaxBookmarksPerPhoneme of them. Each bad bookmark is appended to `bad`; it and its text up
// to its '>' (or up to the next '<' when it has none) are left out, and reading goes on.
Utterance parse_utterance(std::string_view input, std::vector<BadBookmark>& bad);

}  // namespace pfap::tts
