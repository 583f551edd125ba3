// SPDX-License-Identifier: LGPL-2.1-or-later
// encode_utf8: the first and last code point of each length, as RFC 3629's table gives them.
#include <gtest/gtest.h>

#include <string>

#include "pfap/utf8.h"

namespace pfap {
namespace {

struct Case {
  char32_t code_point;
  std::string bytes;
};

TEST(EncodeUtf8, EachLengthsFirstAndLast) {
  const Case cases[] = {
      {U'\0', std::string(1, '\0')},
      {0x7F, "\x7F"},
      {0x80, "\xC2\x80"},
      {0x7FF, "\xDF\xBF"},
      {0x800, "\xE0\xA0\x80"},
      {0xFFFF, "\xEF\xBF\xBF"},
      {0x10000, "\xF0\x90\x80\x80"},
      {0x10FFFF, "\xF4\x8F\xBF\xBF"},
      {U'é', "\xC3\xA9"},
      {U'€', "\xE2\x82\xAC"},
  };
  for (const Case& c : cases) {
    std::string out = "x";
    encode_utf8(c.code_point, out);
    EXPECT_EQ(out, "x" + c.bytes) << std::hex << static_cast<uint32_t>(c.code_point);
  }
}

}  // namespace
}  // namespace pfap
