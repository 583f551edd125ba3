// SPDX-License-Identifier: LGPL-2.1-or-later
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "pfap/phoneme_table.h"

namespace pfap {
namespace {

// The x-pfap-arpabet table; when the library has none, a failure and an empty table, so that
// the tests fail instead of crashing.
const PhonemeAlphabet& arpabet() {
  static const PhonemeAlphabet kNone{};
  const PhonemeAlphabet* alphabet = find_alphabet(kArpabetAlphabet);
  if (alphabet == nullptr) ADD_FAILURE() << "no alphabet " << kArpabetAlphabet;
  return alphabet != nullptr ? *alphabet : kNone;
}

TEST(PhonemeTable, UnknownAlphabetIsNotFound) {
  EXPECT_EQ(find_alphabet("x-sampa"), nullptr);
  EXPECT_EQ(find_alphabet(""), nullptr);
}

// The numbers of docs/examples/README.md, which the example sessions use.
TEST(PhonemeTable, ArpabetNumbersMatchTheExamplesTable) {
  const struct {
    uint8_t symbol;
    const char* name;
  } rows[] = {{0, "pause"}, {1, "AA"},  {9, "D"},  {16, "HH"}, {19, "JH"},
              {22, "M"},    {25, "OW"}, {29, "S"}, {34, "UW"}, {39, "ZH"}};
  for (const auto& row : rows) {
    const PhonemeInfo* info = find_phoneme(arpabet(), row.symbol);
    ASSERT_NE(info, nullptr) << int(row.symbol);
    EXPECT_EQ(info->name, row.name);
    EXPECT_EQ(find_symbol(arpabet(), row.name), row.symbol);
  }
}

TEST(PhonemeTable, SymbolsPastTheTableAreUnknown) {
  EXPECT_EQ(find_phoneme(arpabet(), 40), nullptr);
  EXPECT_EQ(find_phoneme(arpabet(), 255), nullptr);
  EXPECT_EQ(find_symbol(arpabet(), "XX"), std::nullopt);
}

TEST(PhonemeTable, NamesAreUnique) {
  std::set<std::string> names;
  for (const PhonemeInfo& info : arpabet().symbols) {
    EXPECT_TRUE(names.insert(std::string(info.name)).second) << info.name;
  }
}

TEST(PhonemeTable, ArpabetVisemesFollowMpeg4Groups) {
  const struct {
    const char* name;
    Viseme viseme;
  } rows[] = {{"pause", Viseme::kNone}, {"P", Viseme::kPBM}, {"B", Viseme::kPBM},
              {"M", Viseme::kPBM},      {"F", Viseme::kFV},  {"TH", Viseme::kTH},
              {"T", Viseme::kTD},       {"K", Viseme::kKG},  {"SH", Viseme::kCh},
              {"S", Viseme::kSZ},       {"N", Viseme::kNL},  {"R", Viseme::kR},
              {"AA", Viseme::kA},       {"EH", Viseme::kE},  {"IY", Viseme::kI},
              {"AO", Viseme::kQ},       {"UW", Viseme::kU}};
  for (const auto& row : rows) {
    const auto symbol = find_symbol(arpabet(), row.name);
    ASSERT_TRUE(symbol.has_value()) << row.name;
    EXPECT_EQ(find_phoneme(arpabet(), *symbol)->viseme, row.viseme) << row.name;
  }
}

}  // namespace
}  // namespace pfap
