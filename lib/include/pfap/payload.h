// SPDX-License-Identifier: LGPL-2.1-or-later
// PFAP payload encoder and decoder, bit-exact to draft-ietf-avt-rtp-pfap-00 section 6.
//
// A payload is a packet descriptor, then the recovery entries (if any), then phoneme and FAP
// descriptors chained by their InfoBits; every field is MSB first. docs/format.md has the bit
// diagrams and every reading of the draft that this code makes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "pfap/model.h"

namespace pfap {

enum class RecoveryKind : uint8_t {
  kNone,      // C=0, T=00, PP=000
  kDynamic,   // C=0, PP covers `covered_packets`; T=01 with entries, T=00 when there are none
  kComplete,  // C=1: the whole FAP state; FAPs not listed are 0. No phonemes or FAPs.
};

// Descriptor sizes in bytes (Figures 2 to 5).
inline constexpr size_t kPacketDescriptorBytes = 1;
inline constexpr size_t kPhonemeDescriptorBytes = 4;
inline constexpr size_t kFapDescriptorBytes = 6;  // also a recovery entry

// The prevPackets values the 3-bit PP field can signal.
inline constexpr uint8_t kCoverageSteps[] = {1, 2, 4, 7, 15, 25, 40};
bool is_valid_coverage(unsigned covered_packets);

// A phoneme with the FAPs that start with it (they precede it on the wire).
struct PacketPhoneme {
  Phoneme phoneme;
  uint32_t fap_end = 0;  // one past this phoneme's last FAP in Packet::faps

  bool operator==(const PacketPhoneme&) const = default;
};

// One payload, decoded. Flat vectors so that a Packet reused across decodes stops allocating.
struct Packet {
  RecoveryKind recovery_kind = RecoveryKind::kNone;
  uint8_t covered_packets = 0;  // kDynamic only: one of kCoverageSteps
  std::vector<Fap> recovery;    // type 1 entries, in wire order
  std::vector<PacketPhoneme> phonemes;
  std::vector<Fap> faps;  // all FAP descriptors, in wire order

  bool operator==(const Packet&) const = default;

  void clear();
  // Appends a phoneme and the FAPs that start with it.
  void add_phoneme(const Phoneme& phoneme, std::span<const Fap> faps_before);
  // The FAPs that start with phonemes[i].
  std::span<const Fap> faps_of(size_t i) const;
  // The phonemes' total duration: the packet's time to the last phoneme's end.
  int64_t duration_ns() const;
  // Calls f(i, start_ns) for each phoneme i in order, start_ns being where it starts when the
  // packet's time (its first phoneme's start) is `time_ns`: phonemes follow one another.
  // Returns where the last one ends.
  template <typename F>
  int64_t for_each_phoneme(int64_t time_ns, F&& f) const {
    for (size_t i = 0; i < phonemes.size(); ++i) {
      f(i, time_ns);
      time_ns += int64_t{phonemes[i].phoneme.duration_ms} * kNsPerMs;
    }
    return time_ns;
  }
};

// Every class of bad payload the decoder tells apart.
enum class DecodeStatus : uint8_t {
  kOk = 0,
  kTruncated,               // the payload ends inside a descriptor
  kReservedRecoveryType,    // T = 10 or 11
  kReservedInfoBits,        // an InfoBits value the draft reserves for the place it is in
  kMissingCoverage,         // dynamic recovery entries (C=0, T=01) with PP = 000
  kFapIndexOutOfRange,      // FAPind outside 3..74
  kAmplitudeOutOfRange,     // amplitude over 2529600
  kCurveZero,               // curve 0
  kMissingFinalPhoneme,     // the payload ends before a phoneme that ends the packet
  kTrailingBytes,           // bytes after the end of the packet
  kDataInCompleteRecovery,  // C=1 and the packet descriptor announces phonemes or FAPs
  kUnterminatedRecovery,    // the recovery list runs to the end of the payload
  kEmptyPacket,             // dynamic or no recovery, no entries and no phoneme: nothing to use
};
inline constexpr int kDecodeStatusCount = static_cast<int>(DecodeStatus::kEmptyPacket) + 1;

const char* to_string(DecodeStatus status);

struct DecodeResult {
  DecodeStatus status = DecodeStatus::kOk;
  uint32_t offset = 0;  // byte offset of the descriptor at fault

  bool ok() const { return status == DecodeStatus::kOk; }
};

// Decodes and validates a whole payload into `out` (cleared first; its capacity is kept).
// Reads nothing outside `payload`; time is linear in its size. On error `out` holds no
// usable packet.
DecodeResult decode_payload(std::span<const uint8_t> payload, Packet& out);

enum class EncodeStatus : uint8_t {
  kOk = 0,
  kInvalidFap,              // a FAP or recovery entry outside the ranges of model.h
  kInvalidPhoneme,          // a phoneme outside the ranges of model.h
  kInvalidCoverage,         // kDynamic with covered_packets not in kCoverageSteps
  kEndOfTextNotLast,        // end_of_text on a phoneme other than the last
  kDataInCompleteRecovery,  // kComplete with phonemes
  kRecoveryWithoutKind,     // entries with RecoveryKind::kNone
  kEmptyPacket,             // nothing to send
  kBufferTooSmall,          // out is smaller than encoded_size()
  kBadFapEnd,               // fap_end values not ascending or past faps.size()
};

const char* to_string(EncodeStatus status);

// The payload size of `packet` in bytes.
size_t encoded_size(const Packet& packet);

// Checks `packet` and writes exactly encoded_size(packet) bytes to the front of `out`.
// On error nothing usable is written.
EncodeStatus encode_payload(const Packet& packet, std::span<uint8_t> out);

}  // namespace pfap
