// SPDX-License-Identifier: LGPL-2.1-or-later
// UTF-8 encoding of one code point, shared by the JSON reader and libpfaptts's utterances.
// Internal to the project (lib/formats), not installed.
#pragma once

#include <string>

namespace pfap {

// Appends the UTF-8 bytes of `code_point` (at most U+10FFFF; the caller has checked) to `out`.
void encode_utf8(char32_t code_point, std::string& out);

}  // namespace pfap
