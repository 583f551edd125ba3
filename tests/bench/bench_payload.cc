// Encode and decode+validate throughput beside memcpy of the same bytes (the ceiling).
// Run: meson test -C build --benchmark --verbose   (or build/tests/bench/bench_payload)
#include <benchmark/benchmark.h>

#include <cstring>
#include <vector>

#include "pfap/payload.h"
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

}  // namespace
}  // namespace pfap

BENCHMARK_MAIN();
