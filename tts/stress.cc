// SPDX-License-Identifier: LGPL-2.1-or-later
#include "stress.h"

#include <algorithm>

namespace pfap::tts {
namespace {

bool is_mark(char c) { return c == ' ' || c == '\'' || c == ',' || c == '%' || c == '='; }

}  // namespace

std::vector<bool> primary_stress(std::string_view transcription,
                                 std::span<const std::string> mnemonics) {
  std::vector<bool> stressed(mnemonics.size(), false);
  size_t at = 0;
  for (size_t i = 0; i < mnemonics.size(); ++i) {
    const std::string& m = mnemonics[i];
    size_t from = at;
    bool primary = false;
    while (from < transcription.size() && is_mark(transcription[from])) {
      primary |= transcription[from] == '\'';
      ++from;
    }
    if (transcription.substr(from).starts_with(m)) {
      stressed[i] = primary;
      at = from + m.size();
      continue;
    }
    if (m.starts_with('_')) continue;  // not in the transcription
    // Out of step (a phoneme espeak changed while speaking): resynchronise on the next
    // occurrence in the same word, or stay.
    const size_t word_end = std::min(transcription.find(' ', from), transcription.size());
    const size_t found = transcription.substr(0, word_end).find(m, from);
    if (found != std::string_view::npos) {
      stressed[i] = found > 0 && transcription[found - 1] == '\'';
      at = found + m.size();
    }
  }
  return stressed;
}

}  // namespace pfap::tts
