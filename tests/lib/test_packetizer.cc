// SPDX-License-Identifier: LGPL-2.1-or-later
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "pfap/packetizer.h"
#include "random_markup.h"

namespace pfap {
namespace {

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kSecond = 1'000'000'000;

// ---------------------------------------------------------------------------------------
// rtp_ticks

struct TicksCase {
  int64_t time_ns;
  uint32_t clock_rate;
  uint32_t ticks;
};

TEST(RtpTicks, RoundsToNearestTickAndWrapsTo32Bits) {
  constexpr int64_t kMax = std::numeric_limits<int64_t>::max();
  constexpr int64_t kMin = std::numeric_limits<int64_t>::min();
  const TicksCase cases[] = {
      {0, 44100, 0},
      {kSecond, 44100, 44100},
      {kSecond, 90000, 90000},
      {90 * kSecond, 90000, 8'100'000},
      {11'337, 44100, 0},  // 0.49997 ticks
      {11'338, 44100, 1},  // 0.50002 ticks
      {500'000, 1000, 1},  // exactly half a tick rounds up
      {499'999, 1000, 0},
      {-500'000, 1000, 0},  // halves round up below zero too
      {-500'001, 1000, 0xFFFF'FFFF},
      {-11'337, 44100, 0},
      {-11'338, 44100, 0xFFFF'FFFF},             // -1 wraps
      {-kSecond, 44100, 4'294'923'196},          // 2^32 - 44100
      {47'721'858'835'000, 90000, 0xFFFF'FFFF},  // last tick before 2^32
      {47'721'858'844'444, 90000, 0},            // 2^32 ticks wrap to 0
      {(int64_t{1} << 32) * kSecond / 1'000'000'000 + 5, 1'000'000'000, 5},
      {kMax, 44100, 124'024'912},
      {kMin, 44100, 4'170'942'384},
      {kMax, 0xFFFF'FFFF, 3'037'796'692},  // no intermediate overflow
      {kSecond, 0, 0},
  };
  for (const TicksCase& c : cases) {
    EXPECT_EQ(rtp_ticks(c.time_ns, c.clock_rate), c.ticks)
        << c.time_ns << " ns at " << c.clock_rate << " Hz";
  }
}

// ---------------------------------------------------------------------------------------
// Helpers

TimedPhoneme phoneme_at(int64_t start_ns, uint16_t duration_ms, bool sentence_start = false,
                        bool end_of_text = false) {
  TimedPhoneme p;
  p.start_ns = start_ns;
  p.phoneme.symbol = static_cast<uint8_t>(start_ns / kMs);
  p.phoneme.duration_ms = duration_ms;
  p.phoneme.end_of_text = end_of_text;
  p.sentence_start = sentence_start;
  return p;
}

// `count` distinct valid FAPs.
std::vector<Fap> faps(size_t count, int seed = 0) {
  std::vector<Fap> out;
  for (size_t i = 0; i < count; ++i) {
    out.push_back({static_cast<uint8_t>(kMinFapIndex + i % 70), seed * 100 + static_cast<int>(i),
                   static_cast<uint16_t>(i), Curve::kSpline});
  }
  return out;
}

PacketizerConfig config(size_t max_payload_size = 1388, int64_t max_delay_ns = 10 * kSecond) {
  return {max_payload_size, max_delay_ns};
}

// Pushes `count` contiguous 1 ms phonemes with `fap_count` FAPs each, then drains.
std::vector<PlannedPacket> plan_uniform(const PacketizerConfig& cfg, size_t count,
                                        size_t fap_count) {
  Packetizer packetizer(cfg);
  std::vector<PlannedPacket> out;
  for (size_t i = 0; i < count; ++i) {
    packetizer.push(phoneme_at(static_cast<int64_t>(i) * kMs, 1), faps(fap_count, int(i)), out);
  }
  packetizer.drain(out);
  return out;
}

std::vector<size_t> phoneme_counts(const std::vector<PlannedPacket>& packets) {
  std::vector<size_t> counts;
  for (const PlannedPacket& p : packets) counts.push_back(p.packet.phonemes.size());
  return counts;
}

// ---------------------------------------------------------------------------------------
// Packet fields

TEST(Packetizer, NewPacketTakesStartTimestampAndMarkerFromItsFirstPhoneme) {
  Packetizer packetizer(config());
  std::vector<PlannedPacket> out;
  packetizer.push(phoneme_at(2 * kSecond, 10, true), faps(2), out);
  packetizer.push(phoneme_at(2 * kSecond + 10 * kMs, 10), {}, out);
  packetizer.drain(out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].start_ns, 2 * kSecond);
  EXPECT_TRUE(out[0].marker);
  EXPECT_FALSE(out[0].oversized);
  EXPECT_EQ(out[0].packet.recovery_kind, RecoveryKind::kNone);
  EXPECT_TRUE(out[0].packet.recovery.empty());
  EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{2}));
}

// ---------------------------------------------------------------------------------------
// FAPs stay with their phoneme; packets end with a phoneme

TEST(Packetizer, FapsNeverSplitFromTheirPhonemeAtAnySizeBoundary) {
  for (size_t max_size = 1; max_size <= 80; ++max_size) {
    Packetizer packetizer(config(max_size));
    std::vector<PlannedPacket> out;
    std::vector<std::vector<Fap>> pushed;
    for (int i = 0; i < 30; ++i) {
      pushed.push_back(faps(static_cast<size_t>(i % 4), i));
      packetizer.push(phoneme_at(i * kMs, 1), pushed.back(), out);
    }
    packetizer.drain(out);

    size_t next = 0;
    for (const PlannedPacket& p : out) {
      ASSERT_FALSE(p.packet.phonemes.empty()) << "max " << max_size;
      EXPECT_EQ(p.packet.phonemes.back().fap_end, p.packet.faps.size()) << "max " << max_size;
      for (size_t i = 0; i < p.packet.phonemes.size(); ++i, ++next) {
        ASSERT_LT(next, pushed.size());
        const std::span<const Fap> got = p.packet.faps_of(i);
        EXPECT_EQ(std::vector<Fap>(got.begin(), got.end()), pushed[next])
            << "max " << max_size << ", phoneme " << next;
      }
    }
    EXPECT_EQ(next, pushed.size()) << "max " << max_size;
  }
}

TEST(Packetizer, FlushWithNothingPendingAppendsNoEmptyPacket) {
  Packetizer packetizer(config());
  std::vector<PlannedPacket> out;
  packetizer.drain(out);
  EXPECT_TRUE(out.empty());
  EXPECT_FALSE(packetizer.has_pending());
}

// ---------------------------------------------------------------------------------------
// Sentence start and end of text

TEST(Packetizer, SentenceStartBeginsANewPacketWithMarker) {
  Packetizer packetizer(config());
  std::vector<PlannedPacket> out;
  packetizer.push(phoneme_at(0, 10), {}, out);
  packetizer.push(phoneme_at(10 * kMs, 10), {}, out);
  EXPECT_TRUE(out.empty());
  packetizer.push(phoneme_at(20 * kMs, 10, true), faps(1), out);
  ASSERT_EQ(out.size(), 1u);  // completed by the sentence start, before it
  EXPECT_FALSE(out[0].marker);
  packetizer.push(phoneme_at(30 * kMs, 10), {}, out);
  packetizer.drain(out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{2, 2}));
  EXPECT_TRUE(out[1].marker);
  EXPECT_EQ(out[1].start_ns, 20 * kMs);
  EXPECT_EQ(out[1].packet.faps, faps(1));
}

TEST(Packetizer, EndOfTextCompletesThePacketAtOnce) {
  Packetizer packetizer(config());
  std::vector<PlannedPacket> out;
  packetizer.push(phoneme_at(0, 10, true), {}, out);
  packetizer.push(phoneme_at(10 * kMs, 10, false, true), faps(1), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FALSE(packetizer.has_pending());
  EXPECT_TRUE(out[0].packet.phonemes.back().phoneme.end_of_text);
  EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{2}));

  // The next phoneme, contiguous or not, starts a packet of its own.
  packetizer.push(phoneme_at(20 * kMs, 10), {}, out);
  packetizer.drain(out);
  EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{2, 1}));
  EXPECT_FALSE(out[1].marker);
}

// ---------------------------------------------------------------------------------------
// Contiguity

TEST(Packetizer, GapStartsANewPacketWhileSubMillisecondJitterDoesNot) {
  struct Case {
    int64_t offset_ns;  // second phoneme's start less the first's end
    size_t packets;
  };
  const Case cases[] = {
      {0, 1},        {500'000, 1}, {-500'000, 1}, {500'001, 2},
      {-500'001, 2}, {1 * kMs, 2}, {-5 * kMs, 2}, {300 * kMs, 2},
  };
  for (const Case& c : cases) {
    Packetizer packetizer(config());
    std::vector<PlannedPacket> out;
    packetizer.push(phoneme_at(kSecond, 40), {}, out);
    packetizer.push(phoneme_at(kSecond + 40 * kMs + c.offset_ns, 40), {}, out);
    packetizer.drain(out);
    EXPECT_EQ(out.size(), c.packets) << "offset " << c.offset_ns << " ns";
  }
}

TEST(Packetizer, ContiguityIsMeasuredFromTheFirstStartSoRoundingDoesNotAccumulate) {
  // Phonemes really 10.4 ms long, sent as 10 ms: each is 0.4 ms off its predecessor's end,
  // but the third is 0.8 ms off the first's start plus the durations.
  Packetizer packetizer(config());
  std::vector<PlannedPacket> out;
  for (int i = 0; i < 4; ++i) packetizer.push(phoneme_at(i * 10'400'000, 10), {}, out);
  packetizer.drain(out);
  EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{2, 2}));

  // Jitter around the first start plus the durations keeps one packet.
  out.clear();
  for (int i = 0; i < 8; ++i) {
    const int64_t jitter_ns = i == 0 ? 0 : i % 2 ? 400'000 : -400'000;
    packetizer.push(phoneme_at(i * 10 * kMs + jitter_ns, 10), {}, out);
  }
  packetizer.drain(out);
  EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{8}));
}

// ---------------------------------------------------------------------------------------
// Delay bound

TEST(Packetizer, PacketCompletesAtOnceWhenItsSpanReachesMaxDelay) {
  struct Case {
    std::vector<uint16_t> durations_ms;
    bool completed_at_once;
  };
  const Case cases[] = {
      {{30, 30, 30}, false},     // spans 90 ms: a fourth phoneme may still join
      {{30, 30, 39}, false},     // 99 ms
      {{30, 30, 40}, true},      // exactly 100 ms
      {{30, 30, 30, 30}, true},  // 120 ms: the last phoneme may reach past the bound
      {{100}, true},             // one phoneme as long as the bound
      {{250}, true},             // one phoneme longer than the bound
  };
  for (const Case& c : cases) {
    Packetizer packetizer(config(1388, 100 * kMs));
    std::vector<PlannedPacket> out;
    int64_t start = 0;
    for (uint16_t d : c.durations_ms) {
      packetizer.push(phoneme_at(start, d), {}, out);
      start += d * kMs;
    }
    EXPECT_EQ(packetizer.has_pending(), !c.completed_at_once) << c.durations_ms.size();
    packetizer.drain(out);
    EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{c.durations_ms.size()}));
  }
}

