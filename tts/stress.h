// SPDX-License-Identifier: LGPL-2.1-or-later
// Stress from espeak-ng's stressed transcription (espeak_TextToPhonemes, as `espeak-ng -x`
// prints it: "h@l'oU w'3:ld"), whose marks the phoneme events do not carry.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pfap::tts {

// For each mnemonic of the spoken phonemes in order, whether the transcription puts the
// primary stress mark (') before it. The transcription is walked alongside: white space and
// the other marks (, % =) are passed over, a mnemonic must match the text where the walk
// stands, and a pause the transcription does not show (espeak writes final pauses in events
// only) is passed over; after a mismatch the walk goes on at the next match within a word.
std::vector<bool> primary_stress(std::string_view transcription,
                                 std::span<const std::string> mnemonics);

}  // namespace pfap::tts
