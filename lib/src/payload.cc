// SPDX-License-Identifier: LGPL-2.1-or-later
// PFAP payload, draft-ietf-avt-rtp-pfap-00 section 6. Figure 1 is lost from the draft; the
// order below is the one its text gives (docs/format.md, "Payload layout").
//
// Packet descriptor (6.1), 8 bits:
//    0 1 2 3 4 5 6 7
//   +-+-+-+-+-+-+-+-+
//   |C| T |  PP |IB |
//   +-+-+-+-+-+-+-+-+
//   IB: 00 phoneme follows, 01 FAP follows, 10 end of packet, 11 reserved
//
// Recovery information, type 1 (6.4), 48 bits, only when T = 01 (wider than the formatter's
// column limit, so it is left alone):
// clang-format off
//    0                   1                   2                   3                   4
//    0 1 2 3 4 5 6 7 8 9 0 1 2 3 4 5 6 7 8 9 0 1 2 3 4 5 6 7 8 9 0 1 2 3 4 5 6 7 8 9 0 1 2 3 4 5 6 7
//   +-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+
//   |   FAPind    |s|              Amplitude (22)               |     Transition (14)       | C |IB |
//   +-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+
// clang-format on
//   IB: 00 another entry follows, 01 and 10 reserved, 11 end of recovery information
//
// Phoneme descriptor (6.2), 32 bits:
//    0                   1                   2                   3
//    0 1 2 3 4 5 6 7 8 9 0 1 2 3 4 5 6 7 8 9 0 1 2 3 4 5 6 7 8 9 0 1
//   +-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+
//   | PhonemeSymbol |    PhonemeDuration    |   f0Average   |S|W|IB |
//   +-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+-+
//   IB: 00 phoneme follows, 01 FAP follows, 10 end of packet, 11 end of text (ends the packet)
//
// FAP descriptor (6.3), 48 bits: the recovery entry's layout, with
//   IB: 00 phoneme follows, 01 FAP follows, 10 and 11 reserved
#include "pfap/payload.h"

#include <bit>
#include <cassert>
#include <cstring>

namespace pfap {
namespace {

// InfoBits, by the place they stand in.
constexpr unsigned kNextPhoneme = 0b00;
constexpr unsigned kNextFap = 0b01;
constexpr unsigned kEndOfPacket = 0b10;
constexpr unsigned kEndOfText = 0b11;  // phoneme descriptors only
constexpr unsigned kNextRecovery = 0b00;
constexpr unsigned kEndOfRecovery = 0b11;

constexpr unsigned kRecoveryTypeNone = 0b00;
constexpr unsigned kRecoveryType1 = 0b01;

unsigned coverage_code(unsigned covered_packets) {
  for (unsigned i = 0; i < std::size(kCoverageSteps); ++i) {
    if (kCoverageSteps[i] == covered_packets) return i + 1;
  }
  return 0;
}

// Big-endian fields as whole-word copies and byte swaps: GCC made six shifts and stores of
// byte loops, and every descriptor goes through these. A 48-bit field is a 32-bit and a
// 16-bit word: a 6-byte copy went through the stack.
constexpr bool kLittleEndian = std::endian::native == std::endian::little;

uint16_t read_be16(const uint8_t* p) {
  uint16_t v;
  std::memcpy(&v, p, 2);
  return kLittleEndian ? __builtin_bswap16(v) : v;
}

uint32_t read_be32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return kLittleEndian ? __builtin_bswap32(v) : v;
}

uint64_t read_be48(const uint8_t* p) { return uint64_t{read_be32(p)} << 16 | read_be16(p + 4); }

void write_be16(uint8_t* p, uint16_t v) {
  const uint16_t be = kLittleEndian ? __builtin_bswap16(v) : v;
  std::memcpy(p, &be, 2);
}

void write_be32(uint8_t* p, uint32_t v) {
  const uint32_t be = kLittleEndian ? __builtin_bswap32(v) : v;
  std::memcpy(p, &be, 4);
}

void write_be48(uint8_t* p, uint64_t v) {
  write_be32(p, static_cast<uint32_t>(v >> 16));
  write_be16(p + 4, static_cast<uint16_t>(v));
}

// FAP descriptor and recovery entry without their InfoBits: FAPind 7, s 1, amplitude 22,
// transition 14, C 2. Defined for any value: the encoder checks the ranges as it writes.
uint64_t pack_fap(const Fap& fap, unsigned info_bits) {
  const uint64_t sign = fap.amplitude < 0;
  const uint64_t magnitude =
      sign ? 0u - static_cast<uint32_t>(fap.amplitude) : static_cast<uint32_t>(fap.amplitude);
  return (uint64_t{fap.index} << 41) | (sign << 40) | (magnitude << 18) |
         (uint64_t{fap.transition_ms} << 4) | (uint64_t{static_cast<uint8_t>(fap.curve)} << 2) |
         info_bits;
}

uint32_t pack_phoneme(const Phoneme& phoneme, unsigned info_bits) {
  return (uint32_t{phoneme.symbol} << 24) | (uint32_t{phoneme.duration_ms} << 12) |
         (uint32_t{phoneme.f0} << 4) | (uint32_t{phoneme.stress} << 3) |
         (uint32_t{phoneme.word_begin} << 2) | info_bits;
}

// Unpacks and checks the fields a FAP descriptor and a recovery entry share. Always inlined:
// the decoder's loops call it per descriptor, and GCC left it a call.
[[gnu::always_inline]] inline DecodeStatus unpack_fap(uint64_t bits, Fap& fap) {
  const unsigned index = static_cast<unsigned>(bits >> 41);
  const int32_t magnitude = static_cast<int32_t>((bits >> 18) & 0x3FFFFF);
  const unsigned curve = static_cast<unsigned>(bits >> 2) & 0b11;
  if (index < kMinFapIndex || index > kMaxFapIndex) return DecodeStatus::kFapIndexOutOfRange;
  if (magnitude > kMaxAmplitude) return DecodeStatus::kAmplitudeOutOfRange;
  if (curve == 0) return DecodeStatus::kCurveZero;
  fap.index = static_cast<uint8_t>(index);
  fap.amplitude = (bits >> 40) & 1 ? -magnitude : magnitude;
  fap.transition_ms = static_cast<uint16_t>((bits >> 4) & 0x3FFF);
  fap.curve = static_cast<Curve>(curve);
  return DecodeStatus::kOk;
}

}  // namespace

