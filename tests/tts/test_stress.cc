// SPDX-License-Identifier: LGPL-2.1-or-later
// primary_stress: the transcription's ' marks on the spoken phonemes.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "stress.h"

namespace pfap::tts {
namespace {

TEST(Stress, MarksTheVowelAfterTheApostrophe) {
  const std::vector<std::string> spoken = {"h", "@", "l", "oU", "w", "3:", "l", "d", "_:", "_"};
  const std::vector<bool> want = {false, false, false, true,  false,
                                  true,  false, false, false, false};
  EXPECT_EQ(primary_stress("h@l'oU w'3:ld", spoken), want);
}

TEST(Stress, SecondaryIsNotPrimary) {
  const std::vector<std::string> spoken = {"a#", "b", "aU", "t"};
  EXPECT_EQ(primary_stress("a#b,aUt", spoken), (std::vector<bool>{false, false, false, false}));
}

TEST(Stress, ResynchronisesAfterAChangedPhoneme) {
  // The transcription says "t", the speech has a flap "t#": the walk stays, finds "3" further
  // in the word and the stress of "dog" after it.
  const std::vector<std::string> spoken = {"b", "E", "t#", "3", "d", "0", "g"};
  const std::vector<bool> want = {false, true, false, false, false, true, false};
  EXPECT_EQ(primary_stress("b'Et3 d'0g", spoken), want);
}

}  // namespace
}  // namespace pfap::tts