TEST(Packetizer, PhonemeStartingMaxDelayAfterThePacketStartBeginsANewPacket) {
  // Span 99 ms < 99.4 ms, so the packet stays open; the next phoneme is contiguous (0.4 ms
  // late) but starts 99.4 ms after the first, so it may not join.
  struct Case {
    int64_t next_start_ns;
    std::vector<size_t> packets;
  };
  const Case cases[] = {
      {99'400'000, {1, 1}},
      {99'300'000, {2}},
  };
  for (const Case& c : cases) {
    Packetizer packetizer(config(1388, 99'400'000));
    std::vector<PlannedPacket> out;
    packetizer.push(phoneme_at(0, 99), {}, out);
    ASSERT_TRUE(packetizer.has_pending());
    packetizer.push(phoneme_at(c.next_start_ns, 10), {}, out);
    packetizer.drain(out);
    EXPECT_EQ(phoneme_counts(out), c.packets) << c.next_start_ns;
  }
}

TEST(Packetizer, ZeroMaxDelaySendsEachPhonemeAlone) {
  EXPECT_EQ(phoneme_counts(plan_uniform(config(1388, 0), 3, 1)), (std::vector<size_t>{1, 1, 1}));
}

// ---------------------------------------------------------------------------------------
// Size limit

TEST(Packetizer, PacketsFillUpToMaxPayloadSize) {
  struct Case {
    size_t max_payload_size;
    size_t fap_count;  // per phoneme
    size_t phoneme_count;
    std::vector<size_t> packets;  // phonemes per packet
    size_t first_packet_bytes;
  };
  const Case cases[] = {
      {16, 0, 7, {3, 3, 1}, 13},  // 13 bytes leave no room for a phoneme
      {17, 0, 9, {4, 4, 1}, 17},  // exact fit
      {16, 1, 3, {1, 1, 1}, 11},  // 11 + 10 > 16
      {21, 1, 3, {2, 1}, 21},     // exact fit with FAPs
      {11, 1, 2, {1, 1}, 11},     // one phoneme with one FAP fits exactly
      {64, 0, 40, {15, 15, 10}, 61},
      {64, 1, 13, {6, 6, 1}, 61},
      {64, 3, 6, {2, 2, 2}, 45},  // 45 + 22 > 64, yet 19 bytes are left
      {1388, 0, 700, {346, 346, 8}, 1385},
      {1388, 1, 300, {138, 138, 24}, 1381},
      {1388, 5, 80, {40, 40}, 1361},
  };
  for (const Case& c : cases) {
    const std::vector<PlannedPacket> out =
        plan_uniform(config(c.max_payload_size), c.phoneme_count, c.fap_count);
    EXPECT_EQ(phoneme_counts(out), c.packets)
        << "max " << c.max_payload_size << ", " << c.fap_count << " FAPs";
    ASSERT_FALSE(out.empty());
    EXPECT_EQ(encoded_size(out[0].packet), c.first_packet_bytes) << "max " << c.max_payload_size;
    for (const PlannedPacket& p : out) {
      EXPECT_FALSE(p.oversized);
      EXPECT_LE(encoded_size(p.packet), c.max_payload_size);
    }
  }
}

