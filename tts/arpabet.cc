// SPDX-License-Identifier: LGPL-2.1-or-later
#include "arpabet.h"

#include "pfap/phoneme_table.h"

namespace pfap::tts {
namespace {

// espeak-ng 1.51's English phonemes (phsource/ph_english and its en-us variants) by sound.
// Where ARPAbet has no such phoneme the nearest is taken: the syllabic consonants as the
// consonant, the r-coloured and centring vowels of British English as their vowel, the flap
// as T, the glottal stop as T, the velar fricative x (loch) as K, and ';' (the linking
// palatal glide of "the_evening") as Y.
constexpr MnemonicMapping kEnglish[] = {
    // Vowels and diphthongs
    {"a", "AE"},
    {"aa", "AE"},
    {"a#", "AH"},
    {"a2", "AH"},
    {"A:", "AA"},
    {"A@", "AA"},
    {"A~", "AA"},
    {"0", "AA"},
    {"O2", "AO"},
    {"O:", "AO"},
    {"O@", "AO"},
    {"o@", "AO"},
    {"O", "AO"},
    {"V", "AH"},
    {"@", "AH"},
    {"@2", "AH"},
    {"@5", "AH"},
    {"@L", "L"},
    {"3", "ER"},
    {"3:", "ER"},
    {"VR", "ER"},
    {"e", "EH"},
    {"E", "EH"},
    {"E2", "EH"},
    {"e@", "EH"},
    {"eI", "EY"},
    {"i", "IY"},
    {"i:", "IY"},
    {"i@", "IY"},
    {"i@3", "IH"},
    {"I", "IH"},
    {"I#", "IH"},
    {"I2", "IH"},
    {"IR", "IH"},
    {"aI", "AY"},
    {"aI@", "AY"},
    {"aI3", "AY"},
    {"aU", "AW"},
    {"aU@", "AW"},
    {"OI", "OY"},
    {"oU", "OW"},
    {"oU#", "OW"},
    {"U", "UH"},
    {"U@", "UH"},
    {"u:", "UW"},
    // Consonants
    {"p", "P"},
    {"b", "B"},
    {"t", "T"},
    {"t#", "T"},
    {"d", "D"},
    {"d#", "D"},
    {"?", "T"},
    {"k", "K"},
    {"g", "G"},
    {"x", "K"},
    {"f", "F"},
    {"v", "V"},
    {"T", "TH"},
    {"D", "DH"},
    {"s", "S"},
    {"z", "Z"},
    {"S", "SH"},
    {"Z", "ZH"},
    {"h", "HH"},
    {"tS", "CH"},
    {"dZ", "JH"},
    {"m", "M"},
    {"n", "N"},
    {"n-", "N"},
    {"N", "NG"},
    {"l", "L"},
    {"r", "R"},
    {"r-", "R"},
    {"w", "W"},
    {"j", "Y"},
    {";", "Y"},
    // Pauses: '_' and its lengths ("_:", "_!", ...)
    {"_", "pause"},
};

std::optional<uint8_t> lookup(std::string_view mnemonic) {
  static const PhonemeAlphabet& arpabet = *find_alphabet(kArpabetAlphabet);
  for (const MnemonicMapping& m : kEnglish) {
    if (m.mnemonic == mnemonic) return find_symbol(arpabet, m.arpabet);
  }
  return std::nullopt;
}

}  // namespace

std::span<const MnemonicMapping> english_mnemonics() { return kEnglish; }

std::optional<ArpabetSymbol> arpabet_symbol(std::string_view mnemonic) {
  if (mnemonic.starts_with('_')) return ArpabetSymbol{0, true};
  if (std::optional<uint8_t> s = lookup(mnemonic)) return ArpabetSymbol{*s, true};
  std::string_view base = mnemonic;
  while (base.size() > 1 &&
         std::string_view("0123456789#-/;:").find(base.back()) != std::string_view::npos) {
    base.remove_suffix(1);
  }
  if (base != mnemonic) {
    if (std::optional<uint8_t> s = lookup(base)) return ArpabetSymbol{*s, false};
  }
  return std::nullopt;
}

}  // namespace pfap::tts
