// SPDX-License-Identifier: LGPL-2.1-or-later
// web/src/viseme_detector.js is the same, step by step (tests/web checks that both give the
// same visemes).
#include "viseme_detector.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace pfap::align {
namespace {

constexpr size_t kHeader = 7;  // kind, mfccs, past, ahead, hidden1, hidden2, visemes
constexpr float kKind = 2;     // 2: with the cepstral mean's prior
// The numbers before the layers: the inputs' means and scales, and the cepstral mean's prior.
constexpr size_t kNormalization = 2 * kVisemeMfccs + (kVisemeMfccs - 1);
// A hidden layer's units at most: the reader refuses more, and the network's scratch on the
// stack is that large.
constexpr size_t kMaxHiddenUnits = 1024;

// The model tools/viseme-train wrote: its numbers, C++ and JavaScript read the same file.
constexpr float kBuiltinNumbers[] = {
#include "viseme_model.txt"
};

// The coefficients of a window of digital silence: the context before the stream's start
// and after its end.
const std::vector<float>& silence_frame() {
  static const std::vector<float> frame = [] {
    MfccFrames mfcc;
    std::vector<float> out;
    mfcc.push(std::vector<float>(kVisemeWindow, 0.0f), out);
    out.resize(kVisemeMfccs);
    return out;
  }();
  return frame;
}

}  // namespace

const VisemeModel& VisemeModel::builtin() {
  static const std::unique_ptr<VisemeModel> model = from_numbers(kBuiltinNumbers);
  return *model;
}

std::unique_ptr<VisemeModel> VisemeModel::from_numbers(std::span<const float> n) {
  auto whole = [](float v, size_t low, size_t high) {
    return v >= static_cast<float>(low) && v <= static_cast<float>(high) && v == std::floor(v);
  };
  if (n.size() < kHeader || n[0] != kKind || n[1] != kVisemeMfccs ||
      !whole(n[2], 0, kMaxVisemePastFrames) || n[3] != kVisemeAheadFrames || n[6] != kVisemeCount ||
      !whole(n[4], 1, kMaxHiddenUnits) || !whole(n[5], 1, kMaxHiddenUnits)) {
    return nullptr;
  }
  auto model = std::make_unique<VisemeModel>();
  model->past_ = static_cast<size_t>(n[2]);
  model->hidden1_ = static_cast<size_t>(n[4]);
  model->hidden2_ = static_cast<size_t>(n[5]);
  const size_t inputs = model->inputs(), h1 = model->hidden1_, h2 = model->hidden2_;
  const size_t want = kNormalization + h1 * (inputs + 1) + h2 * (h1 + 1) + kVisemeCount * (h2 + 1);
  if (n.size() != kHeader + want) return nullptr;
  model->params_.assign(n.begin() + kHeader, n.end());
  return model;
}

void VisemeModel::probabilities(std::span<const float> context, std::span<float> out) const {
  const float* p = params_.data();
  const float* mean = p;
  const float* scale = p + kVisemeMfccs;
  p += kNormalization;
  const size_t inputs = this->inputs();
  // On the stack, as large as any model's inputs and layers: no allocation a frame.
  std::array<float, (kMaxVisemePastFrames + 1 + kVisemeAheadFrames) * kVisemeMfccs> x;
  std::array<float, kMaxHiddenUnits> h1, h2;
  for (size_t i = 0; i < inputs; ++i) {
    x[i] = (context[i] - mean[i % kVisemeMfccs]) * scale[i % kVisemeMfccs];
  }
  // layer: out[r] = b[r] + sum W[r][c] in[c], ReLU but on the last
  auto layer = [&p](const float* in, size_t n_in, size_t n_out, float* result, bool relu) {
    const float* w = p;
    const float* b = p + n_in * n_out;
    for (size_t r = 0; r < n_out; ++r) {
      double sum = b[r];
      for (size_t c = 0; c < n_in; ++c) sum += static_cast<double>(w[r * n_in + c]) * in[c];
      result[r] = relu ? std::max(0.0f, static_cast<float>(sum)) : static_cast<float>(sum);
    }
    p += n_in * n_out + n_out;
  };
  layer(x.data(), inputs, hidden1_, h1.data(), true);
  layer(h1.data(), hidden1_, hidden2_, h2.data(), true);
  layer(h2.data(), hidden2_, kVisemeCount, out.data(), false);
  const float top = *std::max_element(out.begin(), out.end());
  double sum = 0;
  for (float& v : out) sum += v = std::exp(v - top);
  for (float& v : out) v = static_cast<float>(v / sum);
}

