// SPDX-License-Identifier: LGPL-2.1-or-later
// What pfap-web takes from a browser on its WebSocket (docs/web.md, docs/security.md): one
// JSON object per text message, checked whole against the schema before anything acts on it.
// No GStreamer here, so that tests/fuzz/fuzz_signal.cc can fuzz it alone.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace pfap_web {

// A message longer than this is refused before it is parsed (a browser's SDP answer is 1 to
// 5 KB); so is one nested deeper than kMaxSignalDepth, since json-glib 1.6 parses nesting by
// recursion and 128 KiB of '[' (libsoup's largest message) overflows the stack.
constexpr size_t kMaxSignalBytes = 64 * 1024;
constexpr int kMaxSignalDepth = 4;
// The longest text a page may ask to be said (pfaptts speaks it all).
constexpr size_t kMaxSayBytes = 4096;
// An ICE candidate line (about 100 bytes from a browser).
constexpr size_t kMaxCandidateBytes = 1024;
// The m-lines of the offer are 2 (audio and the data channel); more would be refused by
// webrtcbin, this only bounds the number.
constexpr int64_t kMaxMLineIndex = 63;

enum class SignalKind {
  kAnswer,    // {"type": "answer", "sdp": string}
  kIce,       // {"type": "ice", "candidate": string, "sdpMLineIndex"?: integer or null}
  kSay,       // {"type": "say", "text": string}
  kPlaying,   // {"type": "playing"}
  kComplete,  // {"type": "complete"}
};

struct Signal {
  SignalKind kind = SignalKind::kPlaying;
  std::string sdp;        // kAnswer: not empty
  std::string candidate;  // kIce: empty for the end of the candidates
  unsigned mline = 0;     // kIce: 0 when the message gives none
  std::string text;       // kSay: may be empty (nothing is said)
};

// Reads one text message into `signal`. False when it does not fit the schema, with `error`
// saying why in a short sentence of its own (never the message's bytes), for the log and the
// error message sent back. Members the schema does not name are ignored.
bool parse_signal(std::string_view message, Signal& signal, std::string& error);

}  // namespace pfap_web
