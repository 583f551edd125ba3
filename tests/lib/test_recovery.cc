// SPDX-License-Identifier: LGPL-2.1-or-later
// Recovery: a receiver that loses packets ends with the FAP state of one that lost none,
// whenever every gap is within the coverage of the packet after it.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "pfap/packetizer.h"
#include "pfap/recovery.h"
#include "random_markup.h"

namespace pfap {
namespace {

struct SentPacket {
  Packet packet;
  int64_t time_ns;
  uint16_t seqnum;
};

// A seeded session of `phonemes` phonemes with FAPs of every kind (a third triangles), sent
// with dynamic recovery of `depth` and a complete state every `complete_every` packets (and
// first), each through the encoder and decoder.
std::vector<SentPacket> send_session(uint32_t seed, int phonemes, unsigned depth,
                                     int complete_every) {
  testing::RandomMarkup random(seed);
  Packetizer packetizer({.max_payload_size = 200, .max_delay_ns = 150 * kNsPerMs});
  RecoverySender sender(depth);
  std::vector<PlannedPacket> planned;
  int64_t t = 0;
  for (int i = 0; i < phonemes; ++i) {
    Phoneme p = random.phoneme();
    p.duration_ms = static_cast<uint16_t>(random.uniform(40, 200));
    p.end_of_text = random.chance(0.05);
    std::vector<Fap> faps;
    for (int n = random.chance(0.6) ? 0 : random.uniform(1, 3); n > 0; --n) {
      Fap f = random.fap();
      f.index = static_cast<uint8_t>(random.uniform(kMinFapIndex, 12));  // reuse indexes
      f.transition_ms = static_cast<uint16_t>(random.uniform(0, 1500));
      faps.push_back(f);
    }
    packetizer.push({t, p, i == 0 || random.chance(0.02)}, faps, planned);
    t += p.duration_ms * kNsPerMs + (p.end_of_text ? 300 * kNsPerMs : 0);
  }
  packetizer.drain(planned);

  std::vector<SentPacket> sent;
  const auto send = [&](Packet packet, int64_t time_ns) {
    std::vector<uint8_t> bytes(encoded_size(packet));
    EXPECT_EQ(encode_payload(packet, bytes), EncodeStatus::kOk);
    Packet decoded;
    EXPECT_TRUE(decode_payload(bytes, decoded).ok());
    sender.sent(decoded, time_ns);
    sent.push_back({decoded, time_ns, static_cast<uint16_t>(60000 + sent.size())});
  };
  for (size_t i = 0; i < planned.size(); ++i) {
    if (complete_every > 0 && i % static_cast<size_t>(complete_every) == 0) {
      Packet complete;
      EXPECT_TRUE(sender.make_complete(complete, planned[i].start_ns, 1388));
      send(complete, planned[i].start_ns);
    }
    Packet packet = planned[i].packet;
    sender.add_dynamic(packet, planned[i].start_ns, 1388 - encoded_size(packet));
    send(packet, planned[i].start_ns);
  }
  return sent;
}

struct Outcome {
  int compared = 0;   // packets received while the lossy receiver said it was whole
  int differing = 0;  // of those, packets after which some settled value differed
  int not_whole = 0;  // packets received while it said it was not whole
};

// Feeds every packet to a lossless receiver and the ones `keep` keeps to a lossy one, and
// compares settled values after each packet the lossy one receives.
template <typename Keep>
Outcome compare(const std::vector<SentPacket>& packets, Keep keep) {
  RecoveryReceiver lossless, lossy;
  Outcome outcome;
  for (size_t i = 0; i < packets.size(); ++i) {
    const SentPacket& s = packets[i];
    lossless.receive(s.packet, s.seqnum, s.time_ns);
    if (!keep(i)) continue;
    const ReceiveResult r = lossy.receive(s.packet, s.seqnum, s.time_ns);
    if (!r.state_whole) {
      ++outcome.not_whole;
      continue;
    }
    ++outcome.compared;
    for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) {
      if (lossy.state().settled(f) != lossless.state().settled(f)) {
        ++outcome.differing;
        break;
      }
    }
  }
  return outcome;
}

TEST(Recovery, RandomLossWithinCoverageLeavesTheSettledStateExact) {
  for (unsigned depth : {1u, 4u, 7u, 15u}) {
    const std::vector<SentPacket> packets = send_session(depth, 3000, depth, 0);
    for (double loss : {0.01, 0.05, 0.10, 0.20}) {
      std::mt19937 rng(static_cast<uint32_t>(depth * 1000 + loss * 100));
      std::bernoulli_distribution drop(loss);
      // Drop at random, but never more in a row than the coverage: every gap is covered.
      std::vector<bool> kept(packets.size(), true);
      unsigned run = 0;
      for (size_t i = 1; i < packets.size(); ++i) {
        kept[i] = !(run < depth && drop(rng));
        run = kept[i] ? 0 : run + 1;
      }
      const Outcome o = compare(packets, [&](size_t i) { return kept[i]; });
      SCOPED_TRACE(::testing::Message() << "depth " << depth << " loss " << loss);
      EXPECT_EQ(o.not_whole, 0);
      EXPECT_GT(o.compared, 1000);
      EXPECT_EQ(o.differing, 0);
    }
  }
}

TEST(Recovery, WithoutRecoveryLossLeavesTheStateWrong) {
  const std::vector<SentPacket> packets = send_session(3, 3000, 0, 0);
  std::mt19937 rng(3);
  std::bernoulli_distribution drop(0.05);
  std::vector<bool> kept(packets.size());
  for (size_t i = 0; i < packets.size(); ++i) kept[i] = i == 0 || !drop(rng);
  RecoveryReceiver lossless, lossy;
  int differing = 0;
  for (size_t i = 0; i < packets.size(); ++i) {
    lossless.receive(packets[i].packet, packets[i].seqnum, packets[i].time_ns);
    if (!kept[i]) continue;
    lossy.receive(packets[i].packet, packets[i].seqnum, packets[i].time_ns);
    for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) {
      if (lossy.state().settled(f) != lossless.state().settled(f)) {
        ++differing;
        break;
      }
    }
  }
  EXPECT_GT(differing, 100) << "the comparison must be able to see lost FAPs";
}

