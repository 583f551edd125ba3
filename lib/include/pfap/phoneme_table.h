// SPDX-License-Identifier: LGPL-2.1-or-later
// Phoneme alphabets: the 8-bit symbol tables that the draft leaves to out-of-band signalling
// (section 5: "the mapping ... is signalled out of band"; here the `alphabet` caps field and
// SDP `a=fmtp:<pt> alphabet=<name>`), with the MPEG-4 viseme of each phoneme for renderers.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace pfap {

// The MPEG-4 visemes (ISO/IEC 14496-2, FAP 1 viseme_select): mouth shapes, each named by the
// phonemes that share it.
enum class Viseme : uint8_t {
  kNone = 0,  // silence, and phonemes with no mouth shape of their own
  kPBM = 1,   // p b m: lips closed
  kFV = 2,    // f v: lower lip to upper teeth
  kTH = 3,    // T D (think, that): tongue between teeth
  kTD = 4,    // t d
  kKG = 5,    // k g
  kCh = 6,    // tS dZ S (cheese, joy, she): lips rounded forward
  kSZ = 7,    // s z: teeth nearly closed
  kNL = 8,    // n l
  kR = 9,     // r
  kA = 10,    // A: (car): jaw open
  kE = 11,    // e (bed)
  kI = 12,    // I (tip): lips spread
  kQ = 13,    // Q (top): open, rounded
  kU = 14,    // U (book): rounded, nearly closed
};

struct PhonemeInfo {
  std::string_view name;  // the phoneme's name in its alphabet, e.g. "AA"
  Viseme viseme;
};

struct PhonemeAlphabet {
  std::string_view name;                 // the `alphabet` caps field's value
  std::span<const PhonemeInfo> symbols;  // indexed by symbol; symbols past the end are unknown
};

// x-pfap-arpabet: 0 is a pause, then the 39 ARPAbet phonemes of the CMU Pronouncing
// Dictionary in alphabetical order, AA = 1 ... ZH = 39 (docs/examples/README.md).
inline constexpr std::string_view kArpabetAlphabet = "x-pfap-arpabet";

// Alphabets whose symbols are the visemes of another vocabulary, for streams that came from
// a service or tool that gives visemes, not phonemes (docs/visemes.md): each symbol stands
// for the phonemes its viseme shows.
// Amazon Polly's viseme names: 0 sil, then p t S T f k i r s u @ a e E o O (1..16).
inline constexpr std::string_view kPollyVisemeAlphabet = "x-pfap-polly-viseme";
// Azure Speech / SAPI viseme IDs: the symbol is the ID, 0 (silence) .. 21 (p b m).
inline constexpr std::string_view kAzureVisemeAlphabet = "x-pfap-azure-viseme";
// Rhubarb Lip Sync mouth shapes: 0 X (rest), then A..H (1..8).
inline constexpr std::string_view kRhubarbShapeAlphabet = "x-pfap-rhubarb-shape";
// The viseme detector's (pfapalign recognizer=visemes, pfap.js): symbol k is Oculus viseme k,
// which is MPEG-4 viseme k: 0 sil, then PP FF TH DD kk CH SS nn RR aa E ih oh ou (1..14).
inline constexpr std::string_view kOculusVisemeAlphabet = "x-pfap-oculus-viseme";

// The alphabet called `name`, or nullptr if it is not one this library knows.
const PhonemeAlphabet* find_alphabet(std::string_view name);

// Symbol `symbol` of `alphabet`, or nullptr if the alphabet has no such symbol.
const PhonemeInfo* find_phoneme(const PhonemeAlphabet& alphabet, uint8_t symbol);

// The symbol of the phoneme called `name` in `alphabet`.
std::optional<uint8_t> find_symbol(const PhonemeAlphabet& alphabet, std::string_view name);

}  // namespace pfap
