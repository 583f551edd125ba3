// SPDX-License-Identifier: LGPL-2.1-or-later
// The library's costs: encode and decode+validate beside memcpy of the same bytes (the
// ceiling), FAP-state evaluation and bookmarks applied as a receiver does them, the sender's
// recovery work per packet, and how the cost of a packet grows with its size.
// Run: scripts/bench, meson test -C build --benchmark --verbose, or build/tests/bench/bench_payload
#include <benchmark/benchmark.h>

#include <cstring>
#include <vector>

#include "pfap/fap_state.h"
#include "pfap/payload.h"
#include "pfap/recovery.h"
#include "random_markup.h"

namespace pfap {
namespace {

// A full 1388-byte payload (1400-byte MTU less the RTP header) as speech gives it: dynamic
// recovery over 4 packets with 3 entries, then phonemes of which one in four carries 2 FAPs.
Packet typical_packet() {
  testing::RandomMarkup random(1);
  Packet packet;
  packet.recovery_kind = RecoveryKind::kDynamic;
  packet.covered_packets = 4;
  for (int i = 0; i < 3; ++i) packet.recovery.push_back(random.fap());
  for (int i = 0;; ++i) {
    std::vector<Fap> faps;
    if (i % 4 == 0) faps = {random.fap(), random.fap()};
    if (encoded_size(packet) + 4 + 6 * faps.size() > 1388) break;
    packet.add_phoneme(random.phoneme(), faps);
  }
  return packet;
}

size_t descriptors(const Packet& p) {
  return 1 + p.recovery.size() + p.phonemes.size() + p.faps.size();
}

void report(benchmark::State& state, const Packet& packet, size_t bytes) {
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * bytes));
  state.counters["descriptors/s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * descriptors(packet)), benchmark::Counter::kIsRate);
  state.counters["payload_bytes"] = static_cast<double>(bytes);
}

void BM_Memcpy(benchmark::State& state) {
  const Packet packet = typical_packet();
  std::vector<uint8_t> from(encoded_size(packet)), to(from.size());
  encode_payload(packet, from);
  for (auto _ : state) {
    std::memcpy(to.data(), from.data(), from.size());
    benchmark::DoNotOptimize(to.data());
    benchmark::ClobberMemory();
  }
  report(state, packet, from.size());
}
BENCHMARK(BM_Memcpy);

void BM_Encode(benchmark::State& state) {
  const Packet packet = typical_packet();
  std::vector<uint8_t> out(encoded_size(packet));
  for (auto _ : state) {
    benchmark::DoNotOptimize(encode_payload(packet, out));
    benchmark::ClobberMemory();
  }
  report(state, packet, out.size());
}
BENCHMARK(BM_Encode);

void BM_DecodeValidate(benchmark::State& state) {
  const Packet packet = typical_packet();
  std::vector<uint8_t> bytes(encoded_size(packet));
  encode_payload(packet, bytes);
  Packet decoded;
  for (auto _ : state) {
    benchmark::DoNotOptimize(decode_payload(bytes, decoded));
    benchmark::ClobberMemory();
  }
  if (decoded != packet) state.SkipWithError("decode does not give the packet back");
  report(state, packet, bytes.size());
}
BENCHMARK(BM_DecodeValidate);

// ---- FAP state at a receiver ----

constexpr int64_t kFrameNs = 1'000'000'000 / 60;  // a renderer at 60 frames per second

// What a renderer does each frame: the amplitude of every active FAP. The FAPs (8, a face
// that speaks; 72, every one) start transitions of 0..1000 ms with every curve at time 0,
// and the frames run over 0..1 s and again: on average half the transitions are running.
void BM_FapStateFrame(benchmark::State& state) {
  testing::RandomMarkup random(2);
  const int active = static_cast<int>(state.range(0));
  FapState fap_state;
  std::vector<int> indexes;
  for (int i = 0; i < active; ++i) {
    Fap f = random.fap();
    f.index = static_cast<uint8_t>(kMinFapIndex + i);
    f.transition_ms = static_cast<uint16_t>(random.uniform(0, 1000));
    fap_state.apply(f, 0);
    indexes.push_back(f.index);
  }
  int frame = 0;
  for (auto _ : state) {
    const int64_t t = (frame++ % 60) * kFrameNs;
    double sum = 0;
    for (const int index : indexes) sum += fap_state.amplitude(index, t);
    benchmark::DoNotOptimize(sum);
  }
  state.counters["amplitudes/s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * indexes.size()), benchmark::Counter::kIsRate);
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FapStateFrame)->ArgName("active_faps")->Arg(8)->Arg(72);

// Bookmarks applied as they arrive: 4096 random FAPs, 20 ms apart, then the same again later.
void BM_FapStateApply(benchmark::State& state) {
  testing::RandomMarkup random(3);
  std::vector<Fap> faps;
  for (int i = 0; i < 4096; ++i) faps.push_back(random.fap());
  constexpr int64_t kStepNs = 20'000'000;
  FapState fap_state;
  int64_t t = 0;
  size_t i = 0;
  for (auto _ : state) {
    fap_state.apply(faps[i], t);
    if (++i == faps.size()) i = 0;
    t += kStepNs;
  }
  benchmark::DoNotOptimize(fap_state.settled(kMinFapIndex));
  state.counters["bookmarks/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FapStateApply);

// ---- How the cost of a packet grows with its size ----

// Packets of one shape: `phonemes` phonemes with `faps_per_phoneme` FAPs before each, after
// `recovery_entries` dynamic recovery entries.
Packet shaped_packet(int phonemes, int faps_per_phoneme, int recovery_entries) {
  testing::RandomMarkup random(4);
  Packet packet;
  if (recovery_entries > 0) {
    packet.recovery_kind = RecoveryKind::kDynamic;
    packet.covered_packets = 4;
    for (int i = 0; i < recovery_entries; ++i) packet.recovery.push_back(random.fap());
  }
  std::vector<Fap> faps;
  for (int i = 0; i < phonemes; ++i) {
    faps.clear();
    for (int k = 0; k < faps_per_phoneme; ++k) faps.push_back(random.fap());
    packet.add_phoneme(random.phoneme(), faps);
  }
  return packet;
}

// The time per packet is the benchmark's; per_byte is the time per payload byte.
void report_growth(benchmark::State& state, size_t bytes) {
  state.counters["payload_bytes"] = static_cast<double>(bytes);
  state.counters["per_byte"] =
      benchmark::Counter(static_cast<double>(state.iterations() * bytes),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void encode_growth(benchmark::State& state, const Packet& packet) {
  std::vector<uint8_t> out(encoded_size(packet));
  for (auto _ : state) {
    benchmark::DoNotOptimize(encode_payload(packet, out));
    benchmark::ClobberMemory();
  }
  report_growth(state, out.size());
}

void decode_growth(benchmark::State& state, const Packet& packet) {
  std::vector<uint8_t> bytes(encoded_size(packet));
  encode_payload(packet, bytes);
  Packet decoded;
  for (auto _ : state) {
    benchmark::DoNotOptimize(decode_payload(bytes, decoded));
    benchmark::ClobberMemory();
  }
  if (decoded != packet) state.SkipWithError("decode does not give the packet back");
  report_growth(state, bytes.size());
}

// Phonemes per packet, without FAPs or recovery: up to 256 (a full payload holds 346).
void BM_EncodeByPhonemes(benchmark::State& state) {
  encode_growth(state, shaped_packet(static_cast<int>(state.range(0)), 0, 0));
}
void BM_DecodeByPhonemes(benchmark::State& state) {
  decode_growth(state, shaped_packet(static_cast<int>(state.range(0)), 0, 0));
}
BENCHMARK(BM_EncodeByPhonemes)->ArgName("phonemes")->RangeMultiplier(4)->Range(1, 256);
BENCHMARK(BM_DecodeByPhonemes)->ArgName("phonemes")->RangeMultiplier(4)->Range(1, 256);

// FAPs per phoneme, one phoneme: up to 40 (MPEG-4's limit of bookmarks before a phoneme).
void BM_EncodeByFaps(benchmark::State& state) {
  encode_growth(state, shaped_packet(1, static_cast<int>(state.range(0)), 0));
}
void BM_DecodeByFaps(benchmark::State& state) {
  decode_growth(state, shaped_packet(1, static_cast<int>(state.range(0)), 0));
}
BENCHMARK(BM_EncodeByFaps)->ArgName("faps")->Arg(0)->Arg(1)->Arg(2)->Arg(4)->Arg(10)->Arg(40);
BENCHMARK(BM_DecodeByFaps)->ArgName("faps")->Arg(0)->Arg(1)->Arg(2)->Arg(4)->Arg(10)->Arg(40);

// Recovery entries before one phoneme: up to 72, every FAP.
void BM_EncodeByRecoveryEntries(benchmark::State& state) {
  encode_growth(state, shaped_packet(1, 0, static_cast<int>(state.range(0))));
}
void BM_DecodeByRecoveryEntries(benchmark::State& state) {
  decode_growth(state, shaped_packet(1, 0, static_cast<int>(state.range(0))));
}
BENCHMARK(BM_EncodeByRecoveryEntries)->ArgName("entries")->Arg(0)->Arg(1)->Arg(4)->Arg(16)->Arg(72);
BENCHMARK(BM_DecodeByRecoveryEntries)->ArgName("entries")->Arg(0)->Arg(1)->Arg(4)->Arg(16)->Arg(72);

// The sender's recovery work per data packet at each recovery depth: add_dynamic (entries
// for the FAPs the covered packets bookmarked) and sent (remember the packet), over packets
// of speech as rtppfappay makes them at its defaults: 1 or 2 phonemes of 40..100 ms, a
// bookmark before 45 % of them (1..3 FAPs of the indexes 3..12 and 69..74, reused).
void BM_RecoverySender(benchmark::State& state) {
  testing::RandomMarkup random(5);
  std::vector<Packet> packets(1024);
  std::vector<int64_t> starts;
  int64_t t = 0;
  for (Packet& packet : packets) {
    starts.push_back(t);
    std::vector<Fap> faps;
    for (int n = random.uniform(1, 2); n > 0; --n) {
      faps.clear();
      if (random.chance(0.45)) {
        for (int k = random.uniform(1, 3); k > 0; --k) {
          Fap f = random.fap();
          const int i = random.uniform(0, 15);
          f.index =
              static_cast<uint8_t>(i < 10 ? kMinFapIndex + i : kFirstExpressionIndex + i - 10);
          f.transition_ms = static_cast<uint16_t>(random.uniform(50, 500));
          faps.push_back(f);
        }
      }
      Phoneme p = random.phoneme();
      p.duration_ms = static_cast<uint16_t>(random.uniform(40, 100));
      t += int64_t{p.duration_ms} * kNsPerMs;
      packet.add_phoneme(p, faps);
    }
  }
  const unsigned depth = static_cast<unsigned>(state.range(0));
  RecoverySender sender(depth);
  Packet packet;
  size_t i = 0;
  int64_t lap_ns = 0;  // time goes on across laps over the packets
  size_t entries = 0;
  for (auto _ : state) {
    packet = packets[i];
    const int64_t start_ns = lap_ns + starts[i];
    sender.add_dynamic(packet, start_ns, 1388 - encoded_size(packet));
    entries += packet.recovery.size();
    sender.sent(packet, start_ns);
    if (++i == packets.size()) {
      i = 0;
      lap_ns += t;
    }
  }
  state.counters["entries/packet"] =
      static_cast<double>(entries) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_RecoverySender)->ArgName("depth")->Arg(0)->Arg(1)->Arg(4)->Arg(15)->Arg(40);

}  // namespace
}  // namespace pfap

BENCHMARK_MAIN();
