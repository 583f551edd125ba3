// SPDX-License-Identifier: LGPL-2.1-or-later
// Payload encoder and decoder: byte-exact vectors from the draft's figures, round trips, and
// one test per class of bad payload.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "pfap/payload.h"
#include "random_markup.h"

namespace pfap {
namespace {

using Bytes = std::vector<uint8_t>;

Bytes encode(const Packet& packet) {
  Bytes out(encoded_size(packet));
  EXPECT_EQ(encode_payload(packet, out), EncodeStatus::kOk);
  return out;
}

DecodeResult decode(const Bytes& bytes) {
  Packet packet;
  return decode_payload(bytes, packet);
}

Packet packet_of(RecoveryKind kind, uint8_t covered, std::vector<Fap> recovery) {
  Packet p;
  p.recovery_kind = kind;
  p.covered_packets = covered;
  p.recovery = std::move(recovery);
  return p;
}

// Each vector: the packet, and the bytes worked out by hand from Figures 2 to 5, field by
// field, MSB first (the comment under each gives the fields' bits in order).
struct Vector {
  const char* name;
  Packet packet;
  Bytes bytes;
};

std::vector<Vector> vectors() {
  std::vector<Vector> v;
  {
    // PD   C=0 T=00 PP=000 IB=00                                     0 00 000 00 -> 00
    // Ph   sym 42, dur 100, f0 60 (120 Hz), S=1, W=1, IB=11 (end of text)
    //      00101010 000001100100 00111100 1 1 11                      -> 2A 06 43 CF
    Packet p;
    p.add_phoneme({.symbol = 42,
                   .duration_ms = 100,
                   .f0 = 60,
                   .stress = true,
                   .word_begin = true,
                   .end_of_text = true},
                  {});
    v.push_back({"one_phoneme_end_of_text", p, {0x00, 0x2A, 0x06, 0x43, 0xCF}});
  }
  {
    // The draft's example <FAP 2 1 40 2 30 2000 3> = <FAP 69 40 2000 3><FAP 70 30 2000 3>,
    // starting with a phoneme.
    // PD   C=0 T=00 PP=000 IB=01 (FAP follows)                       0 00 000 01 -> 01
    // FAP  ind 69, s=0, a=40, T=2000, C=3, IB=01 (FAP follows)
    //      1000101 0 0000000000000000101000 00011111010000 11 01      -> 8A 00 00 A0 7D 0D
    // FAP  ind 70, s=0, a=30, T=2000, C=3, IB=00 (phoneme follows)
    //      1000110 0 0000000000000000011110 00011111010000 11 00      -> 8C 00 00 78 7D 0C
    // Ph   sym 7, dur 80, f0 0, S=0, W=1, IB=10 (end of packet)
    //      00000111 000001010000 00000000 0 1 10                      -> 07 05 00 06
    Packet p;
    const Fap faps[] = {{69, 40, 2000, Curve::kSpline}, {70, 30, 2000, Curve::kSpline}};
    p.add_phoneme({.symbol = 7, .duration_ms = 80, .word_begin = true}, faps);
    v.push_back({"draft_expression_example",
                 p,
                 {0x01, 0x8A, 0x00, 0x00, 0xA0, 0x7D, 0x0D, 0x8C, 0x00, 0x00, 0x78, 0x7D, 0x0C,
                  0x07, 0x05, 0x00, 0x06}});
  }
  {
    // Dynamic recovery over 4 packets with two entries at the field extremes, then a phoneme
    // with every field at its maximum.
    // PD   C=0 T=01 PP=011 (4 packets) IB=00                         0 01 011 00 -> 2C
    // Rec  ind 48, s=1, a=20000, T=0, C=1, IB=00 (entry follows)
    //      0110000 1 0000000100111000100000 00000000000000 01 00      -> 61 01 38 80 00 04
    // Rec  ind 74, s=0, a=2529600, T=16383, C=2, IB=11 (end of recovery)
    //      1001010 0 1001101001100101000000 11111111111111 10 11      -> 94 9A 65 03 FF FB
    // Ph   sym 255, dur 4095, f0 255, S=1, W=0, IB=10
    //      11111111 111111111111 11111111 1 0 10                      -> FF FF FF FA
    Packet p = packet_of(
        RecoveryKind::kDynamic, 4,
        {{48, -20000, 0, Curve::kLinear}, {74, kMaxAmplitude, kMaxTransitionMs, Curve::kTriangle}});
    p.add_phoneme({.symbol = 255, .duration_ms = 4095, .f0 = 255, .stress = true}, {});
    v.push_back({"dynamic_recovery_extremes",
                 p,
                 {0x2C, 0x61, 0x01, 0x38, 0x80, 0x00, 0x04, 0x94, 0x9A, 0x65, 0x03, 0xFF, 0xFB,
                  0xFF, 0xFF, 0xFF, 0xFA}});
  }
  {
    // PD   C=1 T=01 PP=000 IB=10 (end of packet)                     1 01 000 10 -> A2
    // Rec  ind 3, s=0, a=100, T=0, C=1, IB=11
    //      0000011 0 0000000000000001100100 00000000000000 01 11      -> 06 00 01 90 00 07
    Packet p = packet_of(RecoveryKind::kComplete, 0, {{3, 100, 0, Curve::kLinear}});
    v.push_back({"complete_recovery", p, {0xA2, 0x06, 0x00, 0x01, 0x90, 0x00, 0x07}});
  }
  {
    // Complete recovery with no entry: every FAP is 0.    1 00 000 10 -> 82
    v.push_back({"complete_recovery_all_zero", packet_of(RecoveryKind::kComplete, 0, {}), {0x82}});
  }
  {
    // Dynamic recovery with nothing to recover: T=00 with PP set (our reading, format.md).
    // PD   C=0 T=00 PP=001 (1 packet) IB=00                          0 00 001 00 -> 04
    // Ph   sym 0, dur 0, f0 0, S=0, W=0, IB=10                        -> 00 00 00 02
    Packet p = packet_of(RecoveryKind::kDynamic, 1, {});
    p.add_phoneme({}, {});
    v.push_back({"dynamic_recovery_nothing_to_recover", p, {0x04, 0x00, 0x00, 0x00, 0x02}});
  }
  {
    // Phoneme, then a FAP, then a phoneme: the first phoneme's IB announces the FAP.
    // PD   IB=00                                                      -> 00
    // Ph   sym 1, dur 1, f0 1, S=0, W=1, IB=01                        -> 01 00 10 15
    //      00000001 000000000001 00000001 0 1 01
    // FAP  ind 19, s=1, a=1, T=1, C=1, IB=00
    //      0010011 1 0000000000000000000001 00000000000001 01 00      -> 27 00 00 04 00 14
    // Ph   sym 2, dur 2, f0 2, S=0, W=0, IB=10                        -> 02 00 20 22
    //      00000010 000000000010 00000010 0 0 10
    Packet p;
    p.add_phoneme({.symbol = 1, .duration_ms = 1, .f0 = 1, .word_begin = true}, {});
    const Fap fap[] = {{19, -1, 1, Curve::kLinear}};
    p.add_phoneme({.symbol = 2, .duration_ms = 2, .f0 = 2}, fap);
    v.push_back({"fap_between_phonemes",
                 p,
                 {0x00, 0x01, 0x00, 0x10, 0x15, 0x27, 0x00, 0x00, 0x04, 0x00, 0x14, 0x02, 0x00,
                  0x20, 0x22}});
  }
  return v;
}

TEST(PayloadVectors, EncodeGivesTheHandDerivedBytes) {
  for (const Vector& v : vectors()) {
    SCOPED_TRACE(v.name);
    EXPECT_EQ(encoded_size(v.packet), v.bytes.size());
    EXPECT_EQ(encode(v.packet), v.bytes);
  }
}

TEST(PayloadVectors, DecodeGivesThePacketBack) {
  for (const Vector& v : vectors()) {
    SCOPED_TRACE(v.name);
    Packet decoded;
    const DecodeResult result = decode_payload(v.bytes, decoded);
    ASSERT_TRUE(result.ok()) << to_string(result.status) << " at " << result.offset;
    EXPECT_EQ(decoded, v.packet);
  }
}

// Seeded random packets of every kind survive encode then decode field for field, and the
// re-encoded bytes are the same.
TEST(PayloadRoundTrip, RandomPacketsKeepEveryField) {
  testing::RandomMarkup random(20261121);
  Packet decoded;
  for (int n = 0; n < 5000; ++n) {
    Packet packet;
    const int kind = random.uniform(0, 2);
    if (kind == 2) {
      packet.recovery_kind = RecoveryKind::kComplete;
    } else if (kind == 1) {
      packet.recovery_kind = RecoveryKind::kDynamic;
      packet.covered_packets = kCoverageSteps[random.uniform(0, 6)];
    }
    if (kind != 0) {
      for (int i = random.uniform(0, 8); i > 0; --i) packet.recovery.push_back(random.fap());
    }
    if (kind != 2) {
      const int phonemes = random.uniform(packet.recovery.empty() ? 1 : 0, 30);
      for (int i = 0; i < phonemes; ++i) {
        std::vector<Fap> faps;
        for (int j = random.chance(0.7) ? 0 : random.uniform(1, 6); j > 0; --j) {
          faps.push_back(random.fap());
        }
        Phoneme phoneme = random.phoneme();
        phoneme.end_of_text = i + 1 == phonemes && random.chance(0.3);
        packet.add_phoneme(phoneme, faps);
      }
    }
    SCOPED_TRACE(n);
    const Bytes bytes = encode(packet);
    const DecodeResult result = decode_payload(bytes, decoded);
    ASSERT_TRUE(result.ok()) << to_string(result.status) << " at " << result.offset;
    ASSERT_EQ(decoded, packet);
    ASSERT_EQ(encode(decoded), bytes);
  }
}

// One case per class of bad payload; each starts from a valid payload and breaks one thing.
struct BadPayload {
  const char* name;
  Bytes bytes;
  DecodeStatus status;
  uint32_t offset;
};

TEST(PayloadDecodeErrors, EachClassIsReportedWithItsOffset) {
  // A valid FAP descriptor (ind 3, a=100, T=0, C=1) with its IB in the last byte.
  const auto fap = [](uint8_t last) { return Bytes{0x06, 0x00, 0x01, 0x90, 0x00, last}; };
  const auto cat = [](std::initializer_list<Bytes> parts) {
    Bytes out;
    for (const Bytes& part : parts) out.insert(out.end(), part.begin(), part.end());
    return out;
  };
  const Bytes phoneme_end = {0x00, 0x00, 0x00, 0x02};
  const std::vector<BadPayload> cases = {
      {"empty_payload", {}, DecodeStatus::kTruncated, 0},
      {"phoneme_cut_short", {0x00, 0x00, 0x00, 0x00}, DecodeStatus::kTruncated, 1},
      {"fap_cut_short", cat({{0x01}, {0x06, 0x00, 0x01}}), DecodeStatus::kTruncated, 1},
      {"recovery_cut_short", {0x24, 0x06, 0x00}, DecodeStatus::kTruncated, 1},
      {"reserved_type_10", cat({{0x40}, phoneme_end}), DecodeStatus::kReservedRecoveryType, 0},
      {"reserved_type_11", cat({{0x60}, phoneme_end}), DecodeStatus::kReservedRecoveryType, 0},
      {"reserved_ib_in_packet_descriptor", cat({{0x03}, phoneme_end}),
       DecodeStatus::kReservedInfoBits, 0},
      {"reserved_ib_01_in_recovery", cat({{0x24}, fap(0x05), phoneme_end}),
       DecodeStatus::kReservedInfoBits, 1},
      {"reserved_ib_10_in_recovery", cat({{0x24}, fap(0x06), phoneme_end}),
       DecodeStatus::kReservedInfoBits, 1},
      {"reserved_ib_10_in_fap", cat({{0x01}, fap(0x06), phoneme_end}),
       DecodeStatus::kReservedInfoBits, 1},
      {"reserved_ib_11_in_fap", cat({{0x01}, fap(0x07), phoneme_end}),
       DecodeStatus::kReservedInfoBits, 1},
      {"dynamic_recovery_with_pp_000", cat({{0x20}, fap(0x07), phoneme_end}),
       DecodeStatus::kMissingCoverage, 0},
      {"fap_index_2", cat({{0x01}, {0x04, 0x00, 0x01, 0x90, 0x00, 0x04}, phoneme_end}),
       DecodeStatus::kFapIndexOutOfRange, 1},
      {"fap_index_75", cat({{0x01}, {0x96, 0x00, 0x01, 0x90, 0x00, 0x04}, phoneme_end}),
       DecodeStatus::kFapIndexOutOfRange, 1},
      {"recovery_fap_index_0", cat({{0x24}, {0x00, 0x00, 0x01, 0x90, 0x00, 0x07}, phoneme_end}),
       DecodeStatus::kFapIndexOutOfRange, 1},
      // 2529601 = 0x269941: 0000011 0 1001101001100101000001 00000000000000 01 00
      //                                                        -> 06 9A 65 04 00 04
      {"amplitude_2529601", cat({{0x01}, {0x06, 0x9A, 0x65, 0x04, 0x00, 0x04}, phoneme_end}),
       DecodeStatus::kAmplitudeOutOfRange, 1},
      {"amplitude_all_ones", cat({{0x01}, {0x07, 0xFF, 0xFF, 0xFC, 0x00, 0x04}, phoneme_end}),
       DecodeStatus::kAmplitudeOutOfRange, 1},
      {"curve_0_in_fap", cat({{0x01}, fap(0x00), phoneme_end}), DecodeStatus::kCurveZero, 1},
      {"curve_0_in_recovery", cat({{0x24}, fap(0x03), phoneme_end}), DecodeStatus::kCurveZero, 1},
      {"ends_with_fap", cat({{0x01}, fap(0x04)}), DecodeStatus::kMissingFinalPhoneme, 7},
      {"ends_after_phoneme_that_announces_more",
       {0x00, 0x00, 0x00, 0x00, 0x00},
       DecodeStatus::kMissingFinalPhoneme,
       5},
      {"descriptor_only_announcing_phoneme", {0x00}, DecodeStatus::kMissingFinalPhoneme, 1},
      {"bytes_after_end_of_packet", cat({{0x00}, phoneme_end, {0x00}}),
       DecodeStatus::kTrailingBytes, 5},
      {"bytes_after_end_of_text",
       {0x00, 0x00, 0x00, 0x00, 0x03, 0xFF, 0xFF},
       DecodeStatus::kTrailingBytes,
       5},
      {"bytes_after_complete_recovery", {0x82, 0x00}, DecodeStatus::kTrailingBytes, 1},
      {"complete_recovery_announcing_phoneme", cat({{0x80}, phoneme_end}),
       DecodeStatus::kDataInCompleteRecovery, 0},
      {"complete_recovery_announcing_fap", cat({{0xA1}, fap(0x07), fap(0x04), phoneme_end}),
       DecodeStatus::kDataInCompleteRecovery, 0},
      {"recovery_list_never_ends", cat({{0x24}, fap(0x04), fap(0x04)}),
       DecodeStatus::kUnterminatedRecovery, 13},
      {"nothing_at_all", {0x02}, DecodeStatus::kEmptyPacket, 0},
      {"nothing_but_coverage", {0x06}, DecodeStatus::kEmptyPacket, 0},
  };
  for (const BadPayload& c : cases) {
    SCOPED_TRACE(c.name);
    const DecodeResult result = decode(c.bytes);
    EXPECT_EQ(result.status, c.status) << to_string(result.status);
    EXPECT_EQ(result.offset, c.offset);
  }
}

TEST(PayloadDecodeErrors, EveryStatusHasItsOwnName) {
  std::set<std::string> names;
  for (int i = 0; i < kDecodeStatusCount; ++i) {
    names.insert(to_string(static_cast<DecodeStatus>(i)));
  }
  EXPECT_EQ(names.size(), static_cast<size_t>(kDecodeStatusCount));
  EXPECT_EQ(names.count("unknown"), 0u);
}

TEST(PayloadDecodeErrors, BadPayloadLeavesNoPartialPacket) {
  Packet packet;
  const Bytes bad = {0x01, 0x06, 0x00, 0x01, 0x90, 0x00, 0x04, 0x00, 0x00, 0x00, 0x02, 0xFF};
  EXPECT_EQ(decode_payload(bad, packet).status, DecodeStatus::kTrailingBytes);
  EXPECT_EQ(packet, Packet{});
}

// Every prefix of a valid payload is refused (never read past its end: the ASan build checks
// the reads), and is refused for the reason its cut gives.
TEST(PayloadDecodeErrors, EveryPrefixOfAValidPayloadIsRefused) {
  for (const Vector& v : vectors()) {
    SCOPED_TRACE(v.name);
    for (size_t length = 0; length < v.bytes.size(); ++length) {
      const Bytes prefix(v.bytes.begin(), v.bytes.begin() + static_cast<long>(length));
      const DecodeStatus status = decode(prefix).status;
      EXPECT_TRUE(status == DecodeStatus::kTruncated ||
                  status == DecodeStatus::kMissingFinalPhoneme ||
                  status == DecodeStatus::kUnterminatedRecovery)
          << length << ": " << to_string(status);
    }
  }
}

TEST(PayloadDecode, NegativeZeroAmplitudeReadsAsZero) {
  Packet packet;
  const Bytes bytes = {0x01, 0x07, 0x00, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x02};
  ASSERT_TRUE(decode_payload(bytes, packet).ok());
  EXPECT_EQ(packet.faps.at(0).amplitude, 0);
}

TEST(PayloadDecode, CompleteRecoveryIgnoresPP) {
  Packet packet;
  ASSERT_TRUE(decode_payload(Bytes{0x9E}, packet).ok());  // 1 00 111 10
  EXPECT_EQ(packet.recovery_kind, RecoveryKind::kComplete);
  EXPECT_EQ(packet.covered_packets, 0);
}

TEST(PayloadDecode, ReusedPacketKeepsItsCapacity) {
  const Vector v = vectors()[1];
  Packet packet;
  ASSERT_TRUE(decode_payload(v.bytes, packet).ok());
  const Fap* faps = packet.faps.data();
  ASSERT_TRUE(decode_payload(v.bytes, packet).ok());
  EXPECT_EQ(packet.faps.data(), faps);
}

struct BadPacket {
  const char* name;
  Packet packet;
  EncodeStatus status;
};

TEST(PayloadEncodeErrors, InvalidPacketsAreRefused) {
  const Phoneme phoneme{.symbol = 1, .duration_ms = 10};
  const auto with_phonemes = [](Packet p, std::vector<Phoneme> phonemes,
                                std::vector<Fap> first_faps = {}) {
    for (size_t i = 0; i < phonemes.size(); ++i) {
      p.add_phoneme(phonemes[i],
                    i == 0 ? std::span<const Fap>(first_faps) : std::span<const Fap>());
    }
    return p;
  };
  const Fap good{3, 1, 1, Curve::kLinear};
  Fap index_2 = good, amplitude_over = good, transition_over = good, curve_0 = good;
  index_2.index = 2;
  amplitude_over.amplitude = -kMaxAmplitude - 1;
  transition_over.transition_ms = kMaxTransitionMs + 1;
  curve_0.curve = static_cast<Curve>(0);
  Phoneme long_phoneme = phoneme, ended = phoneme;
  long_phoneme.duration_ms = kMaxPhonemeDurationMs + 1;
  ended.end_of_text = true;
  Packet faps_without_phoneme;
  faps_without_phoneme.faps.push_back(good);
  Packet fap_end_past_faps = with_phonemes({}, {phoneme});
  fap_end_past_faps.phonemes[0].fap_end = 1;

  const std::vector<BadPacket> cases = {
      {"fap_index_2", with_phonemes({}, {phoneme}, {index_2}), EncodeStatus::kInvalidFap},
      {"amplitude_over", with_phonemes({}, {phoneme}, {amplitude_over}), EncodeStatus::kInvalidFap},
      {"transition_over", with_phonemes({}, {phoneme}, {transition_over}),
       EncodeStatus::kInvalidFap},
      {"curve_0", with_phonemes({}, {phoneme}, {curve_0}), EncodeStatus::kInvalidFap},
      {"recovery_entry_invalid",
       with_phonemes(packet_of(RecoveryKind::kDynamic, 1, {index_2}), {phoneme}),
       EncodeStatus::kInvalidFap},
      {"phoneme_over_4095_ms", with_phonemes({}, {long_phoneme}), EncodeStatus::kInvalidPhoneme},
      {"coverage_3", with_phonemes(packet_of(RecoveryKind::kDynamic, 3, {}), {phoneme}),
       EncodeStatus::kInvalidCoverage},
      {"end_of_text_first_of_two", with_phonemes({}, {ended, phoneme}),
       EncodeStatus::kEndOfTextNotLast},
      {"complete_with_phoneme", with_phonemes(packet_of(RecoveryKind::kComplete, 0, {}), {phoneme}),
       EncodeStatus::kDataInCompleteRecovery},
      {"recovery_entries_without_kind",
       with_phonemes(packet_of(RecoveryKind::kNone, 0, {good}), {phoneme}),
       EncodeStatus::kRecoveryWithoutKind},
      {"nothing", Packet{}, EncodeStatus::kEmptyPacket},
      {"dynamic_nothing", packet_of(RecoveryKind::kDynamic, 2, {}), EncodeStatus::kEmptyPacket},
      {"faps_without_phoneme", faps_without_phoneme, EncodeStatus::kEmptyPacket},
      {"fap_end_past_faps", fap_end_past_faps, EncodeStatus::kBadFapEnd},
  };
  for (const BadPacket& c : cases) {
    SCOPED_TRACE(c.name);
    Bytes out(64);
    EXPECT_EQ(encode_payload(c.packet, out), c.status) << to_string(encode_payload(c.packet, out));
  }
}

TEST(PayloadEncodeErrors, TooSmallBufferIsRefused) {
  const Vector v = vectors()[1];
  Bytes out(v.bytes.size() - 1);
  EXPECT_EQ(encode_payload(v.packet, out), EncodeStatus::kBufferTooSmall);
}

TEST(PayloadCoverage, OnlyTheSevenPPValuesAreValid) {
  std::vector<unsigned> valid;
  for (unsigned n = 0; n <= 64; ++n) {
    if (is_valid_coverage(n)) valid.push_back(n);
  }
  EXPECT_EQ(valid, (std::vector<unsigned>{1, 2, 4, 7, 15, 25, 40}));
}

}  // namespace
}  // namespace pfap

namespace pfap {
namespace {

// The shipped sample was made by an independent bit packer (samples/hello.pfap-hex): every
// payload decodes, and the library's encoder gives the same bytes back.
TEST(PayloadSample, IndependentlyPackedSampleDecodesAndReencodesToTheSameBytes) {
  std::ifstream file(PFAP_SAMPLES_DIR "/hello.pfap-hex");
  ASSERT_TRUE(file) << "cannot open the sample";
  int payloads = 0;
  for (std::string line; std::getline(file, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream hex(line);
    Bytes bytes;
    for (unsigned byte; hex >> std::hex >> byte;) bytes.push_back(static_cast<uint8_t>(byte));
    SCOPED_TRACE(line);
    Packet packet;
    const DecodeResult result = decode_payload(bytes, packet);
    ASSERT_TRUE(result.ok()) << to_string(result.status) << " at " << result.offset;
    EXPECT_EQ(encode(packet), bytes);
    ++payloads;
  }
  EXPECT_EQ(payloads, 4);
}

}  // namespace
}  // namespace pfap
