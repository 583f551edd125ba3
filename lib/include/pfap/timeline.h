// SPDX-License-Identifier: LGPL-2.1-or-later
// Where the events of a markup stream (x-pfap buffers) go in time, as the elements that read
// them place them: one rule for an event without a time, one for an event that goes back.
#pragma once

#include <cstdint>
#include <optional>

namespace pfap {

class EventTimeline {
 public:
  // Where an event starts: at `time_ns` when it has a time; else where the previous event
  // ended (phonemes follow one another, so a source that leaves the time out means this),
  // the stream's first event at `first_ns`.
  int64_t start(std::optional<int64_t> time_ns, int64_t first_ns) const {
    if (time_ns) return *time_ns;
    return end_ns_ ? *end_ns_ : first_ns;
  }

  // Whether an event at `time_ns` is earlier than the one before it; such an event is counted
  // (earlier_count) and goes at previous_ns(): writers and animations want times that never
  // go back.
  bool earlier(int64_t time_ns) {
    if (!previous_ns_ || time_ns >= *previous_ns_) return false;
    ++earlier_count_;
    return true;
  }
  // The previous event's time; 0 before the first.
  int64_t previous_ns() const { return previous_ns_.value_or(0); }
  // Events found earlier than the one before them, since construction (reset keeps it).
  uint64_t earlier_count() const { return earlier_count_; }

  // Records an event at `time_ns` lasting `duration_ns` (0 for a state event).
  void add(int64_t time_ns, int64_t duration_ns) {
    previous_ns_ = time_ns;
    end_ns_ = time_ns + duration_ns;
  }
  // Forgets the events (a new stream): the next is a first event again.
  void reset() {
    previous_ns_.reset();
    end_ns_.reset();
  }

 private:
  std::optional<int64_t> previous_ns_;
  std::optional<int64_t> end_ns_;
  uint64_t earlier_count_ = 0;
};

}  // namespace pfap
