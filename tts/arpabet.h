// SPDX-License-Identifier: LGPL-2.1-or-later
// espeak-ng's phoneme mnemonics (its -x transcription and phoneme events) for English voices,
// as the x-pfap-arpabet symbols of pfap/phoneme_table.h. docs/tts.md has the table and why.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace pfap::tts {

struct MnemonicMapping {
  std::string_view mnemonic;  // espeak-ng's, e.g. "oU"
  std::string_view arpabet;   // x-pfap-arpabet's name, e.g. "OW"; "pause" for silence
};

// The table, for tests and docs.
std::span<const MnemonicMapping> english_mnemonics();

struct ArpabetSymbol {
  uint8_t symbol = 0;
  bool exact = true;  // false: found by the mnemonic's base (modifiers stripped)
};

// The x-pfap-arpabet symbol of an espeak-ng mnemonic: from the table, else from its base
// (the mnemonic without trailing digits, '#', '-', '/', ';' or ':', as in "l/2" or "e:"),
// else nullopt. Mnemonics starting with '_' are pauses.
std::optional<ArpabetSymbol> arpabet_symbol(std::string_view mnemonic);

}  // namespace pfap::tts