TEST(Recovery, BurstLongerThanCoverageBreaksTheStateUntilACompleteState) {
  const std::vector<SentPacket> packets = send_session(5, 2000, 4, 50);
  RecoveryReceiver lossless, lossy(/*retry_ns=*/int64_t{1} << 62);  // no retries
  bool requested = false, broke = false, whole_again = false;
  int repeats = 0;
  for (size_t i = 0; i < packets.size(); ++i) {
    const SentPacket& s = packets[i];
    lossless.receive(s.packet, s.seqnum, s.time_ns);
    if (i >= 100 && i < 110) continue;  // a burst of 10 > coverage 4
    const ReceiveResult r = lossy.receive(s.packet, s.seqnum, s.time_ns);
    if (i == 110) {
      EXPECT_FALSE(r.state_whole);
      EXPECT_TRUE(r.request_complete);
      EXPECT_EQ(r.lost, 10u);
      requested = broke = true;
    } else if (broke && !whole_again && r.recovery == ReceiveResult::Recovery::kComplete) {
      whole_again = r.state_whole;
      for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) {
        EXPECT_EQ(lossy.state().settled(f), lossless.state().settled(f)) << f;
      }
    } else if (broke && !whole_again) {
      EXPECT_FALSE(r.state_whole);
      if (r.request_complete) ++repeats;  // only after the retry interval
    }
  }
  EXPECT_TRUE(requested);
  EXPECT_TRUE(whole_again);
  EXPECT_EQ(repeats, 0) << "asked once per loss";
}

