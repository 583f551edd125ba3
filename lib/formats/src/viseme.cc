// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap/viseme.h"

#include <array>
#include <span>

namespace pfap {
namespace {

// One symbol's viseme in the vocabularies that are not MPEG-4's (the MPEG-4 viseme, and with it
// the Oculus one, comes from the phoneme table).
struct OtherVisemes {
  uint8_t azure;
  uint8_t polly;    // sil p t S T f k i r s u @ a e E o O = 0..16
  uint8_t rhubarb;  // X A B C D E F G H = 0..8
};

// Polly viseme symbols and Rhubarb shapes by name, for the tables below.
enum : uint8_t { sil, p, t, S, T, f, k, i, r, s, u, schwa, a, e, E, o, O };
enum : uint8_t { X, A, B, C, D, Ee, F, G, H };

// x-pfap-arpabet, in its symbol order. Azure: its en-US phoneme table; Polly: its en-US table;
// Rhubarb: its shape descriptions. docs/visemes.md says where a row is a judgment.
constexpr std::array<OtherVisemes, 40> kArpabet{{
    {0, sil, X},     // pause
    {2, a, D},       // AA
    {1, a, C},       // AE
    {1, schwa, C},   // AH
    {3, O, Ee},      // AO
    {9, a, D},       // AW
    {11, a, D},      // AY
    {21, p, A},      // B
    {16, S, B},      // CH
    {19, t, B},      // D
    {17, T, B},      // DH
    {4, E, C},       // EH
    {5, E, Ee},      // ER
    {4, e, C},       // EY
    {18, f, G},      // F
    {20, k, B},      // G
    {12, k, B},      // HH
    {6, i, B},       // IH
    {6, i, B},       // IY
    {16, S, B},      // JH
    {20, k, B},      // K
    {14, t, H},      // L
    {21, p, A},      // M
    {19, t, B},      // N
    {20, k, B},      // NG
    {8, o, F},       // OW
    {10, O, Ee},     // OY
    {21, p, A},      // P
    {13, r, Ee},     // R
    {15, s, B},      // S
    {16, S, B},      // SH
    {19, t, B},      // T
    {17, T, B},      // TH
    {4, u, F},       // UH
    {7, u, F},       // UW
    {18, f, G},      // V
    {7, u, F},       // W
    {6, i, B},       // Y
    {15, s, B},      // Z
    {16, S, B},      // ZH
}};

constexpr std::array<OtherVisemes, 17> kPolly{{
    {0, sil, X},  {21, p, A},  {19, t, B},        {16, S, B}, {17, T, B}, {18, f, G},
    {20, k, B},   {6, i, B},   {13, r, Ee},       {15, s, B}, {7, u, F},  {1, schwa, C},
    {2, a, D},    {4, e, C},   {4, E, C},         {8, o, F},  {3, O, Ee},
}};

// By ID: 0 silence; 1 æ ə ʌ; 2 ɑ; 3 ɔ; 4 ɛ ʊ; 5 ɝ; 6 j i ɪ; 7 w u; 8 o; 9 aʊ; 10 ɔɪ; 11 aɪ;
// 12 h; 13 ɹ; 14 l; 15 s z; 16 ʃ tʃ dʒ ʒ; 17 ð θ; 18 f v; 19 d t n; 20 k g ŋ; 21 p b m.
constexpr std::array<OtherVisemes, 22> kAzure{{
    {0, sil, X},   {1, schwa, C}, {2, a, D},   {3, O, Ee},  {4, E, C},   {5, E, Ee},
    {6, i, B},     {7, u, F},     {8, o, F},   {9, a, D},   {10, O, Ee}, {11, a, D},
    {12, k, B},    {13, r, Ee},   {14, t, H},  {15, s, B},  {16, S, B},  {17, T, B},
    {18, f, G},    {19, t, B},    {20, k, B},  {21, p, A},
}};

// X rest; A M B P closed; B clenched teeth (K S T, EE); C open (EH AE); D wide open (AA);
// E slightly rounded (AO ER); F puckered (UW OW W); G F V; H L.
constexpr std::array<OtherVisemes, 9> kRhubarb{{
    {0, sil, X},
    {21, p, A},
    {15, s, B},
    {4, E, C},
    {2, a, D},
    {3, O, Ee},
    {7, u, F},
    {18, f, G},
    {14, t, H},
}};

// x-pfap-oculus-viseme: each viseme as the x-pfap-arpabet phoneme of OVRLipSync's example
// word for it (sil, put, fat, think, tip, call, chair, sir, lot, red, car, bed, tip, toe, book).
constexpr std::array<OtherVisemes, 15> kOculus{{
    kArpabet[0],   // sil: pause
    kArpabet[27],  // PP: P
    kArpabet[14],  // FF: F
    kArpabet[32],  // TH: TH
    kArpabet[31],  // DD: T
    kArpabet[20],  // kk: K
    kArpabet[8],   // CH: CH
    kArpabet[29],  // SS: S
    kArpabet[21],  // nn: L
    kArpabet[28],  // RR: R
    kArpabet[1],   // aa: AA
    kArpabet[11],  // E: EH
    kArpabet[17],  // ih: IH
    kArpabet[25],  // oh: OW
    kArpabet[33],  // ou: UH
}};

struct Table {
  std::string_view alphabet;
  std::span<const OtherVisemes> rows;
};
constexpr std::array<Table, 5> kTables{{
    {kArpabetAlphabet, kArpabet},
    {kPollyVisemeAlphabet, kPolly},
    {kAzureVisemeAlphabet, kAzure},
    {kRhubarbShapeAlphabet, kRhubarb},
    {kOculusVisemeAlphabet, kOculus},
}};

constexpr std::array<std::string_view, kOculusVisemeCount> kOculusNames{
    "sil", "PP", "FF", "TH", "DD", "kk", "CH", "SS", "nn", "RR", "aa", "E", "ih", "oh", "ou"};
constexpr std::array<std::string_view, kOculusVisemeCount> kTalkingHeadNames{
    "sil", "PP", "FF", "TH", "DD", "kk", "CH", "SS", "nn", "RR", "aa", "E", "I", "O", "U"};

}  // namespace

std::string_view oculus_name(OculusViseme viseme) {
  return kOculusNames.at(static_cast<size_t>(viseme));
}

std::string_view talkinghead_name(OculusViseme viseme) {
  return kTalkingHeadNames.at(static_cast<size_t>(viseme));
}

std::optional<VisemeSet> find_visemes(const PhonemeAlphabet& alphabet, uint8_t symbol) {
  const PhonemeInfo* info = find_phoneme(alphabet, symbol);
  if (info == nullptr) return std::nullopt;
  for (const Table& table : kTables) {
    if (table.alphabet != alphabet.name || symbol >= table.rows.size()) continue;
    const OtherVisemes& row = table.rows[symbol];
    return VisemeSet{info->viseme, oculus_viseme(info->viseme), row.azure, row.polly,
                     row.rhubarb};
  }
  return std::nullopt;
}

}  // namespace pfap