TEST(Packetizer, PacketCompletesAtOnceWhenNoFurtherPhonemeFits) {
  struct Case {
    size_t max_payload_size;
    size_t fap_count;
    size_t phoneme_count;
    bool completed_at_once;
  };
  const Case cases[] = {
      {16, 0, 2, false},  // 9 bytes: 7 left
      {16, 0, 3, true},   // 13 bytes: 3 left
      {17, 0, 3, false},  // 13 bytes: 4 left, one more bare phoneme fits
      {17, 0, 4, true},   // full
      {14, 1, 1, true},   // 11 bytes: 3 left
      {15, 1, 1, false},  // 11 bytes: 4 left
  };
  for (const Case& c : cases) {
    Packetizer packetizer(config(c.max_payload_size));
    std::vector<PlannedPacket> out;
    for (size_t i = 0; i < c.phoneme_count; ++i) {
      packetizer.push(phoneme_at(static_cast<int64_t>(i) * kMs, 1), faps(c.fap_count), out);
    }
    EXPECT_EQ(out.size(), c.completed_at_once ? 1u : 0u)
        << "max " << c.max_payload_size << ", " << c.phoneme_count << " phonemes";
  }
}

TEST(Packetizer, PhonemeWhoseFapsDoNotFitGoesAloneFlaggedOversized) {
  Packetizer packetizer(config(16));
  std::vector<PlannedPacket> out;
  packetizer.push(phoneme_at(0, 10), {}, out);
  packetizer.push(phoneme_at(10 * kMs, 10), faps(2), out);  // 1 + 4 + 12 = 17 > 16
  ASSERT_EQ(out.size(), 2u);  // the pending packet first, then the oversized one at once
  EXPECT_FALSE(packetizer.has_pending());
  EXPECT_FALSE(out[0].oversized);
  EXPECT_TRUE(out[1].oversized);
  EXPECT_EQ(out[1].start_ns, 10 * kMs);
  EXPECT_EQ(out[1].packet.faps, faps(2));
  EXPECT_EQ(encoded_size(out[1].packet), 17u);

  packetizer.push(phoneme_at(20 * kMs, 10), {}, out);
  packetizer.drain(out);
  EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{1, 1, 1}));
  EXPECT_FALSE(out[2].oversized);
}

