// SPDX-License-Identifier: LGPL-2.1-or-later
// The viseme vocabularies avatars and TTS services speak today, and the viseme of every symbol
// of the alphabets this library knows in each of them (docs/visemes.md has every table, its
// source and where a row is a judgment).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "pfap/phoneme_table.h"

namespace pfap {

// Oculus / Meta OVRLipSync's 15 visemes, in its order (its viseme index). They are the MPEG-4
// visemes with silence first, in the same order: oculus_viseme() is the identity on indexes.
enum class OculusViseme : uint8_t {
  kSil,
  kPP,
  kFF,
  kTH,
  kDD,
  kKK,
  kCH,
  kSS,
  kNN,
  kRR,
  kAA,
  kE,
  kIH,
  kOH,
  kOU,
};
inline constexpr int kOculusVisemeCount = 15;
constexpr OculusViseme oculus_viseme(Viseme viseme) { return OculusViseme(uint8_t(viseme)); }
// Its name as OVRLipSync spells it: sil PP FF TH DD kk CH SS nn RR aa E ih oh ou.
std::string_view oculus_name(OculusViseme viseme);
// Its name as met4citizen/TalkingHead spells it (Ready Player Me's viseme_* morph targets): the
// same but I, O, U for ih, oh, ou.
std::string_view talkinghead_name(OculusViseme viseme);

// Azure Speech viseme IDs (SAPI's SPVISEMES): 0 silence .. 21 p b m.
inline constexpr uint8_t kAzureVisemeCount = 22;

// The viseme of one symbol in every vocabulary. Polly visemes and Rhubarb shapes are symbols
// of the alphabets kPollyVisemeAlphabet and kRhubarbShapeAlphabet, whose names are what those
// formats write; an Azure viseme is its ID, also the symbol of kAzureVisemeAlphabet.
struct VisemeSet {
  Viseme mpeg4;  // the phoneme table's
  OculusViseme oculus;
  uint8_t azure;    // 0..21
  uint8_t polly;    // symbol of kPollyVisemeAlphabet
  uint8_t rhubarb;  // symbol of kRhubarbShapeAlphabet

  bool operator==(const VisemeSet&) const = default;
};

// The visemes of `symbol` in `alphabet`, one of this library's alphabets; none for a symbol
// the alphabet does not have or an alphabet with no viseme table.
std::optional<VisemeSet> find_visemes(const PhonemeAlphabet& alphabet, uint8_t symbol);

}  // namespace pfap