bool is_valid_coverage(unsigned covered_packets) { return coverage_code(covered_packets) != 0; }

void Packet::clear() {
  recovery_kind = RecoveryKind::kNone;
  covered_packets = 0;
  recovery.clear();
  phonemes.clear();
  faps.clear();
}

void Packet::add_phoneme(const Phoneme& phoneme, std::span<const Fap> faps_before) {
  faps.insert(faps.end(), faps_before.begin(), faps_before.end());
  phonemes.push_back({phoneme, static_cast<uint32_t>(faps.size())});
}

std::span<const Fap> Packet::faps_of(size_t i) const {
  const uint32_t begin = i == 0 ? 0 : phonemes[i - 1].fap_end;
  return std::span<const Fap>(faps).subspan(begin, phonemes[i].fap_end - begin);
}

int64_t Packet::duration_ns() const {
  return for_each_phoneme(0, [](size_t, int64_t) {});
}

size_t encoded_size(const Packet& packet) {
  return kPacketDescriptorBytes +
         kFapDescriptorBytes * (packet.recovery.size() + packet.faps.size()) +
         kPhonemeDescriptorBytes * packet.phonemes.size();
}

const char* to_string(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::kOk:
      return "ok";
    case DecodeStatus::kTruncated:
      return "truncated descriptor";
    case DecodeStatus::kReservedRecoveryType:
      return "reserved recovery type";
    case DecodeStatus::kReservedInfoBits:
      return "reserved InfoBits";
    case DecodeStatus::kMissingCoverage:
      return "dynamic recovery with PP=000";
    case DecodeStatus::kFapIndexOutOfRange:
      return "FAP index outside 3..74";
    case DecodeStatus::kAmplitudeOutOfRange:
      return "amplitude over 2529600";
    case DecodeStatus::kCurveZero:
      return "curve 0";
    case DecodeStatus::kMissingFinalPhoneme:
      return "packet does not end with a phoneme";
    case DecodeStatus::kTrailingBytes:
      return "bytes after the end of the packet";
    case DecodeStatus::kDataInCompleteRecovery:
      return "complete recovery with phonemes or FAPs";
    case DecodeStatus::kUnterminatedRecovery:
      return "recovery list without end";
    case DecodeStatus::kEmptyPacket:
      return "empty packet";
  }
  return "unknown";
}

