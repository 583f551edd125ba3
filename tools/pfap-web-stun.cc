// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap-web-stun.h"

namespace pfap_web {

namespace {

constexpr uint32_t kMagicCookie = 0x2112A442;
constexpr uint16_t kBindingRequest = 0x0001;
constexpr uint16_t kBindingSuccess = 0x0101;
constexpr uint16_t kXorMappedAddress = 0x0020;
constexpr size_t kHeaderBytes = 20;

uint16_t read16(std::span<const uint8_t> b, size_t at) {
  return static_cast<uint16_t>(b[at] << 8 | b[at + 1]);
}

uint32_t read32(std::span<const uint8_t> b, size_t at) {
  return static_cast<uint32_t>(read16(b, at)) << 16 | read16(b, at + 2);
}

void put16(std::vector<uint8_t>& out, uint16_t v) {
  out.push_back(static_cast<uint8_t>(v >> 8));
  out.push_back(static_cast<uint8_t>(v));
}

void put32(std::vector<uint8_t>& out, uint32_t v) {
  put16(out, static_cast<uint16_t>(v >> 16));
  put16(out, static_cast<uint16_t>(v));
}

}  // namespace

std::optional<std::vector<uint8_t>> stun_binding_response(std::span<const uint8_t> request,
                                                          uint32_t address, uint16_t port) {
  // The header: type (the top two bits 0), length (of the attributes, a multiple of 4),
  // the magic cookie, a 96-bit transaction ID.
  if (request.size() < kHeaderBytes || read16(request, 0) != kBindingRequest ||
      read32(request, 4) != kMagicCookie) {
    return std::nullopt;
  }
  const size_t length = read16(request, 2);
  if (length % 4 != 0 || kHeaderBytes + length != request.size()) return std::nullopt;
  // Each attribute: type, length, value padded to 4 bytes, within the message.
  for (size_t at = kHeaderBytes; at < request.size();) {
    if (request.size() - at < 4) return std::nullopt;
    const size_t value = (static_cast<size_t>(read16(request, at + 2)) + 3) / 4 * 4;
    if (request.size() - at - 4 < value) return std::nullopt;
    at += 4 + value;
  }
  std::vector<uint8_t> out;
  out.reserve(kHeaderBytes + 12);
  put16(out, kBindingSuccess);
  put16(out, 12);
  out.insert(out.end(), request.begin() + 4, request.begin() + kHeaderBytes);  // cookie, ID
  put16(out, kXorMappedAddress);
  put16(out, 8);
  put16(out, 0x0001);  // IPv4
  put16(out, static_cast<uint16_t>(port ^ (kMagicCookie >> 16)));
  put32(out, address ^ kMagicCookie);
  return out;
}

}  // namespace pfap_web
