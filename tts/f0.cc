// SPDX-License-Identifier: LGPL-2.1-or-later
#include "f0.h"

#include <aubio/aubio.h>

#include <memory>

namespace pfap::tts {
namespace {

constexpr uint_t kWindow = 1024;  // 46 ms at 22050 Hz: two periods of 43 Hz
constexpr uint_t kHop = 128;      // 5.8 ms, several estimates in the shortest phonemes
constexpr smpl_t kMinConfidence = 0.8;
constexpr smpl_t kMinHz = 50;
constexpr smpl_t kMaxHz = 500;
constexpr smpl_t kSilenceDb = -50;

struct Estimate {
  size_t centre;  // sample at the middle of the window
  double hz;
};

}  // namespace

std::vector<double> segment_f0(std::span<const int16_t> samples, unsigned rate,
                               std::span<const size_t> bounds, const std::atomic<bool>* cancel) {
  std::vector<Estimate> voiced;
  {
    std::unique_ptr<aubio_pitch_t, decltype(&del_aubio_pitch)> pitch(
        new_aubio_pitch("yinfast", kWindow, kHop, rate), &del_aubio_pitch);
    std::unique_ptr<fvec_t, decltype(&del_fvec)> in(new_fvec(kHop), &del_fvec);
    std::unique_ptr<fvec_t, decltype(&del_fvec)> out(new_fvec(1), &del_fvec);
    aubio_pitch_set_unit(pitch.get(), "Hz");
    aubio_pitch_set_silence(pitch.get(), kSilenceDb);
    for (size_t hop_start = 0; hop_start < samples.size(); hop_start += kHop) {
      if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) break;
      for (uint_t k = 0; k < kHop; ++k) {
        const size_t j = hop_start + k;
        in->data[k] = j < samples.size() ? static_cast<smpl_t>(samples[j]) / 32768 : 0;
      }
      aubio_pitch_do(pitch.get(), in.get(), out.get());
      // The window ends with this hop.
      const size_t end = hop_start + kHop;
      if (end < kWindow / 2) continue;
      const smpl_t hz = out->data[0];
      if (hz >= kMinHz && hz <= kMaxHz &&
          aubio_pitch_get_confidence(pitch.get()) >= kMinConfidence) {
        voiced.push_back({end - kWindow / 2, hz});
      }
    }
  }
  std::vector<double> f0;
  auto it = voiced.begin();
  for (size_t i = 0; i + 1 < bounds.size(); ++i) {
    while (it != voiced.end() && it->centre < bounds[i]) ++it;
    double sum = 0;
    int n = 0;
    for (; it != voiced.end() && it->centre < bounds[i + 1]; ++it, ++n) sum += it->hz;
    f0.push_back(n > 0 ? sum / n : 0);
  }
  return f0;
}

}  // namespace pfap::tts