const char* to_string(EncodeStatus status) {
  switch (status) {
    case EncodeStatus::kOk:
      return "ok";
    case EncodeStatus::kInvalidFap:
      return "FAP field out of range";
    case EncodeStatus::kInvalidPhoneme:
      return "phoneme field out of range";
    case EncodeStatus::kInvalidCoverage:
      return "coverage not one of 1, 2, 4, 7, 15, 25, 40";
    case EncodeStatus::kEndOfTextNotLast:
      return "end of text before the last phoneme";
    case EncodeStatus::kDataInCompleteRecovery:
      return "complete recovery with phonemes or FAPs";
    case EncodeStatus::kRecoveryWithoutKind:
      return "recovery entries without a recovery kind";
    case EncodeStatus::kEmptyPacket:
      return "empty packet";
    case EncodeStatus::kBufferTooSmall:
      return "output buffer too small";
    case EncodeStatus::kBadFapEnd:
      return "FAPs not attached to phonemes in order";
  }
  return "unknown";
}

DecodeResult decode_payload(std::span<const uint8_t> payload, Packet& out) {
  out.clear();
  const uint8_t* const data = payload.data();
  const size_t size = payload.size();
  const auto fail = [&out](DecodeStatus status, size_t offset) {
    out.clear();
    return DecodeResult{status, static_cast<uint32_t>(offset)};
  };

  if (size == 0) return fail(DecodeStatus::kTruncated, 0);
  const unsigned complete = data[0] >> 7;
  const unsigned type = (data[0] >> 5) & 0b11;
  const unsigned pp = (data[0] >> 2) & 0b111;
  unsigned next = data[0] & 0b11;
  if (type != kRecoveryTypeNone && type != kRecoveryType1) {
    return fail(DecodeStatus::kReservedRecoveryType, 0);
  }
  if (next == 0b11) return fail(DecodeStatus::kReservedInfoBits, 0);
  if (complete) {
    if (next != kEndOfPacket) return fail(DecodeStatus::kDataInCompleteRecovery, 0);
    out.recovery_kind = RecoveryKind::kComplete;
  } else if (pp != 0) {
    out.recovery_kind = RecoveryKind::kDynamic;
    out.covered_packets = kCoverageSteps[pp - 1];
  } else if (type == kRecoveryType1) {
    return fail(DecodeStatus::kMissingCoverage, 0);
  }

  size_t pos = kPacketDescriptorBytes;
  if (type == kRecoveryType1) {
    for (unsigned info_bits = kNextRecovery; info_bits != kEndOfRecovery;
         pos += kFapDescriptorBytes) {
      if (size - pos < kFapDescriptorBytes) {
        return fail(pos == size ? DecodeStatus::kUnterminatedRecovery : DecodeStatus::kTruncated,
                    pos);
      }
      const uint64_t bits = read_be48(data + pos);
      info_bits = bits & 0b11;
      if (info_bits != kNextRecovery && info_bits != kEndOfRecovery) {
        return fail(DecodeStatus::kReservedInfoBits, pos);
      }
      Fap entry;
      if (const DecodeStatus status = unpack_fap(bits, entry); status != DecodeStatus::kOk) {
        return fail(status, pos);
      }
      out.recovery.push_back(entry);
    }
  }

  if (next == kEndOfPacket) {
    if (!complete && out.recovery.empty()) return fail(DecodeStatus::kEmptyPacket, 0);
  }
  while (next != kEndOfPacket) {
    if (pos == size) return fail(DecodeStatus::kMissingFinalPhoneme, pos);
    if (next == kNextPhoneme) {
      if (size - pos < kPhonemeDescriptorBytes) return fail(DecodeStatus::kTruncated, pos);
      const uint32_t bits = read_be32(data + pos);
      next = bits & 0b11;
      out.phonemes.push_back({Phoneme{.symbol = static_cast<uint8_t>(bits >> 24),
                                      .duration_ms = static_cast<uint16_t>((bits >> 12) & 0xFFF),
                                      .f0 = static_cast<uint8_t>(bits >> 4),
                                      .stress = ((bits >> 3) & 1) != 0,
                                      .word_begin = ((bits >> 2) & 1) != 0,
                                      .end_of_text = next == kEndOfText},
                              static_cast<uint32_t>(out.faps.size())});
      if (next == kEndOfText) next = kEndOfPacket;
      pos += kPhonemeDescriptorBytes;
    } else {
      if (size - pos < kFapDescriptorBytes) return fail(DecodeStatus::kTruncated, pos);
      const uint64_t bits = read_be48(data + pos);
      next = bits & 0b11;
      if (next != kNextPhoneme && next != kNextFap)
        return fail(DecodeStatus::kReservedInfoBits, pos);
      if (const DecodeStatus status = unpack_fap(bits, out.faps.emplace_back());
          status != DecodeStatus::kOk) {
        return fail(status, pos);
      }
      pos += kFapDescriptorBytes;
    }
  }
  if (pos != size) return fail(DecodeStatus::kTrailingBytes, pos);
  return {};
}

