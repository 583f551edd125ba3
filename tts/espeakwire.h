// SPDX-License-Identifier: LGPL-2.1-or-later
// What libpfaptts (espeak.cc) and its helper program pfap-espeak say to each other, as bytes.
// Both are built from one source tree and installed together, so the format is this machine's
// (native byte order and sizes) and has no version.
//
// A request, one datagram on their SOCK_SEQPACKET socket, with the write end of a fresh pipe
// passed by SCM_RIGHTS: an Ask, the voice settings, the text (empty for check_voice). The
// answer, on that pipe: a pid (the grandchild's that speaks, so that the caller can kill it, or
// 0 when pfap-espeak answers itself), an error (empty when none), then for check_voice the
// sample rate and for synthesize the Synthesis.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

#include "espeak.h"

namespace pfap::tts::wire {

// A request's most bytes: pfaptts's pieces and pfapalign's longest text (24,200 code points,
// under 97 KB) are shorter, and an AF_UNIX datagram must fit in the socket's default send
// buffer (212992 bytes).
inline constexpr size_t kMaxRequest = 128 * 1024;

// The file descriptor of pfap-espeak's end of the socket.
inline constexpr int kSocketFd = 3;

// What a call asks: the first byte of a request.
enum class Ask : uint8_t { check_voice, synthesize };

struct Writer {
  std::string bytes;
  template <typename T>
  requires std::is_trivially_copyable_v<T>
  void put(const T& v) { bytes.append(reinterpret_cast<const char*>(&v), sizeof v); }
  void put(std::string_view text) {
    put(uint64_t{text.size()});
    bytes.append(text);
  }
};

struct Reader {
  std::string_view rest;
  bool whole = true;  // false once something was cut short
  template <typename T>
  requires std::is_trivially_copyable_v<T>
  void get(T& v) {
    if (rest.size() < sizeof v) {
      whole = false;
      return;
    }
    std::memcpy(&v, rest.data(), sizeof v);
    rest.remove_prefix(sizeof v);
  }
  void get(std::string& text);
};

void put(Writer& w, const VoiceSettings& settings);
void get(Reader& r, VoiceSettings& settings);
void put(Writer& w, const Synthesis& s);
void get(Reader& r, Synthesis& s);

}  // namespace pfap::tts::wire
