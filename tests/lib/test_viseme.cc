// SPDX-License-Identifier: LGPL-2.1-or-later
// The viseme tables: every phoneme of every alphabet has a viseme in each vocabulary, and the
// rows of docs/visemes.md that come from the vocabularies' own documentation.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "pfap/phoneme_table.h"
#include "pfap/viseme.h"

namespace pfap {
namespace {

const PhonemeAlphabet& alphabet(std::string_view name) {
  static const PhonemeAlphabet kNone{};
  const PhonemeAlphabet* found = find_alphabet(name);
  if (found == nullptr) ADD_FAILURE() << "no alphabet " << name;
  return found != nullptr ? *found : kNone;
}

VisemeSet visemes(std::string_view alphabet_name, std::string_view phoneme) {
  const PhonemeAlphabet& a = alphabet(alphabet_name);
  const std::optional<uint8_t> symbol = find_symbol(a, phoneme);
  if (!symbol) {
    ADD_FAILURE() << phoneme << " not in " << alphabet_name;
    return {};
  }
  const std::optional<VisemeSet> set = find_visemes(a, *symbol);
  if (!set) ADD_FAILURE() << phoneme << " has no visemes";
  return set.value_or(VisemeSet{});
}

constexpr std::string_view kAlphabets[] = {kArpabetAlphabet, kPollyVisemeAlphabet,
                                           kAzureVisemeAlphabet, kRhubarbShapeAlphabet,
                                           kOculusVisemeAlphabet};

TEST(Viseme, EverySymbolOfEveryAlphabetHasAVisemeInEachSet) {
  const size_t sizes[] = {40, 17, 22, 9, 15};
  for (size_t a = 0; a < std::size(kAlphabets); ++a) {
    const PhonemeAlphabet& table = alphabet(kAlphabets[a]);
    ASSERT_EQ(table.symbols.size(), sizes[a]) << kAlphabets[a];
    for (size_t s = 0; s < table.symbols.size(); ++s) {
      SCOPED_TRACE(std::string(kAlphabets[a]) + " " + std::string(table.symbols[s].name));
      const std::optional<VisemeSet> set = find_visemes(table, static_cast<uint8_t>(s));
      ASSERT_TRUE(set.has_value());
      EXPECT_EQ(set->mpeg4, table.symbols[s].viseme);  // the table pfapface animates
      EXPECT_LE(static_cast<int>(set->mpeg4), 14);
      EXPECT_EQ(static_cast<int>(set->oculus), static_cast<int>(set->mpeg4));
      EXPECT_LT(set->azure, kAzureVisemeCount);
      EXPECT_LT(set->polly, 17);
      EXPECT_LT(set->rhubarb, 9);
      // Silence is silence in every vocabulary, and only silence.
      const bool silent = set->mpeg4 == Viseme::kNone;
      EXPECT_EQ(set->azure == 0, silent);
      EXPECT_EQ(set->polly == 0, silent);
      EXPECT_EQ(set->rhubarb == 0, silent);
    }
    EXPECT_FALSE(find_visemes(table, static_cast<uint8_t>(sizes[a])).has_value());
  }
}

TEST(Viseme, VisemeAlphabetsMapToThemselves) {
  const PhonemeAlphabet& polly = alphabet(kPollyVisemeAlphabet);
  for (uint8_t s = 0; s < polly.symbols.size(); ++s) EXPECT_EQ(find_visemes(polly, s)->polly, s);
  const PhonemeAlphabet& azure = alphabet(kAzureVisemeAlphabet);
  for (uint8_t s = 0; s < azure.symbols.size(); ++s) {
    EXPECT_EQ(find_visemes(azure, s)->azure, s);
    EXPECT_EQ(azure.symbols[s].name, std::to_string(s));
  }
  const PhonemeAlphabet& rhubarb = alphabet(kRhubarbShapeAlphabet);
  for (uint8_t s = 0; s < rhubarb.symbols.size(); ++s) {
    EXPECT_EQ(find_visemes(rhubarb, s)->rhubarb, s);
  }
  // x-pfap-oculus-viseme: symbol k is Oculus (and MPEG-4) viseme k, by Oculus's name.
  const PhonemeAlphabet& oculus = alphabet(kOculusVisemeAlphabet);
  for (uint8_t s = 0; s < oculus.symbols.size(); ++s) {
    EXPECT_EQ(static_cast<int>(find_visemes(oculus, s)->oculus), s);
    EXPECT_EQ(oculus.symbols[s].name, oculus_name(OculusViseme(s)));
  }
  // Its other columns are those of the phoneme of OVRLipSync's example word.
  const PhonemeAlphabet& arpabet = alphabet(kArpabetAlphabet);
  const struct {
    const char* viseme;
    const char* phoneme;
  } examples[] = {{"PP", "P"}, {"nn", "L"}, {"oh", "OW"}, {"ou", "UH"}};
  for (const auto& e : examples) {
    EXPECT_EQ(find_visemes(oculus, *find_symbol(oculus, e.viseme)),
              find_visemes(arpabet, *find_symbol(arpabet, e.phoneme)))
        << e.viseme;
  }
}

// Names as the formats write them.
TEST(Viseme, NamesAreTheVocabulariesOwn) {
  std::string oculus, talkinghead;
  for (int v = 0; v < kOculusVisemeCount; ++v) {
    oculus += std::string(oculus_name(OculusViseme(v))) + " ";
    talkinghead += std::string(talkinghead_name(OculusViseme(v))) + " ";
  }
  EXPECT_EQ(oculus, "sil PP FF TH DD kk CH SS nn RR aa E ih oh ou ");
  EXPECT_EQ(talkinghead, "sil PP FF TH DD kk CH SS nn RR aa E I O U ");
  std::string polly;
  for (const PhonemeInfo& info : alphabet(kPollyVisemeAlphabet).symbols) {
    polly += std::string(info.name) + " ";
  }
  EXPECT_EQ(polly, "sil p t S T f k i r s u @ a e E o O ");
  std::string rhubarb;
  for (const PhonemeInfo& info : alphabet(kRhubarbShapeAlphabet).symbols) rhubarb += info.name;
  EXPECT_EQ(rhubarb, "XABCDEFGH");
}

// Rows straight from the sources (docs/visemes.md): Azure's en-US phoneme table, Polly's en-US
// table, Rhubarb's shape descriptions, OVRLipSync's viseme reference.
TEST(Viseme, ArpabetRowsFollowTheSources) {
  const struct {
    const char* phoneme;
    OculusViseme oculus;
    uint8_t azure;
    const char* polly;
    const char* rhubarb;
  } rows[] = {
      {"pause", OculusViseme::kSil, 0, "sil", "X"}, {"P", OculusViseme::kPP, 21, "p", "A"},
      {"M", OculusViseme::kPP, 21, "p", "A"},       {"F", OculusViseme::kFF, 18, "f", "G"},
      {"V", OculusViseme::kFF, 18, "f", "G"},       {"TH", OculusViseme::kTH, 17, "T", "B"},
      {"DH", OculusViseme::kTH, 17, "T", "B"},      {"T", OculusViseme::kDD, 19, "t", "B"},
      {"N", OculusViseme::kNN, 19, "t", "B"},       {"K", OculusViseme::kKK, 20, "k", "B"},
      {"NG", OculusViseme::kKK, 20, "k", "B"},      {"HH", OculusViseme::kKK, 12, "k", "B"},
      {"CH", OculusViseme::kCH, 16, "S", "B"},      {"ZH", OculusViseme::kCH, 16, "S", "B"},
      {"S", OculusViseme::kSS, 15, "s", "B"},       {"L", OculusViseme::kNN, 14, "t", "H"},
      {"R", OculusViseme::kRR, 13, "r", "E"},       {"AA", OculusViseme::kAA, 2, "a", "D"},
      {"AE", OculusViseme::kAA, 1, "a", "C"},       {"EH", OculusViseme::kE, 4, "E", "C"},
      {"EY", OculusViseme::kE, 4, "e", "C"},        {"IY", OculusViseme::kIH, 6, "i", "B"},
      {"AO", OculusViseme::kOH, 3, "O", "E"},       {"OW", OculusViseme::kOH, 8, "o", "F"},
      {"UW", OculusViseme::kOU, 7, "u", "F"},       {"W", OculusViseme::kOU, 7, "u", "F"},
      {"AY", OculusViseme::kAA, 11, "a", "D"},      {"AW", OculusViseme::kAA, 9, "a", "D"},
      {"OY", OculusViseme::kOH, 10, "O", "E"},      {"ER", OculusViseme::kRR, 5, "E", "E"},
  };
  const PhonemeAlphabet& polly = alphabet(kPollyVisemeAlphabet);
  const PhonemeAlphabet& rhubarb = alphabet(kRhubarbShapeAlphabet);
  for (const auto& row : rows) {
    SCOPED_TRACE(row.phoneme);
    const VisemeSet set = visemes(kArpabetAlphabet, row.phoneme);
    EXPECT_EQ(set.oculus, row.oculus);
    EXPECT_EQ(set.azure, row.azure);
    EXPECT_EQ(polly.symbols[set.polly].name, row.polly);
    EXPECT_EQ(rhubarb.symbols[set.rhubarb].name, row.rhubarb);
  }
}

// The viseme alphabets agree with the phoneme table: a phoneme and the viseme that stands for
// it in another vocabulary have the same MPEG-4 viseme, where the vocabularies group alike.
TEST(Viseme, VisemeAlphabetsAgreeWithArpabetOnMpeg4) {
  const PhonemeAlphabet& arpabet = alphabet(kArpabetAlphabet);
  const PhonemeAlphabet& polly = alphabet(kPollyVisemeAlphabet);
  const PhonemeAlphabet& azure = alphabet(kAzureVisemeAlphabet);
  for (uint8_t s = 0; s < arpabet.symbols.size(); ++s) {
    const VisemeSet set = *find_visemes(arpabet, s);
    SCOPED_TRACE(arpabet.symbols[s].name);
    // Polly and Azure are finer than or as fine as MPEG-4 for these consonant groups.
    if (set.mpeg4 == Viseme::kPBM || set.mpeg4 == Viseme::kFV || set.mpeg4 == Viseme::kCh ||
        set.mpeg4 == Viseme::kSZ || set.mpeg4 == Viseme::kKG || set.mpeg4 == Viseme::kNone) {
      EXPECT_EQ(polly.symbols[set.polly].viseme, set.mpeg4);
    }
    if (set.mpeg4 != Viseme::kTD && set.mpeg4 != Viseme::kNL && set.mpeg4 != Viseme::kTH &&
        set.mpeg4 != Viseme::kE && set.mpeg4 != Viseme::kU) {
      EXPECT_EQ(azure.symbols[set.azure].viseme, set.mpeg4);
    }
  }
}

}  // namespace
}  // namespace pfap
