// SPDX-License-Identifier: LGPL-2.1-or-later
// web/src/viseme_detector.js computes the same, step by step: a change here is a change there
// (tests/web checks that both give the same visemes).
#include "viseme_features.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numeric>

namespace pfap::align {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr size_t kFft = 512;
constexpr size_t kBins = kFft / 2 + 1;
constexpr size_t kBands = 26;
constexpr double kLowHz = 100;
constexpr double kHighHz = 7600;
constexpr double kLogFloor = 1e-10;  // the power of a band of digital silence
constexpr double kCutoff = 0.45;     // of the lower of the two rates
constexpr double kZeroCrossings = 16;

double mel(double hz) { return 2595 * std::log10(1 + hz / 700); }
double hz(double m) { return 700 * (std::pow(10, m / 2595) - 1); }

// An in-place radix-2 FFT of kFft points.
void fft(std::vector<std::complex<double>>& x) {
  for (size_t i = 1, j = 0; i < kFft; ++i) {
    size_t bit = kFft >> 1;
    for (; (j & bit) != 0; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(x[i], x[j]);
  }
  for (size_t len = 2; len <= kFft; len <<= 1) {
    const double angle = -2 * kPi / static_cast<double>(len);
    for (size_t i = 0; i < kFft; i += len) {
      for (size_t k = 0; k < len / 2; ++k) {
        const std::complex<double> w(std::cos(angle * static_cast<double>(k)),
                                     std::sin(angle * static_cast<double>(k)));
        const std::complex<double> u = x[i + k], v = x[i + k + len / 2] * w;
        x[i + k] = u + v;
        x[i + k + len / 2] = u - v;
      }
    }
  }
}

}  // namespace

Resampler::Resampler(unsigned rate) {
  rate = std::clamp(rate, kMinVisemeInputRate, kMaxVisemeInputRate);
  passthrough_ = rate == kVisemeRate;
  if (passthrough_) return;
  const size_t g = std::gcd(static_cast<size_t>(rate), static_cast<size_t>(kVisemeRate));
  up_ = kVisemeRate / g;
  down_ = rate / g;
  // The filter in input samples: a cutoff of kCutoff of the lower rate, as a fraction of
  // the input rate; kZeroCrossings of it each side, under a Hann window.
  const double f = 2 * kCutoff * std::min(rate, kVisemeRate) / rate;
  half_ = static_cast<size_t>(std::ceil(kZeroCrossings / f));
  table_.resize(up_ * 2 * half_);
  for (size_t p = 0; p < up_; ++p) {
    const double frac = static_cast<double>(p) / static_cast<double>(up_);
    for (size_t t = 0; t < 2 * half_; ++t) {
      const double x = static_cast<double>(t) - static_cast<double>(half_) + 1 - frac;
      const double s = x == 0 ? 1 : std::sin(kPi * f * x) / (kPi * f * x);
      const double w = 0.5 * (1 + std::cos(kPi * x / static_cast<double>(half_)));
      table_[p * 2 * half_ + t] = static_cast<float>(f * s * w);
    }
  }
}

void Resampler::push(std::span<const float> in, std::vector<float>& out) {
  if (passthrough_) {
    out.insert(out.end(), in.begin(), in.end());
    return;
  }
  in_.insert(in_.end(), in.begin(), in.end());
  const size_t have = in_start_ + in_.size();
  for (;;) {
    const size_t pos = next_ * down_;
    const size_t centre = pos / up_;  // input sample at or before the output's time
    if (centre + half_ >= have) break;
    const float* taps = table_.data() + (pos % up_) * 2 * half_;
    double sum = 0;
    for (size_t t = 0; t < 2 * half_; ++t) {
      // input centre - half_ + 1 + t; before the stream's start, zeros
      const size_t i = centre + 1 + t;
      if (i < half_) continue;
      sum += static_cast<double>(taps[t]) * in_[i - half_ - in_start_];
    }
    out.push_back(static_cast<float>(sum));
    ++next_;
  }
  // Keep what the next output needs.
  const size_t centre = next_ * down_ / up_;
  const size_t keep_from = centre + 1 > half_ ? centre + 1 - half_ : 0;
  if (keep_from > in_start_ + in_.size() / 2) {
    const size_t drop = std::min(keep_from - in_start_, in_.size());
    in_.erase(in_.begin(), in_.begin() + static_cast<std::ptrdiff_t>(drop));
    in_start_ += drop;
  }
}

void Resampler::finish(std::vector<float>& out) {
  if (passthrough_) return;
  // The outputs whose times lie within the input, as if zeros followed it.
  const size_t wanted = ((in_start_ + in_.size()) * up_ + down_ - 1) / down_;
  std::vector<float> rest;
  push(std::vector<float>(half_ + 1, 0.0f), rest);
  const size_t first = next_ - rest.size();
  if (wanted > first) out.insert(out.end(), rest.begin(), rest.begin() + static_cast<std::ptrdiff_t>(std::min(rest.size(), wanted - first)));
}

MfccFrames::MfccFrames() {
  window_.resize(kVisemeWindow);
  for (size_t i = 0; i < kVisemeWindow; ++i) {
    window_[i] = static_cast<float>(
        0.5 - 0.5 * std::cos(2 * kPi * static_cast<double>(i) / (kVisemeWindow - 1)));
  }
  // Triangular filters on the mel scale between kLowHz and kHighHz, as dense rows.
  mel_.assign(kBands * kBins, 0.0f);
  std::vector<double> edges(kBands + 2);
  for (size_t b = 0; b < kBands + 2; ++b) {
    edges[b] = hz(mel(kLowHz) + (mel(kHighHz) - mel(kLowHz)) * static_cast<double>(b) /
                                    static_cast<double>(kBands + 1));
  }
  for (size_t b = 0; b < kBands; ++b) {
    for (size_t k = 0; k < kBins; ++k) {
      const double f = static_cast<double>(k) * kVisemeRate / kFft;
      double w = 0;
      if (f > edges[b] && f <= edges[b + 1]) w = (f - edges[b]) / (edges[b + 1] - edges[b]);
      if (f > edges[b + 1] && f < edges[b + 2])
        w = (edges[b + 2] - f) / (edges[b + 2] - edges[b + 1]);
      mel_[b * kBins + k] = static_cast<float>(w);
    }
  }
  // DCT-II, orthonormal.
  dct_.resize(kVisemeMfccs * kBands);
  for (size_t i = 0; i < kVisemeMfccs; ++i) {
    const double scale = std::sqrt((i == 0 ? 1.0 : 2.0) / kBands);
    for (size_t j = 0; j < kBands; ++j) {
      dct_[i * kBands + j] = static_cast<float>(
          scale * std::cos(kPi * static_cast<double>(i) * (static_cast<double>(j) + 0.5) /
                           kBands));
    }
  }
  // Frame 0's window starts kVisemeWindowLead samples before the stream: zeros.
  buffer_.assign(kVisemeWindowLead, 0.0f);
}

void MfccFrames::frame(std::vector<float>& out) {
  std::vector<std::complex<double>> x(kFft);
  for (size_t i = 0; i < kVisemeWindow; ++i) {
    x[i] = static_cast<double>(buffer_[at_ + i]) * static_cast<double>(window_[i]);
  }
  fft(x);
  std::array<double, kBins> power;
  for (size_t k = 0; k < kBins; ++k) power[k] = std::norm(x[k]);
  std::array<double, kBands> logmel;
  for (size_t b = 0; b < kBands; ++b) {
    double e = 0;
    for (size_t k = 0; k < kBins; ++k) e += static_cast<double>(mel_[b * kBins + k]) * power[k];
    logmel[b] = std::log(std::max(e, kLogFloor));
  }
  for (size_t i = 0; i < kVisemeMfccs; ++i) {
    double c = 0;
    for (size_t j = 0; j < kBands; ++j) c += static_cast<double>(dct_[i * kBands + j]) * logmel[j];
    out.push_back(static_cast<float>(c));
  }
  at_ += kVisemeHop;
  ++frames_;
}

void MfccFrames::push(std::span<const float> in, std::vector<float>& out) {
  buffer_.insert(buffer_.end(), in.begin(), in.end());
  samples_ += in.size();
  while (buffer_.size() - at_ >= kVisemeWindow) frame(out);
  buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(at_));
  at_ = 0;
}