TEST(RecoveryReceiver, AsksAgainEachRetryIntervalWhileNotWhole) {
  RecoveryReceiver r(/*retry_ns=*/1000 * kNsPerMs);
  r.reset(/*joined_mid_stream=*/true);
  Packet p;
  p.add_phoneme({.duration_ms = 100}, {});
  std::vector<int64_t> asked_at;
  for (int i = 0; i < 30; ++i) {
    if (r.receive(p, static_cast<uint16_t>(i), i * 100 * kNsPerMs).request_complete) {
      asked_at.push_back(i * 100);
    }
  }
  EXPECT_EQ(asked_at, (std::vector<int64_t>{0, 1000, 2000}));
}

TEST(RecoveryReceiver, LossOfUnknownSizeBreaksTheStateUntilACompleteState) {
  RecoveryReceiver r;
  Packet covered;
  covered.recovery_kind = RecoveryKind::kDynamic;
  covered.covered_packets = 40;
  covered.add_phoneme({.duration_ms = 10}, {});
  EXPECT_TRUE(r.receive(covered, 1, 0).state_whole);
  r.lost_unknown();
  const ReceiveResult next = r.receive(covered, 2, 10 * kNsPerMs);  // no seqnum gap
  EXPECT_FALSE(next.state_whole) << "no coverage is known to span a loss of unknown size";
  EXPECT_TRUE(next.request_complete);
  Packet complete;
  complete.recovery_kind = RecoveryKind::kComplete;
  EXPECT_TRUE(r.receive(complete, 3, 20 * kNsPerMs).state_whole);
}

TEST(RecoveryReceiver, CompleteStateSaysWhetherItChangedAnything) {
  RecoveryReceiver r;
  Packet zero;
  zero.recovery_kind = RecoveryKind::kComplete;
  EXPECT_FALSE(r.receive(zero, 1, 0).changed);
  Packet joy = zero;
  joy.recovery = {{69, 40, 0, Curve::kLinear}};
  EXPECT_TRUE(r.receive(joy, 2, 0).changed);
  EXPECT_FALSE(r.receive(joy, 3, 0).changed);
}

TEST(RecoveryReceiver, DuplicateOrBackwardSequenceNumberCountsNoLoss) {
  RecoveryReceiver r;
  Packet p;
  p.add_phoneme({.duration_ms = 10}, {});
  EXPECT_EQ(r.receive(p, 65535, 0).lost, 0u);
  EXPECT_EQ(r.receive(p, 2, 0).lost, 2u);  // wraps: 0 and 1 missing
  EXPECT_EQ(r.receive(p, 2, 0).lost, 0u);  // duplicate
  EXPECT_EQ(r.receive(p, 1, 0).lost, 0u);  // back
}

TEST(Recovery, LateJoinerIsWholeFromItsFirstCompleteState) {
  const std::vector<SentPacket> packets = send_session(6, 2000, 4, 40);
  RecoveryReceiver lossless, joiner;
  joiner.reset(/*joined_mid_stream=*/true);
  bool asked = false;
  int compared = 0;
  for (size_t i = 0; i < packets.size(); ++i) {
    const SentPacket& s = packets[i];
    lossless.receive(s.packet, s.seqnum, s.time_ns);
    if (i < 333) continue;
    const ReceiveResult r = joiner.receive(s.packet, s.seqnum, s.time_ns);
    if (i == 333) asked = r.request_complete;
    if (!r.state_whole) continue;
    ++compared;
    for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) {
      ASSERT_EQ(joiner.state().settled(f), lossless.state().settled(f)) << "packet " << i;
    }
  }
  EXPECT_TRUE(asked);
  EXPECT_GT(compared, 500);
}

TEST(Recovery, RecoveryWithoutLossChangesNothing) {
  const std::vector<SentPacket> packets = send_session(7, 500, 7, 0);
  RecoveryReceiver a;
  FapState plain;
  for (const SentPacket& s : packets) {
    const ReceiveResult r = a.receive(s.packet, s.seqnum, s.time_ns);
    EXPECT_EQ(r.recovery, ReceiveResult::Recovery::kNone);
    int64_t start = s.time_ns;
    for (size_t i = 0; i < s.packet.phonemes.size(); ++i) {
      for (const Fap& f : s.packet.faps_of(i)) plain.apply(f, start);
      start += s.packet.phonemes[i].phoneme.duration_ms * kNsPerMs;
    }
    for (int f = kMinFapIndex; f <= kMaxFapIndex; ++f) {
      ASSERT_EQ(a.state().settled(f), plain.settled(f));
    }
  }
}