VisemeDetector::VisemeDetector(unsigned rate, size_t max_run_frames, VisemeSmoothing smoothing,
                               const VisemeModel& model)
    : model_(model),
      max_run_frames_(max_run_frames),
      smoothing_(smoothing),
      resampler_(rate),
      cepstral_mean_(model.cepstral_prior()) {
  for (size_t k = 0; k < model.past_frames(); ++k) {
    context_.insert(context_.end(), silence_frame().begin(), silence_frame().end());
  }
}

void VisemeDetector::push(std::span<const int16_t> samples, std::vector<VisemeRun>& out) {
  std::vector<float> f(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) f[i] = static_cast<float>(samples[i]) / 32768;
  push(std::span<const float>(f), out);
}

void VisemeDetector::push(std::span<const float> samples, std::vector<VisemeRun>& out) {
  resampled_.clear();
  resampler_.push(samples, resampled_);
  coefficients_.clear();
  mfcc_.push(resampled_, coefficients_);
  cepstral_mean_.apply(coefficients_);
  take_frames(out);
}

void VisemeDetector::finish(std::vector<VisemeRun>& out) {
  resampled_.clear();
  resampler_.finish(resampled_);
  coefficients_.clear();
  mfcc_.push(resampled_, coefficients_);
  mfcc_.finish(coefficients_);
  cepstral_mean_.apply(coefficients_);
  take_frames(out);
  // The frames ahead of the last ones are silence.
  while (classified_ < mfcc_.frames()) {
    coefficients_.assign(silence_frame().begin(), silence_frame().end());
    take_frames(out);
  }
  while (decided_ < classified_) decide(out);
  if (open_.frames > 0) out.push_back(open_);
  open_.frames = 0;
}

void VisemeDetector::take_frames(std::vector<VisemeRun>& out) {
  for (size_t at = 0; at < coefficients_.size(); at += kVisemeMfccs) {
    context_.insert(context_.end(), coefficients_.begin() + static_cast<std::ptrdiff_t>(at),
                    coefficients_.begin() + static_cast<std::ptrdiff_t>(at + kVisemeMfccs));
    if (context_.size() < model_.inputs()) continue;
    classify(out);
    context_.erase(context_.begin(), context_.begin() + kVisemeMfccs);
  }
}

void VisemeDetector::classify(std::vector<VisemeRun>& out) {
  std::array<float, kVisemeCount> p;
  model_.probabilities(context_, p);
  if (trace_ != nullptr) trace_->insert(trace_->end(), p.begin(), p.end());
  probs_.insert(probs_.end(), p.begin(), p.end());
  ++classified_;
  // Frame k is decided once frame k + kSmoothFrames is classified.
  if (classified_ > kSmoothFrames) decide(out);
}

void VisemeDetector::decide(std::vector<VisemeRun>& out) {
  // probs_ holds frames [first, classified_); frame decided_'s neighbours within it.
  const uint64_t first = classified_ - probs_.size() / kVisemeCount;
  const uint64_t from = std::max(first, decided_ >= kSmoothFrames ? decided_ - kSmoothFrames : 0);
  const uint64_t to = std::min(classified_, decided_ + kSmoothFrames + 1);
  std::array<float, kVisemeCount> mean{};
  for (uint64_t k = from; k < to; ++k) {
    for (size_t v = 0; v < kVisemeCount; ++v) mean[v] += probs_[(k - first) * kVisemeCount + v];
  }
  const auto best = static_cast<size_t>(std::max_element(mean.begin(), mean.end()) - mean.begin());
  const auto shown = static_cast<size_t>(shown_);
  const float margin = smoothing_.switch_margin * static_cast<float>(to - from);
  if (best != shown && mean[best] > mean[shown] + margin && held_ >= smoothing_.min_run_frames) {
    if (open_.frames > 0) out.push_back(open_);
    shown_ = static_cast<Viseme>(best);
    open_ = {decided_, 0, shown_};
    held_ = 0;
  }
  if (open_.frames == 0) open_.start = decided_, open_.viseme = shown_;
  ++open_.frames;
  ++held_;
  if (max_run_frames_ > 0 && open_.frames >= max_run_frames_) {
    out.push_back(open_);
    open_ = {decided_ + 1, 0, shown_};
  }
  ++decided_;
  // Keep the frames the next decision averages.
  const uint64_t keep_from = decided_ >= kSmoothFrames ? decided_ - kSmoothFrames : 0;
  if (keep_from > first) {
    probs_.erase(probs_.begin(),
                 probs_.begin() + static_cast<std::ptrdiff_t>((keep_from - first) * kVisemeCount));
  }
}

}  // namespace pfap::align