namespace {

EncodeStatus check(const Packet& packet) {
  switch (packet.recovery_kind) {
    case RecoveryKind::kNone:
      if (!packet.recovery.empty()) return EncodeStatus::kRecoveryWithoutKind;
      if (packet.phonemes.empty()) return EncodeStatus::kEmptyPacket;
      break;
    case RecoveryKind::kDynamic:
      if (!is_valid_coverage(packet.covered_packets)) return EncodeStatus::kInvalidCoverage;
      if (packet.recovery.empty() && packet.phonemes.empty()) return EncodeStatus::kEmptyPacket;
      break;
    case RecoveryKind::kComplete:
      if (!packet.phonemes.empty() || !packet.faps.empty()) {
        return EncodeStatus::kDataInCompleteRecovery;
      }
      break;
  }
  uint32_t fap_end = 0;
  for (size_t i = 0; i < packet.phonemes.size(); ++i) {
    const PacketPhoneme& entry = packet.phonemes[i];
    if (entry.fap_end < fap_end) return EncodeStatus::kBadFapEnd;
    fap_end = entry.fap_end;
    if (!is_valid(entry.phoneme)) return EncodeStatus::kInvalidPhoneme;
    if (entry.phoneme.end_of_text && i + 1 != packet.phonemes.size()) {
      return EncodeStatus::kEndOfTextNotLast;
    }
  }
  if (fap_end != packet.faps.size()) return EncodeStatus::kBadFapEnd;
  // The FAPs' ranges are checked as they are written (encode_payload).
  return EncodeStatus::kOk;
}

}  // namespace

EncodeStatus encode_payload(const Packet& packet, std::span<uint8_t> out) {
  // Everything but the FAPs' ranges; those are checked in the loops that write the FAPs, one
  // pass over them instead of two (a complete state has up to 72).
  if (const EncodeStatus status = check(packet); status != EncodeStatus::kOk) return status;
  if (out.size() < encoded_size(packet)) return EncodeStatus::kBufferTooSmall;

  const std::vector<PacketPhoneme>& phonemes = packet.phonemes;
  // What follows phoneme i-1 (or the packet descriptor, for i = 0): phoneme i's first FAP,
  // else phoneme i itself.
  const auto announce = [&phonemes](size_t i) {
    if (i == phonemes.size()) return kEndOfPacket;
    const uint32_t fap_begin = i == 0 ? 0 : phonemes[i - 1].fap_end;
    return phonemes[i].fap_end > fap_begin ? kNextFap : kNextPhoneme;
  };

  const unsigned complete = packet.recovery_kind == RecoveryKind::kComplete;
  const unsigned type = packet.recovery.empty() ? kRecoveryTypeNone : kRecoveryType1;
  const unsigned pp =
      packet.recovery_kind == RecoveryKind::kDynamic ? coverage_code(packet.covered_packets) : 0;
  uint8_t* p = out.data();
  *p++ = static_cast<uint8_t>(complete << 7 | type << 5 | pp << 2 | announce(0));

  bool faps_valid = true;
  // Pointers, not indexes compared with size(): a size of 12-byte Faps is a division. The
  // last entry is written after the loop, so that the loop has no test for it.
  const Fap* entry = packet.recovery.data();
  const Fap* const recovery_end = entry + packet.recovery.size();
  if (entry != recovery_end) {
    for (; entry + 1 != recovery_end; ++entry, p += kFapDescriptorBytes) {
      faps_valid &= is_valid(*entry);
      write_be48(p, pack_fap(*entry, kNextRecovery));
    }
    faps_valid &= is_valid(*entry);
    write_be48(p, pack_fap(*entry, kEndOfRecovery));
    p += kFapDescriptorBytes;
  }
  size_t fap = 0;
  for (size_t i = 0; i < phonemes.size(); ++i, p += kPhonemeDescriptorBytes) {
    const uint32_t fap_end = phonemes[i].fap_end;
    for (; fap < fap_end; ++fap, p += kFapDescriptorBytes) {
      faps_valid &= is_valid(packet.faps[fap]);
      write_be48(p, pack_fap(packet.faps[fap], fap + 1 == fap_end ? kNextPhoneme : kNextFap));
    }
    const Phoneme& phoneme = phonemes[i].phoneme;
    write_be32(p, pack_phoneme(phoneme, phoneme.end_of_text ? kEndOfText : announce(i + 1)));
  }
  assert(static_cast<size_t>(p - out.data()) == encoded_size(packet));
  // What was written is not usable then, as the contract allows.
  return faps_valid ? EncodeStatus::kOk : EncodeStatus::kInvalidFap;
}

}  // namespace pfap
