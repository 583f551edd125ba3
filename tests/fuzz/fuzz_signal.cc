// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap-web's signalling (tools/pfap-web-signal.h) on arbitrary WebSocket messages: parse_signal
// never crashes, and either refuses the message with a short reason of its own (never the
// message's bytes, which go back to the page) or gives a message that fits the schema: the
// strings within their limits and UTF-8, an SDP answer not empty. A message that is taken is
// taken again the same when read a second time. The same bytes go to its STUN server
// (tools/pfap-web-stun.h) as a datagram: it answers only a well-formed binding request, with
// a success response of 32 bytes carrying the request's cookie and transaction ID.
#include <glib.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.h"
#include "pfap-web-signal.h"
#include "pfap-web-stun.h"

namespace {

bool same(const pfap_web::Signal& a, const pfap_web::Signal& b) {
  return a.kind == b.kind && a.sdp == b.sdp && a.candidate == b.candidate && a.mline == b.mline &&
         a.text == b.text;
}

bool utf8(const std::string& s) {
  return g_utf8_validate(s.data(), static_cast<gssize>(s.size()), nullptr);
}

void check_stun(const uint8_t* data, size_t size) {
  const auto response = pfap_web::stun_binding_response({data, size}, 0x7f000001, 40000);
  if (!response.has_value()) return;
  FUZZ_CHECK(size >= 20 && data[0] == 0 && data[1] == 1);
  FUZZ_CHECK(response->size() == 32);
  FUZZ_CHECK(std::equal(data + 4, data + 20, response->begin() + 4));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  check_stun(data, size);
  const std::string_view message(reinterpret_cast<const char*>(data), size);
  pfap_web::Signal signal;
  std::string error;
  if (!pfap_web::parse_signal(message, signal, error)) {
    FUZZ_CHECK(!error.empty() && error.size() <= 80);
    FUZZ_CHECK(utf8(error));
    FUZZ_CHECK(same(signal, pfap_web::Signal{}));
    return 0;
  }
  FUZZ_CHECK(size <= pfap_web::kMaxSignalBytes);
  FUZZ_CHECK(utf8(signal.sdp) && utf8(signal.candidate) && utf8(signal.text));
  switch (signal.kind) {
    case pfap_web::SignalKind::kAnswer:
      FUZZ_CHECK(!signal.sdp.empty());
      FUZZ_CHECK(signal.candidate.empty() && signal.text.empty() && signal.mline == 0);
      break;
    case pfap_web::SignalKind::kIce:
      FUZZ_CHECK(signal.candidate.size() <= pfap_web::kMaxCandidateBytes);
      FUZZ_CHECK(signal.mline <= pfap_web::kMaxMLineIndex);
      FUZZ_CHECK(signal.sdp.empty() && signal.text.empty());
      break;
    case pfap_web::SignalKind::kSay:
      FUZZ_CHECK(signal.text.size() <= pfap_web::kMaxSayBytes);
      FUZZ_CHECK(signal.sdp.empty() && signal.candidate.empty() && signal.mline == 0);
      break;
    case pfap_web::SignalKind::kPlaying:
    case pfap_web::SignalKind::kComplete:
      FUZZ_CHECK(signal.sdp.empty() && signal.candidate.empty() && signal.text.empty() &&
                 signal.mline == 0);
      break;
  }
  pfap_web::Signal again;
  std::string again_error;
  FUZZ_CHECK(pfap_web::parse_signal(message, again, again_error));
  FUZZ_CHECK(same(signal, again));
  return 0;
}