TEST(Packetizer, MaxPayloadSizeBelowOnePhonemeSendsEveryPhonemeOversized) {
  const std::vector<PlannedPacket> out = plan_uniform(config(4), 3, 0);
  EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{1, 1, 1}));
  for (const PlannedPacket& p : out) EXPECT_TRUE(p.oversized);
}

// ---------------------------------------------------------------------------------------
// flush and reset

TEST(Packetizer, FlushCompletesThePendingPacketOnce) {
  Packetizer packetizer(config());
  std::vector<PlannedPacket> out;
  packetizer.push(phoneme_at(0, 10), faps(1), out);
  packetizer.push(phoneme_at(10 * kMs, 10), {}, out);
  EXPECT_TRUE(packetizer.has_pending());
  EXPECT_TRUE(out.empty());
  packetizer.drain(out);
  EXPECT_FALSE(packetizer.has_pending());
  EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{2}));
  packetizer.drain(out);
  EXPECT_EQ(out.size(), 1u);

  // The next phoneme is contiguous but starts a new packet.
  packetizer.push(phoneme_at(20 * kMs, 10), {}, out);
  packetizer.drain(out);
  EXPECT_EQ(phoneme_counts(out), (std::vector<size_t>{2, 1}));
  EXPECT_EQ(out[1].start_ns, 20 * kMs);
}

