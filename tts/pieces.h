// SPDX-License-Identifier: LGPL-2.1-or-later
// An utterance in pieces of about a sentence, spoken one after the other, so that a long text
// starts speaking after its first sentence and the speech held at a time is one piece's,
// whatever the length of the text.
#pragma once

#include <cstddef>

#include "utterance.h"

namespace pfap::tts {

// No piece is longer than this, in code points (a sentence longer than that is cut at white
// space). It bounds what one espeak-ng call takes: about 20 s of speech for English words,
// 2.5 minutes for CJK characters spelled out one by one (docs/tts.md, "Long texts").
constexpr size_t kMaxPieceCodePoints = 400;

// Where the piece that starts at `from` in `text` ends (exclusive; > from unless `from` is the
// end): after the first sentence end, a '.', '!', '?' or U+2026 with the closing quotes or
// brackets after it, followed by white space, and that white space; or, when there is none
// within kMaxPieceCodePoints, after the last white space within them, or else at the limit.
size_t piece_end(const std::u32string& text, size_t from);

// The piece [from, end) of `utterance` as an utterance of its own: its text, and the bookmarks
// that belong to it, found from `next_bookmark` on (the index of the first bookmark not yet
// given to a piece, moved past those given). A bookmark with only white space between it and
// `end` belongs to the next piece, before its first word, as the MPEG-4 rule places it (the
// next sentence's); the last piece takes every bookmark left.
Utterance piece(const Utterance& utterance, size_t from, size_t end, size_t& next_bookmark);

}  // namespace pfap::tts
