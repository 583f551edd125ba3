// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap/packetizer.h"

#include <cstdlib>
#include <utility>

namespace pfap {
namespace {

constexpr int64_t kNsPerSecond = 1'000'000'000;
// Phoneme starts within this of the pending packet's end count as contiguous: the caller's
// start times come from a clock, the durations on the wire are whole milliseconds.
constexpr int64_t kContiguityToleranceNs = 500'000;

size_t phoneme_bytes(size_t fap_count) {
  return kPhonemeDescriptorBytes + kFapDescriptorBytes * fap_count;
}

}  // namespace

uint32_t rtp_ticks(int64_t time_ns, uint32_t clock_rate) {
  // Whole seconds (floored, so the rest is never negative) and the rest, so that no product
  // overflows: rest * rate < 1e9 * 2^32 < 2^63. Only the low 32 bits of the seconds' ticks
  // matter, and unsigned multiplication keeps them. Halves round up, the same either side
  // of zero.
  int64_t seconds = time_ns / kNsPerSecond;
  int64_t rest_ns = time_ns % kNsPerSecond;
  if (rest_ns < 0) {
    --seconds;
    rest_ns += kNsPerSecond;
  }
  const uint64_t rest_ticks =
      (static_cast<uint64_t>(rest_ns) * clock_rate + kNsPerSecond / 2) / kNsPerSecond;
  return static_cast<uint32_t>(static_cast<uint64_t>(seconds) * clock_rate + rest_ticks);
}

Packetizer::Packetizer(const PacketizerConfig& config) : config_(config) {}

void Packetizer::push(const TimedPhoneme& phoneme, std::span<const Fap> faps,
                      std::vector<PlannedPacket>& out) {
  const size_t bytes = phoneme_bytes(faps.size());
  if (has_pending()) {
    const bool contiguous = std::abs(phoneme.start_ns - pending_end_ns_) <= kContiguityToleranceNs;
    if (phoneme.sentence_start || !contiguous ||
        phoneme.start_ns - pending_.start_ns >= config_.max_delay_ns ||
        pending_size_ + bytes > config_.max_payload_size) {
      finish(out);
    }
  }

  if (!has_pending()) {
    pending_.start_ns = phoneme.start_ns;
    pending_.marker = phoneme.sentence_start;
    pending_.oversized = kPacketDescriptorBytes + bytes > config_.max_payload_size;
    pending_size_ = kPacketDescriptorBytes;
    pending_end_ns_ = phoneme.start_ns;
  }
  pending_.packet.add_phoneme(phoneme.phoneme, faps);
  pending_size_ += bytes;
  // Summed from the first start in whole milliseconds, so clock jitter does not accumulate.
  pending_end_ns_ += int64_t{phoneme.phoneme.duration_ms} * kNsPerMs;

  // Finished at once when no later phoneme may join: end of text, the delay bound reached,
  // or no room for another phoneme (which an oversized packet never has).
  if (phoneme.phoneme.end_of_text || pending_end_ns_ - pending_.start_ns >= config_.max_delay_ns ||
      pending_size_ + kPhonemeDescriptorBytes > config_.max_payload_size) {
    finish(out);
  }
}

void Packetizer::drain(std::vector<PlannedPacket>& out) {
  if (has_pending()) finish(out);
}

void Packetizer::drop() { pending_ = PlannedPacket{}; }

void Packetizer::recycle(std::vector<PlannedPacket>& sent) {
  for (PlannedPacket& planned : sent) {
    planned.packet.clear();
    spare_.push_back(std::move(planned.packet));
  }
  sent.clear();
}

void Packetizer::finish(std::vector<PlannedPacket>& out) {
  out.push_back(std::move(pending_));
  pending_ = PlannedPacket{};
  if (!spare_.empty()) {
    pending_.packet = std::move(spare_.back());
    spare_.pop_back();
  }
}

}  // namespace pfap
