// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap-web's STUN server (RFC 8489, binding requests only; docs/web.md, "Browsers that hide
// their addresses"). A browser that hides its host candidates behind mDNS names (Chromium's
// default unless the page may use the camera or microphone) on a machine with no network
// but loopback gathers no candidate the server can reach, and ICE never starts; asked to use
// a STUN server on 127.0.0.1, it learns its own address from the answer and offers it as a
// server-reflexive candidate, which the server reaches.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace pfap_web {

// The success response to `request` if it is a well-formed STUN binding request (header,
// magic cookie, attribute lengths within the message), telling the sender its address:
// `address` (IPv4, host order) and `port`. Nothing for anything else, which is dropped.
std::optional<std::vector<uint8_t>> stun_binding_response(std::span<const uint8_t> request,
                                                          uint32_t address, uint16_t port);

}  // namespace pfap_web