TEST(Packetizer, ResetDropsThePendingPacket) {
  Packetizer packetizer(config());
  std::vector<PlannedPacket> out;
  packetizer.push(phoneme_at(0, 10, true), faps(3), out);
  packetizer.drop();
  EXPECT_FALSE(packetizer.has_pending());
  packetizer.drain(out);
  EXPECT_TRUE(out.empty());

  // Nothing of the dropped packet leaks into the next one.
  packetizer.push(phoneme_at(500 * kMs, 10), faps(1, 7), out);
  packetizer.drain(out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].start_ns, 500 * kMs);
  EXPECT_FALSE(out[0].marker);
  EXPECT_EQ(out[0].packet.faps, faps(1, 7));
  EXPECT_EQ(encoded_size(out[0].packet), 11u);
}

// ---------------------------------------------------------------------------------------
// Property test over random sessions

struct Input {
  TimedPhoneme phoneme;
  std::vector<Fap> faps;
};

// Sentences of contiguous phonemes with sub-millisecond jitter, now and then a gap; a
// sentence mostly ends with end of text, and the next one starts after a pause.
std::vector<Input> random_session(testing::RandomMarkup& rng) {
  std::vector<Input> session;
  int64_t time_ns = rng.uniform(0, 1000) * kMs;
  const int sentences = rng.uniform(1, 6);
  for (int s = 0; s < sentences; ++s) {
    const int count = rng.uniform(1, 60);
    for (int i = 0; i < count; ++i) {
      if (i > 0 && rng.chance(0.05)) time_ns += rng.uniform(1, 500) * kMs;
      Input in;
      in.phoneme.phoneme = rng.phoneme();
      in.phoneme.phoneme.end_of_text = i == count - 1 && rng.chance(0.8);
      in.phoneme.sentence_start = i == 0;
      in.phoneme.start_ns = time_ns + rng.uniform(-400'000, 400'000);
      const int fap_count = rng.uniform(0, 5);
      for (int f = 0; f < fap_count; ++f) in.faps.push_back(rng.fap());
      session.push_back(in);
      time_ns += in.phoneme.phoneme.duration_ms * kMs;
    }
    // Half the time the next sentence follows without a pause.
    if (rng.chance(0.5)) time_ns += rng.uniform(1, 2000) * kMs;
  }
  return session;
}

