// SPDX-License-Identifier: LGPL-2.1-or-later
#include "placement.h"

#include <algorithm>

namespace pfap::tts {
namespace {

// What may stand between a bookmark and the first word of the sentence it starts.
bool leads_a_sentence(char32_t c) {
  return std::u32string_view(U" \t\r\n\"'([{\u00A0\u00AB\u00BF\u00A1\u2018\u201C").find(c) !=
         std::u32string_view::npos;
}

}  // namespace

std::optional<size_t> place_bookmark(std::span<const Word> words, std::u32string_view text,
                                     size_t position) {
  if (words.empty()) return std::nullopt;
  size_t next = 0;
  while (next < words.size() && words[next].start < position) ++next;
  if (next == words.size()) return words.back().last_phoneme;
  if (next == 0) return words[0].first_phoneme;
  const Word& before = words[next - 1];
  const Word& after = words[next];
  if (before.sentence == after.sentence) return after.first_phoneme;
  const size_t end = std::min(after.start, text.size());
  for (size_t i = std::min(position, end); i < end; ++i) {
    if (!leads_a_sentence(text[i])) return before.last_phoneme;
  }
  return after.first_phoneme;
}

}  // namespace pfap::tts
