// SPDX-License-Identifier: LGPL-2.1-or-later
// Each phoneme's f0, measured from the synthesized audio with aubio's YIN.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pfap::tts {

// The mean f0 in Hz of each segment [bounds[i], bounds[i + 1]) of `samples` (so one fewer
// than `bounds`): aubio "yinfast" over 1024-sample windows every 128 samples, averaged over
// the windows centred in the segment that YIN finds voiced (confidence >= 0.8, 50..500 Hz);
// 0 when none is. Stops early, with the windows measured so far, when `*cancel` becomes true.
std::vector<double> segment_f0(std::span<const int16_t> samples, unsigned rate,
                               std::span<const size_t> bounds,
                               const std::atomic<bool>* cancel = nullptr);

}  // namespace pfap::tts
