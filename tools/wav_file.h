// SPDX-License-Identifier: LGPL-2.1-or-later
// A WAV file's samples, for the measurement tools (tools/pfap-viseme-data, pfap-align-eval).
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace pfap::tools {

// The samples of a 16-bit mono PCM WAV file and its rate; false for anything else.
inline bool read_wav(const std::string& path, std::vector<int16_t>& samples, unsigned& rate) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 12 || bytes.compare(0, 4, "RIFF") != 0) return false;
  auto u32 = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  auto u16 = [&](size_t at) {
    uint16_t v;
    std::memcpy(&v, bytes.data() + at, 2);
    return v;
  };
  bool format_ok = false;
  for (size_t at = 12; at + 8 <= bytes.size();) {
    const std::string id = bytes.substr(at, 4);
    const uint32_t size = u32(at + 4);
    if (id == "fmt ") {
      format_ok = u16(at + 8) == 1 && u16(at + 10) == 1 && u16(at + 22) == 16;
      rate = u32(at + 12);
    } else if (id == "data" && format_ok) {
      const size_t n = std::min<size_t>(size, bytes.size() - at - 8) / 2;
      samples.resize(n);
      std::memcpy(samples.data(), bytes.data() + at + 8, n * 2);
      return true;
    }
    at += 8 + size + (size & 1);
  }
  return false;
}

}  // namespace pfap::tools
