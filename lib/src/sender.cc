// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap/sender.h"

#include <algorithm>

namespace pfap {

namespace {

PacketizerConfig packetizer_config(const SenderConfig& config) {
  return {config.max_payload_size, config.max_delay_ns};
}

}  // namespace

Sender::Sender(const SenderConfig& config)
    : config_(config),
      packetizer_(packetizer_config(config)),
      recovery_(config.recovery_depth),
      recovery_depth_(config.recovery_depth) {}

void Sender::configure(const SenderConfig& config) {
  config_ = config;
  apply_packetizer_config();
}

void Sender::apply_packetizer_config() {
  if (packetizer_.has_pending()) return;
  const PacketizerConfig wanted = packetizer_config(config_);
  const PacketizerConfig& now = packetizer_.config();
  if (wanted.max_payload_size != now.max_payload_size || wanted.max_delay_ns != now.max_delay_ns) {
    packetizer_ = Packetizer(wanted);
  }
}

void Sender::push(const TimedPhoneme& phoneme, std::span<const Fap> faps) {
  apply_packetizer_config();
  packetizer_.push(phoneme, faps, planned_);
}

void Sender::drain() { packetizer_.drain(planned_); }

const OutgoingPacket* Sender::next(bool requested) {
  if (next_planned_ == planned_.size()) {
    packetizer_.recycle(planned_);
    next_planned_ = 0;
    return nullptr;
  }
  PlannedPacket& planned = planned_[next_planned_];
  const size_t max_size = packetizer_.config().max_payload_size;
  if (!complete_checked_) {
    complete_checked_ = true;
    if (recovery_depth_ != config_.recovery_depth) {
      recovery_.set_depth(config_.recovery_depth);
      recovery_depth_ = config_.recovery_depth;
    }
    // Only forward movement counts: a jump back adds nothing, the speech after it does.
    if (position_) forward_ns_ += std::max<int64_t>(0, planned.start_ns - *position_);
    const int64_t interval = config_.complete_interval_ns;
    const bool due = !position_ || requested ||
                     (interval > 0 && forward_ns_ - last_complete_ns_ >= interval);
    // Sampled before this packet's bookmarks: the state a receiver has when it arrives.
    if (due) return complete_at(planned.start_ns);
  }
  complete_checked_ = false;
  ++next_planned_;

  Packet& packet = planned.packet;
  const size_t data_size = encoded_size(packet);
  recovery_.add_dynamic(packet, planned.start_ns, data_size < max_size ? max_size - data_size : 0);
  recovery_.sent(packet, planned.start_ns);
  const int64_t duration = packet.duration_ns();
  position_ = planned.start_ns + duration;
  forward_ns_ += duration;
  out_ = {OutgoingPacket::Kind::kData, &packet, planned.start_ns, duration, planned.marker,
          planned.oversized, max_size};
  return &out_;
}

const OutgoingPacket* Sender::complete_now() {
  if (!position_) return nullptr;
  return complete_at(*position_);
}

const OutgoingPacket* Sender::complete_at(int64_t time_ns) {
  const size_t max_size = packetizer_.config().max_payload_size;
  const bool fits = recovery_.make_complete(complete_, time_ns, max_size);
  if (fits) recovery_.sent(complete_, time_ns);
  last_complete_ns_ = forward_ns_;
  out_ = {fits ? OutgoingPacket::Kind::kComplete : OutgoingPacket::Kind::kCompleteTooLarge,
          &complete_,
          time_ns,
          0,
          false,
          false,
          max_size};
  return &out_;
}

void Sender::reset() {
  packetizer_.drop();
  planned_.clear();
  next_planned_ = 0;
  complete_checked_ = false;
  recovery_.reset();
  position_.reset();
  forward_ns_ = 0;
  last_complete_ns_ = 0;
  apply_packetizer_config();
}

}  // namespace pfap
