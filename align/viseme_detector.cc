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
  auto model = std::make_unique<VisemeModel>();
  while (!n.empty() && model->networks_.size() < kMaxVisemeNetworks) {
    size_t used = 0;
    std::optional<VisemeNetwork> network = VisemeNetwork::from_numbers(n, &used);
    if (!network) return nullptr;
    model->networks_.push_back(std::move(*network));
    n = n.subspan(used);
  }
  if (model->networks_.empty() || !n.empty()) return nullptr;
  return model;
}

size_t VisemeModel::weights() const {
  size_t sum = 0;
  for (const VisemeNetwork& network : networks_) sum += network.weights();
  return sum;
}

std::optional<VisemeNetwork> VisemeNetwork::from_numbers(std::span<const float> n, size_t* used) {
  auto whole = [](float v, size_t low, size_t high) {
    return v >= static_cast<float>(low) && v <= static_cast<float>(high) && v == std::floor(v);
  };
  if (n.size() < kHeader || n[0] != kKind || n[1] != kVisemeMfccs ||
      !whole(n[2], 0, kMaxVisemePastFrames) || n[3] != kVisemeAheadFrames || n[6] != kVisemeCount ||
      !whole(n[4], 1, kMaxHiddenUnits) || !whole(n[5], 1, kMaxHiddenUnits)) {
    return std::nullopt;
  }
  VisemeNetwork network;
  network.past_ = static_cast<size_t>(n[2]);
  const std::array<size_t, 4> sizes = {network.inputs(), static_cast<size_t>(n[4]),
                                        static_cast<size_t>(n[5]), kVisemeCount};
  size_t want = kHeader + kNormalization;
  for (size_t l = 0; l < 3; ++l) want += sizes[l + 1] * (sizes[l] + 1);
  if (n.size() < want) return std::nullopt;
  const float* p = n.data() + kHeader;
  network.normalization_.assign(p, p + kNormalization);
  p += kNormalization;
  for (size_t l = 0; l < 3; ++l) {
    Layer& layer = network.layers_[l];
    layer.inputs = sizes[l];
    layer.outputs = sizes[l + 1];
    layer.weights.assign(p, p + layer.inputs * layer.outputs);
    p += layer.weights.size();
    layer.biases.assign(p, p + layer.outputs);
    p += layer.outputs;
  }
  *used = want;
  return network;
}

size_t VisemeNetwork::weights() const {
  size_t sum = normalization_.size();
  for (const Layer& layer : layers_) sum += layer.weights.size() + layer.biases.size();
  return sum;
}

void VisemeNetwork::probabilities(std::span<const float> context, std::span<float> out) const {
  const float* mean = normalization_.data();
  const float* scale = mean + kVisemeMfccs;
  const size_t inputs = this->inputs();
  // On the stack, as large as any model's inputs and layers: no allocation a frame.
  std::array<float, (kMaxVisemePastFrames + 1 + kVisemeAheadFrames) * kVisemeMfccs> x;
  std::array<float, kMaxHiddenUnits> h1, h2;
  for (size_t i = 0; i < inputs; ++i) {
    x[i] = (context[i] - mean[i % kVisemeMfccs]) * scale[i % kVisemeMfccs];
  }
  // out[r] = b[r] + sum W[r][c] in[c], ReLU but on the last
  auto apply = [](const Layer& layer, const float* in, float* result, bool relu) {
    const float* w = layer.weights.data();
    for (size_t r = 0; r < layer.outputs; ++r) {
      double sum = layer.biases[r];
      for (size_t c = 0; c < layer.inputs; ++c) {
        sum += static_cast<double>(w[r * layer.inputs + c]) * in[c];
      }
      result[r] = relu ? std::max(0.0f, static_cast<float>(sum)) : static_cast<float>(sum);
    }
  };
  apply(layers_[0], x.data(), h1.data(), true);
  apply(layers_[1], h1.data(), h2.data(), true);
  apply(layers_[2], h2.data(), out.data(), false);
  const float top = *std::max_element(out.begin(), out.end());
  double sum = 0;
  for (float& v : out) sum += v = std::exp(v - top);
  for (float& v : out) v = static_cast<float>(v / sum);
}

VisemeDetector::VisemeDetector(unsigned rate, size_t max_run_frames, VisemeSmoothing smoothing,
                               const VisemeModel& model)
    : max_run_frames_(max_run_frames), smoothing_(smoothing), resampler_(rate) {
  for (const VisemeNetwork& network : model.networks()) {
    Member member{&network, CepstralMean(network.cepstral_prior()), {}};
    for (size_t k = 0; k < network.past_frames(); ++k) {
      member.context.insert(member.context.end(), silence_frame().begin(), silence_frame().end());
    }
    members_.push_back(std::move(member));
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
  take_frames(true, out);
}

void VisemeDetector::finish(std::vector<VisemeRun>& out) {
  resampled_.clear();
  resampler_.finish(resampled_);
  coefficients_.clear();
  mfcc_.push(resampled_, coefficients_);
  mfcc_.finish(coefficients_);
  take_frames(true, out);
  // The frames ahead of the last ones are silence.
  while (classified_ < mfcc_.frames()) {
    coefficients_.assign(silence_frame().begin(), silence_frame().end());
    take_frames(false, out);
  }
  while (decided_ < classified_) decide(out);
  if (open_.frames > 0) out.push_back(open_);
  open_.frames = 0;
}

// `heard`: the frames are the stream's (each network's cepstral mean takes its own from them),
// not the silence after its end.
void VisemeDetector::take_frames(bool heard, std::vector<VisemeRun>& out) {
  for (size_t at = 0; at < coefficients_.size(); at += kVisemeMfccs) {
    const auto frame = std::span(coefficients_).subspan(at, kVisemeMfccs);
    for (Member& m : members_) {
      m.context.insert(m.context.end(), frame.begin(), frame.end());
      if (heard) m.cepstral_mean.apply(std::span(m.context).last(kVisemeMfccs));
    }
    // Every context fills at the same frame: each holds its past before the first.
    if (members_[0].context.size() < members_[0].network->inputs()) continue;
    classify(out);
    for (Member& m : members_) m.context.erase(m.context.begin(), m.context.begin() + kVisemeMfccs);
  }
}

void VisemeDetector::classify(std::vector<VisemeRun>& out) {
  // The networks' mean probability of each viseme.
  std::array<double, kVisemeCount> sum{};
  std::array<float, kVisemeCount> p;
  for (const Member& m : members_) {
    m.network->probabilities(m.context, p);
    for (size_t v = 0; v < kVisemeCount; ++v) sum[v] += p[v];
  }
  for (size_t v = 0; v < kVisemeCount; ++v) {
    p[v] = static_cast<float>(sum[v] / static_cast<double>(members_.size()));
  }
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
