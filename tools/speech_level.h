// SPDX-License-Identifier: LGPL-2.1-or-later
// The speech's level that a page finds in the audio it plays to know which time it hears
// (docs/web.md, Timing): the RMS of each millisecond of 48 kHz S16 mono, in S16 units. Sent by
// pfap-web (on its WebSocket) and pfap-broadcast (on Janus's data stream).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

class SpeechLevel {
 public:
  static constexpr int kSamplesPerLevel = 48;  // 1 ms at 48 kHz
  static constexpr size_t kLevelsPerMessage = 50;

  // Adds `samples`; calls `full()` each time kLevelsPerMessage levels are waiting (it takes
  // them with take()).
  template <typename Full>
  void add(std::span<const int16_t> samples, Full&& full) {
    for (int16_t sample : samples) {
      sum_ += static_cast<double>(sample) * sample;
      if (++count_ == kSamplesPerLevel) {
        levels_.push_back(std::lround(std::sqrt(sum_ / kSamplesPerLevel)));
        sum_ = 0.0;
        count_ = 0;
        if (levels_.size() == kLevelsPerMessage) full();
      }
    }
  }

  // The levels waiting, which go: each is the RMS of the millisecond after the one before.
  std::vector<int64_t> take() { return std::exchange(levels_, {}); }
  bool empty() const { return levels_.empty(); }

 private:
  std::vector<int64_t> levels_;
  double sum_ = 0.0;
  int count_ = 0;
};
