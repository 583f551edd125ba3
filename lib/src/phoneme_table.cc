#include "pfap/phoneme_table.h"

#include <array>

namespace pfap {
namespace {

using V = Viseme;

// Visemes as MPEG-4 groups the sounds: a diphthong by its first, larger mouth shape; HH and
// NG, made at the back of the mouth, with k g; ER with r; W with the rounded U; Y with I.
constexpr std::array<PhonemeInfo, 40> kArpabet{{
    {"pause", V::kNone}, {"AA", V::kA},  {"AE", V::kA},  {"AH", V::kA},  {"AO", V::kQ},
    {"AW", V::kA},       {"AY", V::kA},  {"B", V::kPBM}, {"CH", V::kCh}, {"D", V::kTD},
    {"DH", V::kTH},      {"EH", V::kE},  {"ER", V::kR},  {"EY", V::kE},  {"F", V::kFV},
    {"G", V::kKG},       {"HH", V::kKG}, {"IH", V::kI},  {"IY", V::kI},  {"JH", V::kCh},
    {"K", V::kKG},       {"L", V::kNL},  {"M", V::kPBM}, {"N", V::kNL},  {"NG", V::kKG},
    {"OW", V::kQ},       {"OY", V::kQ},  {"P", V::kPBM}, {"R", V::kR},   {"S", V::kSZ},
    {"SH", V::kCh},      {"T", V::kTD},  {"TH", V::kTH}, {"UH", V::kU},  {"UW", V::kU},
    {"V", V::kFV},       {"W", V::kU},   {"Y", V::kI},   {"Z", V::kSZ},  {"ZH", V::kCh},
}};

constexpr std::array<PhonemeAlphabet, 1> kAlphabets{{
    {kArpabetAlphabet, kArpabet},
}};

}  // namespace

const PhonemeAlphabet* find_alphabet(std::string_view name) {
  for (const PhonemeAlphabet& alphabet : kAlphabets) {
    if (alphabet.name == name) return &alphabet;
  }
  return nullptr;
}

const PhonemeInfo* find_phoneme(const PhonemeAlphabet& alphabet, uint8_t symbol) {
  return symbol < alphabet.symbols.size() ? &alphabet.symbols[symbol] : nullptr;
}

std::optional<uint8_t> find_symbol(const PhonemeAlphabet& alphabet, std::string_view name) {
  for (size_t i = 0; i < alphabet.symbols.size(); ++i) {
    if (alphabet.symbols[i].name == name) return static_cast<uint8_t>(i);
  }
  return std::nullopt;
}

}  // namespace pfap
