// SPDX-License-Identifier: LGPL-2.1-or-later
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

// The viseme alphabets: each viseme with the MPEG-4 viseme of the phonemes it stands for
// (docs/visemes.md has the sources and where this is a judgment).
constexpr std::array<PhonemeInfo, 17> kPollyVisemes{{
    {"sil", V::kNone}, {"p", V::kPBM}, {"t", V::kTD}, {"S", V::kCh}, {"T", V::kTH},
    {"f", V::kFV},     {"k", V::kKG},  {"i", V::kI},  {"r", V::kR},  {"s", V::kSZ},
    {"u", V::kU},      {"@", V::kA},   {"a", V::kA},  {"e", V::kE},  {"E", V::kE},
    {"o", V::kQ},      {"O", V::kQ},
}};

constexpr std::array<PhonemeInfo, 22> kAzureVisemes{{
    {"0", V::kNone}, {"1", V::kA},   {"2", V::kA},   {"3", V::kQ},   {"4", V::kE},
    {"5", V::kR},    {"6", V::kI},   {"7", V::kU},   {"8", V::kQ},   {"9", V::kA},
    {"10", V::kQ},   {"11", V::kA},  {"12", V::kKG}, {"13", V::kR},  {"14", V::kNL},
    {"15", V::kSZ},  {"16", V::kCh}, {"17", V::kTH}, {"18", V::kFV}, {"19", V::kTD},
    {"20", V::kKG},  {"21", V::kPBM},
}};

constexpr std::array<PhonemeInfo, 9> kRhubarbShapes{{
    {"X", V::kNone},
    {"A", V::kPBM},
    {"B", V::kSZ},
    {"C", V::kE},
    {"D", V::kA},
    {"E", V::kQ},
    {"F", V::kU},
    {"G", V::kFV},
    {"H", V::kNL},
}};

// Symbol k is MPEG-4 viseme k: the identity, by Oculus's names.
constexpr std::array<PhonemeInfo, 15> kOculusVisemes{{
    {"sil", V::kNone}, {"PP", V::kPBM}, {"FF", V::kFV}, {"TH", V::kTH}, {"DD", V::kTD},
    {"kk", V::kKG},    {"CH", V::kCh},  {"SS", V::kSZ}, {"nn", V::kNL}, {"RR", V::kR},
    {"aa", V::kA},     {"E", V::kE},    {"ih", V::kI},  {"oh", V::kQ},  {"ou", V::kU},
}};

constexpr std::array<PhonemeAlphabet, 5> kAlphabets{{
    {kArpabetAlphabet, kArpabet},
    {kPollyVisemeAlphabet, kPollyVisemes},
    {kAzureVisemeAlphabet, kAzureVisemes},
    {kRhubarbShapeAlphabet, kRhubarbShapes},
    {kOculusVisemeAlphabet, kOculusVisemes},
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