TEST(RecoverySender, FinishedTriangleFromRestIsLeftOutRunningOneIsIn) {
  RecoverySender sender(2);
  Packet p;
  p.add_phoneme({.duration_ms = 100}, std::vector<Fap>{{31, 300, 400, Curve::kTriangle}});
  sender.sent(p, 0);
  Packet next;
  sender.add_dynamic(next, 200 * kNsPerMs, 100);  // triangle still running at 200 ms
  ASSERT_EQ(next.recovery.size(), 1u);
  EXPECT_EQ(next.recovery[0], (Fap{31, 0, 0, Curve::kLinear}));  // its settled value, at once
  Packet later;
  sender.add_dynamic(later, 500 * kNsPerMs, 100);  // over
  EXPECT_EQ(later.recovery_kind, RecoveryKind::kDynamic);
  EXPECT_EQ(later.covered_packets, 2);
  EXPECT_TRUE(later.recovery.empty());
}

TEST(RecoverySender, TransitionIsAdjustedToTheTimeLeft) {
  RecoverySender sender(1);
  Packet p;
  p.add_phoneme({.duration_ms = 100}, std::vector<Fap>{{48, 20000, 800, Curve::kSpline}});
  sender.sent(p, 1000 * kNsPerMs);
  Packet next;
  sender.add_dynamic(next, 1300 * kNsPerMs, 100);
  EXPECT_EQ(next.recovery, (std::vector<Fap>{{48, 20000, 500, Curve::kSpline}}));
  Packet done;
  sender.add_dynamic(done, 2000 * kNsPerMs, 100);
  EXPECT_EQ(done.recovery, (std::vector<Fap>{{48, 20000, 0, Curve::kLinear}}));  // at rest
}

TEST(RecoverySender, CoverageShrinksToFitTheRoomLeft) {
  RecoverySender sender(4);
  for (int i = 0; i < 4; ++i) {
    Packet p;
    p.add_phoneme({.duration_ms = 10},
                  std::vector<Fap>{{static_cast<uint8_t>(3 + i), 100, 0, Curve::kLinear}});
    sender.sent(p, i * 10 * kNsPerMs);
  }
  const struct {
    size_t room;
    uint8_t coverage;
    size_t entries;
  } cases[] = {{24, 4, 4}, {23, 2, 2}, {12, 2, 2}, {11, 1, 1}, {6, 1, 1}, {5, 0, 0}};
  for (const auto& c : cases) {
    Packet next;
    sender.add_dynamic(next, 100 * kNsPerMs, c.room);
    EXPECT_EQ(next.covered_packets, c.coverage) << c.room;
    EXPECT_EQ(next.recovery.size(), c.entries) << c.room;
    EXPECT_EQ(next.recovery_kind, c.coverage ? RecoveryKind::kDynamic : RecoveryKind::kNone);
  }
}

// Packets with one FAP each, FAP 3 + i in packet i.
void send_packets(RecoverySender& sender, int from, int to) {
  for (int i = from; i < to; ++i) {
    Packet p;
    p.add_phoneme({.duration_ms = 10},
                  std::vector<Fap>{{static_cast<uint8_t>(3 + i), 100, 0, Curve::kLinear}});
    sender.sent(p, i * 10 * kNsPerMs);
  }
}

TEST(RecoverySender, AtStreamStartTheFullDepthIsClaimedSinceNothingIsOlder) {
  RecoverySender sender(15);
  send_packets(sender, 0, 2);
  Packet next;
  sender.add_dynamic(next, 100 * kNsPerMs, 1000);
  EXPECT_EQ(next.covered_packets, 15);
  EXPECT_EQ(next.recovery.size(), 2u);
}

