// SPDX-License-Identifier: LGPL-2.1-or-later
// The MPEG-4 bookmark rule (draft section 3, ISO/IEC 14496-3 TtsFAPInterface): "the start
// time of a FAP in a bookmark is the start time of the first phoneme of the first word
// following the bookmark of the current sentence. If there is no word after the bookmark in
// the current sentence, the start time of the FAP is the same as the start time of the last
// phoneme of the previous word."
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string_view>

namespace pfap::tts {

// A spoken word: where it starts in the text, its sentence and its phonemes.
struct Word {
  size_t start = 0;     // code point in the text
  size_t sentence = 0;  // counted from 0 in the utterance
  size_t first_phoneme = 0;
  size_t last_phoneme = 0;  // inclusive
};

// The phoneme whose start the FAPs of a bookmark standing before text[position] take.
// `words` are in spoken order. The bookmark's sentence is the next word's when that word is
// in the same sentence as the word before the bookmark, or when only white space and opening
// quotes or brackets stand between the bookmark and it (the bookmark follows a sentence's
// final punctuation); otherwise the bookmark ends the previous word's sentence. nullopt when
// there is no word at all.
std::optional<size_t> place_bookmark(std::span<const Word> words, std::u32string_view text,
                                     size_t position);

}  // namespace pfap::tts