void MfccFrames::finish(std::vector<float>& out) {
  const size_t total = (samples_ + kVisemeHop - 1) / kVisemeHop;
  while (frames_ < total) {
    buffer_.resize(std::max(buffer_.size(), at_ + kVisemeWindow), 0.0f);
    frame(out);
  }
}

CepstralMean::CepstralMean(std::span<const float> prior)
    : prior_(prior.begin(), prior.end()), mean_(prior_) {}

void CepstralMean::apply(std::span<float> coefficients) {
  for (size_t at = 0; at + kVisemeMfccs <= coefficients.size(); at += kVisemeMfccs) {
    float* c = coefficients.data() + at;
    if (c[0] > kCepstralSoundC0) {
      const double alpha = 1.0 / static_cast<double>(std::min(kCepstralPriorFrames + sound_frames_,
                                                              kCepstralMeanFrames));
      for (size_t i = 1; i < kVisemeMfccs; ++i) mean_[i - 1] += alpha * (c[i] - mean_[i - 1]);
      ++sound_frames_;
    }
    for (size_t i = 1; i < kVisemeMfccs; ++i) {
      c[i] = static_cast<float>(static_cast<double>(c[i]) - mean_[i - 1] + prior_[i - 1]);
    }
  }
}

std::vector<float> viseme_features(std::span<const int16_t> samples, unsigned rate) {
  std::vector<float> in(samples.size()), resampled, out;
  for (size_t i = 0; i < samples.size(); ++i) in[i] = static_cast<float>(samples[i]) / 32768;
  Resampler resampler(rate);
  resampler.push(in, resampled);
  resampler.finish(resampled);
  MfccFrames mfcc;
  mfcc.push(resampled, out);
  mfcc.finish(out);
  return out;
}

}  // namespace pfap::align
