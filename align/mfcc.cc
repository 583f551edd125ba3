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

struct FrameAnalyzer::Aubio {
  std::unique_ptr<aubio_mfcc_t, decltype(&del_aubio_mfcc)> mfcc{nullptr, &del_aubio_mfcc};
  std::unique_ptr<fvec_t, decltype(&del_fvec)> in{nullptr, &del_fvec};
  std::unique_ptr<fvec_t, decltype(&del_fvec)> window{nullptr, &del_fvec};
  std::unique_ptr<aubio_fft_t, decltype(&del_aubio_fft)> fft{nullptr, &del_aubio_fft};
  std::unique_ptr<cvec_t, decltype(&del_cvec)> spectrum{nullptr, &del_cvec};
  std::unique_ptr<fvec_t, decltype(&del_fvec)> out{nullptr, &del_fvec};
};

FrameAnalyzer::FrameAnalyzer(unsigned rate)
    : rate_(rate),
      hop_(static_cast<size_t>(std::lround(kHopSeconds * rate))),
      window_(static_cast<size_t>(std::lround(kWindowSeconds * rate))),
      aubio_(std::make_unique<Aubio>()) {
  const auto n = static_cast<uint_t>(window_);
  aubio_->mfcc.reset(new_aubio_mfcc(n, kFilters, Features::kMfccs + 1, rate));
  aubio_mfcc_set_mel_coeffs(aubio_->mfcc.get(), kLowHz, kHighHz);
  aubio_->in.reset(new_fvec(n));
  aubio_->window.reset(new_aubio_window(const_cast<char*>("hanningz"), n));
  aubio_->fft.reset(new_aubio_fft(n));
  aubio_->spectrum.reset(new_cvec(n));
  aubio_->out.reset(new_fvec(Features::kMfccs + 1));
}

FrameAnalyzer::~FrameAnalyzer() = default;

Features FrameAnalyzer::frames_of(size_t samples) const {
  Features f;
  f.rate = rate_;
  f.hop = hop_;
  f.window = window_;
  f.n_frames = samples <= window_ ? 1 : 1 + (samples - window_) / hop_;
  f.data.resize(f.n_frames * Features::kDims);
  f.level_db.resize(f.n_frames);
  return f;
}

float FrameAnalyzer::analyze(std::span<const int16_t> samples, float* mfccs) {
  double energy = 0;
  for (size_t i = 0; i < window_; ++i) {
    const smpl_t x = i < samples.size() ? static_cast<smpl_t>(samples[i]) / 32768 : 0;
    energy += static_cast<double>(x) * x;
    aubio_->in->data[i] = x * aubio_->window->data[i];
  }
  aubio_fft_do(aubio_->fft.get(), aubio_->in.get(), aubio_->spectrum.get());
  aubio_mfcc_do(aubio_->mfcc.get(), aubio_->spectrum.get(), aubio_->out.get());
  for (size_t d = 0; d < Features::kMfccs; ++d) {
    // A log of a band with no energy at all would be -inf: such a coefficient counts as 0.
    const smpl_t c = aubio_->out->data[d + 1];
    mfccs[d] = std::isfinite(c) ? c : 0;
  }
  return energy > 0
             ? std::max(kFloorDb,
                        static_cast<float>(10 * std::log10(energy / static_cast<double>(window_))))
             : kFloorDb;
}

void normalize_mfccs(Features& f) {
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
}

Features mfcc(std::span<const int16_t> samples, unsigned rate) {
  FrameAnalyzer analyzer(rate);
  Features f = analyzer.frames_of(samples.size());
  for (size_t k = 0; k < f.n_frames; ++k) {
    f.level_db[k] = analyzer.analyze(samples.subspan(std::min(samples.size(), k * f.hop)),
                                     f.data.data() + k * Features::kDims);
  }
  normalize_mfccs(f);
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
