// SPDX-License-Identifier: LGPL-2.1-or-later
#include "mfcc.h"

#include <aubio/aubio.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace pfap::align {
namespace {

constexpr double kWindowSeconds = 0.025;
constexpr double kHopSeconds = 0.005;
constexpr uint_t kFilters = 40;
constexpr smpl_t kLowHz = 100;
constexpr smpl_t kHighHz = 7000;  // under 8 kHz, half the lowest rate
constexpr float kFloorDb = -120;

}  // namespace

size_t Features::frame_at(size_t sample) const {
  if (n_frames == 0) return 0;
  const double k =
      (static_cast<double>(sample) - static_cast<double>(window) / 2) / static_cast<double>(hop);
  return static_cast<size_t>(std::clamp(std::lround(k), 0L, static_cast<long>(n_frames - 1)));
}

Features mfcc(std::span<const int16_t> samples, unsigned rate) {
  Features f;
  f.rate = rate;
  f.hop = static_cast<size_t>(std::lround(kHopSeconds * rate));
  f.window = static_cast<size_t>(std::lround(kWindowSeconds * rate));
  f.n_frames = samples.size() <= f.window ? 1 : 1 + (samples.size() - f.window) / f.hop;

  std::unique_ptr<aubio_mfcc_t, decltype(&del_aubio_mfcc)> mf(
      new_aubio_mfcc(static_cast<uint_t>(f.window), kFilters, Features::kMfccs + 1, rate),
      &del_aubio_mfcc);
  aubio_mfcc_set_mel_coeffs(mf.get(), kLowHz, kHighHz);
  std::unique_ptr<fvec_t, decltype(&del_fvec)> in(new_fvec(static_cast<uint_t>(f.window)),
                                                  &del_fvec);
  std::unique_ptr<fvec_t, decltype(&del_fvec)> window(
      new_aubio_window(const_cast<char*>("hanningz"), static_cast<uint_t>(f.window)), &del_fvec);
  std::unique_ptr<aubio_fft_t, decltype(&del_aubio_fft)> fft(
      new_aubio_fft(static_cast<uint_t>(f.window)), &del_aubio_fft);
  std::unique_ptr<cvec_t, decltype(&del_cvec)> spectrum(new_cvec(static_cast<uint_t>(f.window)),
                                                        &del_cvec);
  std::unique_ptr<fvec_t, decltype(&del_fvec)> out(new_fvec(Features::kMfccs + 1), &del_fvec);

  f.data.resize(f.n_frames * Features::kDims);
  f.level_db.resize(f.n_frames);
  for (size_t k = 0; k < f.n_frames; ++k) {
    double energy = 0;
    for (size_t i = 0; i < f.window; ++i) {
      const size_t j = k * f.hop + i;
      const smpl_t x = j < samples.size() ? static_cast<smpl_t>(samples[j]) / 32768 : 0;
      energy += static_cast<double>(x) * x;
      in->data[i] = x * window->data[i];
    }
    f.level_db[k] =
        energy > 0
            ? std::max(kFloorDb,
                       static_cast<float>(10 * std::log10(energy / static_cast<double>(f.window))))
            : kFloorDb;
    aubio_fft_do(fft.get(), in.get(), spectrum.get());
    aubio_mfcc_do(mf.get(), spectrum.get(), out.get());
    for (size_t d = 0; d < Features::kMfccs; ++d) {
      // A log of a band with no energy at all would be -inf: such a coefficient counts as 0.
      const smpl_t c = out->data[d + 1];
      f.data[k * Features::kDims + d] = std::isfinite(c) ? c : 0;
    }
  }

  for (size_t d = 0; d < Features::kMfccs; ++d) {
    double sum = 0, sum2 = 0;
    for (size_t k = 0; k < f.n_frames; ++k) {
      const double x = f.data[k * Features::kDims + d];
      sum += x;
      sum2 += x * x;
    }
    const double mean = sum / static_cast<double>(f.n_frames);
    const double var = sum2 / static_cast<double>(f.n_frames) - mean * mean;
    const double scale = var > 1e-12 ? 1 / std::sqrt(var) : 0;
    for (size_t k = 0; k < f.n_frames; ++k) {
      float& x = f.data[k * Features::kDims + d];
      x = static_cast<float>((x - mean) * scale);
    }
  }
  // The level below the utterance's loudest frame, the same scale in any recording, so that
  // pauses match pauses (the MFCCs of silence, normalized, are anything).
  const float loudest = *std::max_element(f.level_db.begin(), f.level_db.end());
  for (size_t k = 0; k < f.n_frames; ++k) {
    const float below = std::clamp(f.level_db[k] - loudest, -kLevelRangeDb, 0.0f);
    f.data[k * Features::kDims + Features::kMfccs] = below / kLevelRangeDb * kLevelWeight;
  }
  return f;
}

}  // namespace pfap::align