TEST(RecoverySender, DeeperDepthMidStreamGrowsWithThePacketsItHolds) {
  RecoverySender sender(2);
  send_packets(sender, 0, 5);  // holds packets 3 and 4 only
  sender.set_depth(7);
  Packet next;
  sender.add_dynamic(next, 100 * kNsPerMs, 1000);
  EXPECT_EQ(next.covered_packets, 2) << "never claims packets it did not keep";
  send_packets(sender, 5, 7);  // now holds 3..6
  sender.add_dynamic(next, 100 * kNsPerMs, 1000);
  EXPECT_EQ(next.covered_packets, 4);
  send_packets(sender, 7, 12);
  sender.add_dynamic(next, 200 * kNsPerMs, 1000);
  EXPECT_EQ(next.covered_packets, 7);
  EXPECT_EQ(next.recovery.size(), 7u);
}

TEST(RecoverySender, OnlyTheLastDepthPacketsAreCoveredAsTheWindowMovesOn) {
  // Packets of 0, 1 or 2 FAPs, so that each place in the window holds packets of every size.
  RecoverySender sender(4);
  for (int i = 0; i < 30; ++i) {
    std::vector<Fap> faps;
    for (int k = 0; k < i % 3; ++k) {
      faps.push_back({static_cast<uint8_t>(3 + (2 * i + k) % 60), 100, 0, Curve::kLinear});
    }
    Packet p;
    p.add_phoneme({.duration_ms = 10}, faps);
    sender.sent(p, i * 10 * kNsPerMs);
    if (i < 4) continue;
    std::vector<Fap> expected;  // the FAPs of packets i - 3 .. i, by index
    for (int j = i - 3; j <= i; ++j) {
      for (int k = 0; k < j % 3; ++k) {
        expected.push_back({static_cast<uint8_t>(3 + (2 * j + k) % 60), 100, 0, Curve::kLinear});
      }
    }
    std::sort(expected.begin(), expected.end(),
              [](const Fap& a, const Fap& b) { return a.index < b.index; });
    Packet next;
    sender.add_dynamic(next, (i + 1) * 10 * kNsPerMs, 1000);
    EXPECT_EQ(next.covered_packets, 4) << i;
    EXPECT_EQ(next.recovery, expected) << i;
  }
}

TEST(RecoverySender, ShallowerDepthKeepsTheStateAndTheNewestPackets) {
  RecoverySender sender(7);
  send_packets(sender, 0, 7);
  sender.set_depth(2);
  Packet next;
  sender.add_dynamic(next, 100 * kNsPerMs, 1000);
  EXPECT_EQ(next.covered_packets, 2);
  EXPECT_EQ(next.recovery,
            (std::vector<Fap>{{8, 100, 0, Curve::kLinear}, {9, 100, 0, Curve::kLinear}}));
  Packet complete;
  ASSERT_TRUE(sender.make_complete(complete, 100 * kNsPerMs, 1000));
  EXPECT_EQ(complete.recovery.size(), 7u) << "the state is kept";
}

TEST(RecoverySender, CompleteStateListsOnlyNonZeroFapsAndIsNeverCut) {
  RecoverySender sender(0);
  Packet p;
  p.add_phoneme({.duration_ms = 10}, std::vector<Fap>{{3, 10, 0, Curve::kLinear},
                                                      {4, 0, 0, Curve::kLinear},
                                                      {5, -300, 0, Curve::kLinear},
                                                      {6, 20, 0, Curve::kLinear}});
  sender.sent(p, 0);
  Packet complete;
  ASSERT_TRUE(sender.make_complete(complete, kNsPerMs * 100, 1 + 3 * 6));
  EXPECT_EQ(complete.recovery_kind, RecoveryKind::kComplete);
  EXPECT_EQ(complete.recovery, (std::vector<Fap>{{3, 10, 0, Curve::kLinear},
                                                 {5, -300, 0, Curve::kLinear},
                                                 {6, 20, 0, Curve::kLinear}}));
  // One byte short: refused, not cut (a receiver would take the missing FAP for 0).
  EXPECT_FALSE(sender.make_complete(complete, kNsPerMs * 100, 3 * 6));
}

}  // namespace
}  // namespace pfap
