// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap::decode_payload on arbitrary bytes. A payload that decodes must hold only valid values
// and encode back to the same bytes, but for the two canonical forms docs/format.md gives:
// negative zero (s = 1, amplitude 0) is written with s = 0, and PP, ignored when C = 1, as 000.
// A payload that does not decode must leave the packet empty and point inside the payload.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_check.h"
#include "pfap/payload.h"

namespace {

constexpr uint8_t kComplete = 0x80;
constexpr uint8_t kCoverageBits = 0b111 << 2;
constexpr uint8_t kSignBit = 0x01;  // the last bit of a FAP descriptor's first byte

// `bytes` in the encoder's canonical form, given the packet they decode to.
void canonicalise(const pfap::Packet& packet, std::vector<uint8_t>& bytes) {
  if (bytes[0] & kComplete) bytes[0] &= static_cast<uint8_t>(~kCoverageBits);
  size_t pos = pfap::kPacketDescriptorBytes;
  const auto fap_at = [&](const pfap::Fap& fap) {
    if (fap.amplitude == 0) bytes[pos] &= static_cast<uint8_t>(~kSignBit);
    pos += pfap::kFapDescriptorBytes;
  };
  for (const pfap::Fap& entry : packet.recovery) fap_at(entry);
  for (size_t i = 0; i < packet.phonemes.size(); ++i) {
    for (const pfap::Fap& fap : packet.faps_of(i)) fap_at(fap);
    pos += pfap::kPhonemeDescriptorBytes;
  }
  FUZZ_CHECK(pos == bytes.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> payload(data, size);
  pfap::Packet packet;
  const pfap::DecodeResult result = pfap::decode_payload(payload, packet);
  if (!result.ok()) {
    FUZZ_CHECK(packet == pfap::Packet{});
    FUZZ_CHECK(result.offset <= size);
    return 0;
  }

  FUZZ_CHECK(pfap::encoded_size(packet) == size);
  for (const pfap::Fap& fap : packet.recovery) FUZZ_CHECK(pfap::is_valid(fap));
  for (const pfap::Fap& fap : packet.faps) FUZZ_CHECK(pfap::is_valid(fap));
  for (const pfap::PacketPhoneme& p : packet.phonemes) FUZZ_CHECK(pfap::is_valid(p.phoneme));

  std::vector<uint8_t> encoded(size);
  FUZZ_CHECK(pfap::encode_payload(packet, encoded) == pfap::EncodeStatus::kOk);
  std::vector<uint8_t> expected(payload.begin(), payload.end());
  canonicalise(packet, expected);
  FUZZ_CHECK(encoded == expected);

  // A Packet reused across decodes gives the same result as a fresh one.
  pfap::Packet again = packet;
  FUZZ_CHECK(pfap::decode_payload(encoded, again).ok());
  FUZZ_CHECK(again == packet);
  return 0;
}
