// SPDX-License-Identifier: LGPL-2.1-or-later
// The espeak-ng mnemonic table: every target is an x-pfap-arpabet symbol, and every phoneme
// the en and en-us voices speak for a corpus maps exactly.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "arpabet.h"
#include "corpus.h"
#include "espeak.h"
#include "pfap/phoneme_table.h"

namespace pfap::tts {
namespace {

TEST(Arpabet, EveryEntryIsASymbol) {
  const PhonemeAlphabet& arpabet = *find_alphabet(kArpabetAlphabet);
  std::set<std::string_view> seen;
  for (const MnemonicMapping& m : english_mnemonics()) {
    SCOPED_TRACE(std::string(m.mnemonic));
    EXPECT_TRUE(seen.insert(m.mnemonic).second) << "twice in the table";
    EXPECT_TRUE(find_symbol(arpabet, m.arpabet).has_value()) << m.arpabet;
    const std::optional<ArpabetSymbol> s = arpabet_symbol(m.mnemonic);
    ASSERT_TRUE(s.has_value());
    EXPECT_TRUE(s->exact);
    EXPECT_EQ(find_phoneme(arpabet, s->symbol)->name, m.arpabet);
  }
}

TEST(Arpabet, SomeMappings) {
  const PhonemeAlphabet& arpabet = *find_alphabet(kArpabetAlphabet);
  auto name = [&](std::string_view m) {
    const std::optional<ArpabetSymbol> s = arpabet_symbol(m);
    return s ? std::string(find_phoneme(arpabet, s->symbol)->name) : std::string("none");
  };
  EXPECT_EQ(name("oU"), "OW");
  EXPECT_EQ(name("D"), "DH");
  EXPECT_EQ(name("tS"), "CH");
  EXPECT_EQ(name("_:"), "pause");
  EXPECT_EQ(name("_!"), "pause");
  // By the base, not exact.
  EXPECT_EQ(name("l/2"), "L");
  EXPECT_FALSE(arpabet_symbol("l/2")->exact);
  EXPECT_EQ(name("@7"), "AH");
  EXPECT_EQ(name("e:"), "EH");  // German's long e
  // Nothing to go by.
  EXPECT_EQ(name("Q"), "none");
  EXPECT_EQ(name("y"), "none");
}

TEST(Arpabet, EnglishVoicesSpeakOnlyMappedPhonemes) {
  for (const char* voice : {"en", "en-us"}) {
    std::set<std::string> spoken, unmapped;
    for (const char* sentence : kCorpus) {
      Synthesis s;
      std::string error;
      ASSERT_TRUE(synthesize(sentence, {voice, 450, 50, 100}, s, error)) << error;
      for (const Synthesis::Phoneme& p : s.phonemes) {
        spoken.insert(p.mnemonic);
        const std::optional<ArpabetSymbol> symbol = arpabet_symbol(p.mnemonic);
        if (!symbol || !symbol->exact) unmapped.insert(p.mnemonic + " (in: " + sentence + ")");
      }
    }
    SCOPED_TRACE(voice);
    EXPECT_GE(spoken.size(), 60u) << "the corpus should reach most of English's phonemes";
    for (const std::string& m : unmapped) ADD_FAILURE() << "unmapped: " << m;
  }
}

}  // namespace
}  // namespace pfap::tts
