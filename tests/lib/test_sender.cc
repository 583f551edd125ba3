// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap::Sender: what is sent when. The complete-state schedule (the stream's first packet, the
// interval, requests while busy and while idle, a state too large for the MTU, input whose
// times go back), depth changes mid-stream, and the data packets' fields.
#include "pfap/sender.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace pfap {
namespace {

constexpr int64_t kMs = kNsPerMs;
constexpr int64_t kSecond = 1000 * kMs;

using Kind = OutgoingPacket::Kind;

// What a test keeps of an OutgoingPacket: a copy, since the sender reuses its storage.
struct Sent {
  Kind kind;
  Packet packet;
  int64_t pts_ns;
  int64_t duration_ns;
  bool marker;
  bool oversized;
};

// Takes every packet ready. `requested` for the first call only, as an element clears its
// request flag once a complete packet answers it.
std::vector<Sent> take(Sender& sender, bool requested = false) {
  std::vector<Sent> out;
  while (const OutgoingPacket* p = sender.next(requested)) {
    out.push_back({p->kind, *p->packet, p->pts_ns, p->duration_ns, p->marker, p->oversized});
    if (p->kind != Kind::kData) requested = false;
  }
  return out;
}

TimedPhoneme phoneme(int64_t start_ns, uint16_t duration_ms, bool sentence_start = false) {
  TimedPhoneme p;
  p.start_ns = start_ns;
  p.phoneme.symbol = 7;
  p.phoneme.duration_ms = duration_ms;
  p.sentence_start = sentence_start;
  return p;
}

Fap fap(int index, int32_t amplitude) {
  Fap f;
  f.index = static_cast<uint8_t>(index);
  f.amplitude = amplitude;
  return f;
}

// One packet per phoneme, every phoneme 100 ms, a complete state each `interval`.
SenderConfig one_per_phoneme(int64_t interval_ns = kSecond) {
  SenderConfig config;
  config.max_delay_ns = 0;
  config.complete_interval_ns = interval_ns;
  return config;
}

std::vector<Kind> kinds(const std::vector<Sent>& sent) {
  std::vector<Kind> out;
  for (const Sent& s : sent) out.push_back(s.kind);
  return out;
}

size_t count(const std::vector<Sent>& sent, Kind kind) {
  return static_cast<size_t>(
      std::count_if(sent.begin(), sent.end(), [&](const Sent& s) { return s.kind == kind; }));
}

TEST(Sender, StreamStartsWithACompleteStateAtTheFirstPacketsTime) {
  Sender sender(one_per_phoneme());
  const Fap faps[] = {fap(3, 100)};
  sender.push(phoneme(5 * kSecond, 80, true), faps);
  const std::vector<Sent> sent = take(sender);
  ASSERT_EQ(kinds(sent), (std::vector<Kind>{Kind::kComplete, Kind::kData}));
  EXPECT_EQ(sent[0].pts_ns, 5 * kSecond);
  EXPECT_EQ(sent[0].duration_ns, 0);
  EXPECT_FALSE(sent[0].marker);
  EXPECT_EQ(sent[0].packet.recovery_kind, RecoveryKind::kComplete);
  EXPECT_TRUE(sent[0].packet.recovery.empty());  // sampled before the packet's bookmark
  EXPECT_EQ(sent[1].pts_ns, 5 * kSecond);
  EXPECT_EQ(sent[1].duration_ns, 80 * kMs);
  EXPECT_TRUE(sent[1].marker);
  EXPECT_FALSE(sent[1].oversized);
  EXPECT_EQ(sent[1].packet.faps.size(), 1u);
  EXPECT_TRUE(sender.started());
}

TEST(Sender, DataPacketDurationIsItsPhonemesAndTheirStartsFollowOneAnother) {
  SenderConfig config;
  config.max_delay_ns = kSecond;
  Sender sender(config);
  sender.push(phoneme(0, 40), {});
  sender.push(phoneme(40 * kMs, 60), {});
  sender.drain();
  const std::vector<Sent> sent = take(sender);
  ASSERT_EQ(kinds(sent), (std::vector<Kind>{Kind::kComplete, Kind::kData}));
  EXPECT_EQ(sent[1].duration_ns, 100 * kMs);
  std::vector<int64_t> starts;
  const int64_t end = sent[1].packet.for_each_phoneme(
      sent[1].pts_ns, [&](size_t, int64_t start_ns) { starts.push_back(start_ns); });
  EXPECT_EQ(starts, (std::vector<int64_t>{0, 40 * kMs}));
  EXPECT_EQ(end, 100 * kMs);
}

TEST(Sender, CompleteStateBeforeTheFirstDataPacketOfEachInterval) {
  Sender sender(one_per_phoneme(kSecond));
  std::vector<Sent> sent;
  for (int i = 0; i < 25; ++i) {  // 2.5 s of contiguous 100 ms phonemes
    sender.push(phoneme(i * 100 * kMs, 100), {});
    for (Sent& s : take(sender)) sent.push_back(std::move(s));
  }
  std::vector<int64_t> complete_times;
  for (const Sent& s : sent) {
    if (s.kind == Kind::kComplete) complete_times.push_back(s.pts_ns);
  }
  EXPECT_EQ(complete_times, (std::vector<int64_t>{0, kSecond, 2 * kSecond}));
  EXPECT_EQ(count(sent, Kind::kData), 25u);
}

TEST(Sender, IntervalZeroSendsACompleteStateOnlyAtTheStartAndOnRequest) {
  Sender sender(one_per_phoneme(0));
  std::vector<Sent> sent;
  for (int i = 0; i < 50; ++i) {
    sender.push(phoneme(i * 100 * kMs, 100), {});
    for (Sent& s : take(sender, i == 30)) sent.push_back(std::move(s));
  }
  EXPECT_EQ(count(sent, Kind::kComplete), 2u);
}

TEST(Sender, RequestWhileBusyGoesBeforeTheNextDataPacketWithItsStartState) {
  Sender sender(one_per_phoneme());
  const Fap faps[] = {fap(5, 300)};
  sender.push(phoneme(0, 100), faps);
  take(sender);
  sender.push(phoneme(100 * kMs, 100), {});
  const std::vector<Sent> sent = take(sender, /*requested=*/true);
  ASSERT_EQ(kinds(sent), (std::vector<Kind>{Kind::kComplete, Kind::kData}));
  EXPECT_EQ(sent[0].pts_ns, 100 * kMs);
  ASSERT_EQ(sent[0].packet.recovery.size(), 1u);
  EXPECT_EQ(sent[0].packet.recovery[0].index, 5);
  EXPECT_EQ(sent[0].packet.recovery[0].amplitude, 300);
}

TEST(Sender, RequestWhileIdleIsTheStateWhereTheStreamIsNow) {
  Sender sender(one_per_phoneme());
  EXPECT_EQ(sender.complete_now(), nullptr);  // before the first data packet: nothing yet
  const Fap faps[] = {fap(9, -40)};
  sender.push(phoneme(2 * kSecond, 150), faps);
  take(sender);
  const OutgoingPacket* complete = sender.complete_now();
  ASSERT_NE(complete, nullptr);
  EXPECT_EQ(complete->kind, Kind::kComplete);
  EXPECT_EQ(complete->pts_ns, 2 * kSecond + 150 * kMs);  // the end of the last data packet
  ASSERT_EQ(complete->packet->recovery.size(), 1u);
  EXPECT_EQ(complete->packet->recovery[0].amplitude, -40);
  // It counts for the interval: the next one is due a second of stream time later.
  std::vector<Sent> sent;
  for (int i = 0; i < 10; ++i) {
    sender.push(phoneme(2 * kSecond + (150 + 100 * i) * kMs, 100), {});
    for (Sent& s : take(sender)) sent.push_back(std::move(s));
  }
  EXPECT_EQ(count(sent, Kind::kComplete), 0u);
  sender.push(phoneme(3 * kSecond + 150 * kMs, 100), {});
  EXPECT_EQ(kinds(take(sender)), (std::vector<Kind>{Kind::kComplete, Kind::kData}));
}

TEST(Sender, CompleteStateOverTheMtuIsNotSentAndCountsForTheInterval) {
  SenderConfig config = one_per_phoneme(kSecond);
  config.max_payload_size = 40;  // room for a phoneme and 6 FAPs, not for a state of 7
  Sender sender(config);
  // Seven FAPs, one per phoneme, each fitting its data packet.
  std::vector<Sent> sent;
  for (int i = 0; i < 30; ++i) {
    const Fap faps[] = {fap(3 + i % 7, 100 + i)};
    sender.push(phoneme(i * 100 * kMs, 100), faps);
    for (Sent& s : take(sender)) sent.push_back(std::move(s));
  }
  // 0 s (empty state, fits), then 1 s and 2 s: seven FAPs, 43 bytes.
  EXPECT_EQ(count(sent, Kind::kComplete), 1u);
  EXPECT_EQ(count(sent, Kind::kCompleteTooLarge), 2u);
  EXPECT_EQ(count(sent, Kind::kData), 30u);
  for (const Sent& s : sent) {
    if (s.kind == Kind::kCompleteTooLarge) {
      EXPECT_GT(encoded_size(s.packet), 40u);
    }
  }
}

TEST(Sender, OversizedPhonemeGoesAloneAndIsFlagged) {
  SenderConfig config = one_per_phoneme();
  config.max_payload_size = 20;
  Sender sender(config);
  const Fap faps[] = {fap(3, 1), fap(4, 2), fap(5, 3)};  // 1 + 18 + 4 = 23 bytes
  sender.push(phoneme(0, 100), faps);
  const std::vector<Sent> sent = take(sender);
  ASSERT_EQ(kinds(sent), (std::vector<Kind>{Kind::kComplete, Kind::kData}));
  EXPECT_TRUE(sent[1].oversized);
  EXPECT_TRUE(sent[1].packet.recovery.empty());  // no room for recovery entries
}

TEST(Sender, BackwardTimesSendNoMoreCompleteStatesThanForwardOnes) {
  // 3000 phonemes of 100 ms (300 s of speech) in forward and in reversed time order: the
  // interval counts stream time that moves forward, so both send one complete state per
  // second of speech, not one per packet.
  for (const bool reversed : {false, true}) {
    SCOPED_TRACE(reversed ? "reversed" : "forward");
    Sender sender(one_per_phoneme(kSecond));
    size_t complete = 0, data = 0;
    for (int i = 0; i < 3000; ++i) {
      const int slot = reversed ? 2999 - i : i;
      sender.push(phoneme(int64_t{slot} * 100 * kMs, 100), {});
      for (const Sent& s : take(sender)) (s.kind == Kind::kData ? data : complete)++;
    }
    EXPECT_EQ(data, 3000u);
    EXPECT_EQ(complete, 300u);
  }
}

TEST(Sender, TimeThatJumpsBackDoesNotHoldTheNextCompleteStateBack) {
  // A new segment from 0 after 10 s: the next complete state comes a second of speech after
  // the last one, not 10 s later.
  Sender sender(one_per_phoneme(kSecond));
  for (int i = 0; i < 95; ++i) {
    sender.push(phoneme(i * 100 * kMs, 100), {});
    take(sender);
  }
  std::vector<int64_t> complete_times;
  for (int i = 0; i < 20; ++i) {
    sender.push(phoneme(i * 100 * kMs, 100), {});
    for (const Sent& s : take(sender)) {
      if (s.kind == Kind::kComplete) complete_times.push_back(s.pts_ns);
    }
  }
  // The last before the jump was at 9 s; 500 ms of speech before the jump, 500 ms after.
  EXPECT_EQ(complete_times, (std::vector<int64_t>{500 * kMs, 1500 * kMs}));
}

TEST(Sender, ManyRequestsWhileBusyShareOneCompleteState) {
  Sender sender(one_per_phoneme(0));
  sender.push(phoneme(0, 100), {});
  take(sender);
  sender.push(phoneme(100 * kMs, 100), {});
  // A request made during the complete packet's push finds the complete check done.
  std::vector<Kind> got;
  while (const OutgoingPacket* p = sender.next(true)) got.push_back(p->kind);
  EXPECT_EQ(got, (std::vector<Kind>{Kind::kComplete, Kind::kData}));
}

TEST(Sender, DeeperRecoveryGrowsOnePacketAtATime) {
  SenderConfig config = one_per_phoneme(0);
  config.recovery_depth = 1;
  Sender sender(config);
  std::vector<unsigned> covered;
  for (int i = 0; i < 8; ++i) {
    if (i == 3) {
      config.recovery_depth = 4;
      sender.configure(config);
    }
    const Fap faps[] = {fap(3 + i, 10)};
    sender.push(phoneme(i * 100 * kMs, 100), faps);
    for (const Sent& s : take(sender)) {
      if (s.kind == Kind::kData) covered.push_back(s.packet.covered_packets);
    }
  }
  // Depth 1 held one packet: coverage 1, then 2 once the sender holds 2 packets, then 4.
  EXPECT_EQ(covered, (std::vector<unsigned>{1, 1, 1, 1, 2, 2, 4, 4}));
}

TEST(Sender, ShallowerRecoveryTakesEffectAtTheNextDataPacket) {
  SenderConfig config = one_per_phoneme(0);
  config.recovery_depth = 4;
  Sender sender(config);
  std::vector<unsigned> covered;
  for (int i = 0; i < 6; ++i) {
    if (i == 4) {
      config.recovery_depth = 0;
      sender.configure(config);
    }
    const Fap faps[] = {fap(3 + i, 10)};
    sender.push(phoneme(i * 100 * kMs, 100), faps);
    for (const Sent& s : take(sender)) {
      if (s.kind == Kind::kData) covered.push_back(s.packet.covered_packets);
    }
  }
  EXPECT_EQ(covered, (std::vector<unsigned>{4, 4, 4, 4, 0, 0}));
}

TEST(Sender, MtuChangeAppliesFromTheNextPacketStarted) {
  SenderConfig config;
  config.max_delay_ns = kSecond;
  config.complete_interval_ns = 0;
  Sender sender(config);
  sender.push(phoneme(0, 10), {});  // pending: 5 bytes
  config.max_payload_size = 8;      // would leave no room for a second phoneme
  sender.configure(config);
  sender.push(phoneme(10 * kMs, 10), {});
  sender.drain();
  std::vector<Sent> sent = take(sender);
  ASSERT_EQ(kinds(sent), (std::vector<Kind>{Kind::kComplete, Kind::kData}));
  EXPECT_EQ(sent[1].packet.phonemes.size(), 2u);  // the packet kept its limit
  sender.push(phoneme(20 * kMs, 10), {});
  sender.push(phoneme(30 * kMs, 10), {});
  sender.drain();
  sent = take(sender);
  ASSERT_EQ(kinds(sent), (std::vector<Kind>{Kind::kData, Kind::kData}));  // 8 bytes: one each
}

TEST(Sender, ResetStartsANewStreamWithACompleteState) {
  Sender sender(one_per_phoneme(0));
  const Fap faps[] = {fap(3, 100)};
  sender.push(phoneme(0, 100), faps);
  take(sender);
  SenderConfig config = sender.config();
  config.max_delay_ns = kSecond;
  sender.configure(config);
  sender.push(phoneme(100 * kMs, 100), {});  // pending, dropped by the reset
  sender.reset();
  EXPECT_FALSE(sender.started());
  EXPECT_EQ(sender.complete_now(), nullptr);
  sender.drain();
  EXPECT_TRUE(take(sender).empty());
  sender.push(phoneme(0, 100), {});
  sender.drain();
  const std::vector<Sent> sent = take(sender);
  ASSERT_EQ(kinds(sent), (std::vector<Kind>{Kind::kComplete, Kind::kData}));
  EXPECT_TRUE(sent[0].packet.recovery.empty());  // the FAP state went with the stream
}

}  // namespace
}  // namespace pfap