PacketizerConfig random_config(testing::RandomMarkup& rng) {
  const size_t sizes[] = {1, 4, 5, 16, 17, 64, 1388};
  PacketizerConfig cfg;
  cfg.max_payload_size =
      rng.chance(0.5) ? sizes[rng.uniform(0, 6)] : static_cast<size_t>(rng.uniform(1, 300));
  cfg.max_delay_ns = rng.uniform(0, 500) * kMs + rng.uniform(0, 999'999);
  return cfg;
}

// Why the packetizer may have ended `packet` before `next` (whose first phoneme and FAPs
// are given): one of the rules must hold, or the split was needless.
bool split_is_justified(const PacketizerConfig& cfg, const PlannedPacket& packet,
                        const Input& next) {
  const Packet& p = packet.packet;
  int64_t end_ns = packet.start_ns;
  for (const PacketPhoneme& ph : p.phonemes) end_ns += ph.phoneme.duration_ms * kMs;
  const size_t size = encoded_size(p);
  const size_t next_bytes = 4 + 6 * next.faps.size();
  return p.phonemes.back().phoneme.end_of_text || packet.oversized ||
         end_ns - packet.start_ns >= cfg.max_delay_ns || size + 4 > cfg.max_payload_size ||
         next.phoneme.sentence_start || std::abs(next.phoneme.start_ns - end_ns) > 500'000 ||
         next.phoneme.start_ns - packet.start_ns >= cfg.max_delay_ns ||
         size + next_bytes > cfg.max_payload_size;
}

void check_session(const PacketizerConfig& cfg, const std::vector<Input>& session) {
  Packetizer packetizer(cfg);
  std::vector<PlannedPacket> out;
  std::vector<size_t> completed_by;  // per packet: the input whose push appended it
  for (size_t i = 0; i < session.size(); ++i) {
    packetizer.push(session[i].phoneme, session[i].faps, out);
    completed_by.resize(out.size(), i);
  }
  packetizer.drain(out);
  completed_by.resize(out.size(), session.size());

  size_t next = 0;  // index into session
  for (size_t k = 0; k < out.size(); ++k) {
    SCOPED_TRACE("packet " + std::to_string(k));
    const PlannedPacket& planned = out[k];
    const Packet& p = planned.packet;
    ASSERT_FALSE(p.phonemes.empty());
    ASSERT_LE(next + p.phonemes.size(), session.size());
    const Input& first = session[next];

    EXPECT_EQ(p.phonemes.back().fap_end, p.faps.size());  // ends with a phoneme
    EXPECT_EQ(p.recovery_kind, RecoveryKind::kNone);
    EXPECT_TRUE(p.recovery.empty());
    EXPECT_EQ(planned.start_ns, first.phoneme.start_ns);
    EXPECT_EQ(planned.marker, first.phoneme.sentence_start);

    const size_t size = encoded_size(p);
    std::vector<uint8_t> payload(size);
    ASSERT_EQ(encode_payload(p, payload), EncodeStatus::kOk);
    Packet decoded;
    ASSERT_TRUE(decode_payload(payload, decoded).ok());
    EXPECT_EQ(decoded, p);
    if (planned.oversized) {
      EXPECT_EQ(p.phonemes.size(), 1u);
      EXPECT_GT(size, cfg.max_payload_size);
    } else {
      EXPECT_LE(size, cfg.max_payload_size);
    }

    int64_t end_ns = planned.start_ns;  // the first start plus the durations so far
    for (size_t i = 0; i < p.phonemes.size(); ++i, ++next) {
      const Input& in = session[next];
      const std::span<const Fap> got = p.faps_of(i);
      EXPECT_EQ(p.phonemes[i].phoneme, in.phoneme.phoneme);
      EXPECT_EQ(std::vector<Fap>(got.begin(), got.end()), in.faps);
      const bool last = i + 1 == p.phonemes.size();
      if (i > 0) {
        EXPECT_FALSE(in.phoneme.sentence_start);
        EXPECT_LE(std::abs(in.phoneme.start_ns - end_ns), 500'000);
        EXPECT_LT(in.phoneme.start_ns - planned.start_ns, cfg.max_delay_ns);
      }
      end_ns += in.phoneme.phoneme.duration_ms * kMs;
      if (!last) {
        EXPECT_FALSE(in.phoneme.phoneme.end_of_text);
        EXPECT_LT(end_ns - planned.start_ns, cfg.max_delay_ns);  // only the last may reach past
      }
    }
    if (k + 1 < out.size()) {
      EXPECT_TRUE(split_is_justified(cfg, planned, session[next]));
    }
    // Completed by its last phoneme's push when nothing more can join, else by the next one's.
    const bool nothing_can_join = p.phonemes.back().phoneme.end_of_text || planned.oversized ||
                                  end_ns - planned.start_ns >= cfg.max_delay_ns ||
                                  size + 4 > cfg.max_payload_size;
    EXPECT_EQ(completed_by[k], nothing_can_join ? next - 1 : next);
  }
  EXPECT_EQ(next, session.size());  // every phoneme, in order, once
}

TEST(PacketizerProperty, RandomSessionsKeepEveryInvariantAndEncodeDecodeRoundTrip) {
  for (uint32_t seed = 1; seed <= 500; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    testing::RandomMarkup rng(seed);
    const PacketizerConfig cfg = random_config(rng);
    check_session(cfg, random_session(rng));
    if (::testing::Test::HasFatalFailure()) return;
  }
}

}  // namespace
}  // namespace pfap
