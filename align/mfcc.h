// SPDX-License-Identifier: LGPL-2.1-or-later
// Spectral features for aligning two recordings of the same words: MFCCs computed with aubio
// on windows of the same duration and over the same band whatever the sample rate, so that
// speech at 16 kHz and at 22.05 kHz give comparable frames.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace pfap::align {

// The sample rates the features are defined for: the mel band (below) must fit under half.
inline constexpr unsigned kMinRate = 16000;
inline constexpr unsigned kMaxRate = 48000;

// The level dimension: 0 for the loudest frame down to -kLevelWeight for kLevelRangeDb below
// it or less (live.cc measures it below the utterance's loudest so far).
inline constexpr float kLevelRangeDb = 50;
inline constexpr float kLevelWeight = 6;

struct Features {
  static constexpr size_t kMfccs = 13;         // MFCC 1..13 (c0, the level, is left out)
  static constexpr size_t kDims = kMfccs + 1;  // and the level below the loudest frame
  unsigned rate = 0;
  size_t hop = 0;     // samples between frames
  size_t window = 0;  // samples per frame
  size_t n_frames = 0;
  // n_frames x kDims: the MFCCs, each normalized to mean 0 and variance 1 over the utterance,
  // which takes away most of what differs between two voices and two microphones; then the
  // frame's level below the loudest frame's, 0 (loudest) to -kLevelWeight (50 dB below or
  // less), which tells pauses in any recording.
  std::vector<float> data;
  std::vector<float> level_db;  // each frame's RMS level in dBFS

  std::span<const float> frame(size_t k) const { return {data.data() + k * kDims, kDims}; }
  // The sample at the middle of frame k's window (frame k covers [k * hop, k * hop + window)).
  size_t centre(size_t k) const { return k * hop + window / 2; }
  // The frame whose centre is nearest `sample`.
  size_t frame_at(size_t sample) const;
};

// Features of `samples` at `rate` (kMinRate..kMaxRate): 25 ms Hann windows every 5 ms, 40 mel
// bands over 100..7000 Hz. Audio shorter than a window gives one frame (zero-padded).
Features mfcc(std::span<const int16_t> samples, unsigned rate);

// One frame of mfcc() before what is measured over all the frames: its MFCCs as aubio gives
// them and its RMS level. They depend on the frame's samples alone, so that the live aligner
// computes each frame once as its audio comes.
class FrameAnalyzer {
 public:
  explicit FrameAnalyzer(unsigned rate);  // kMinRate..kMaxRate
  ~FrameAnalyzer();
  FrameAnalyzer(const FrameAnalyzer&) = delete;
  FrameAnalyzer& operator=(const FrameAnalyzer&) = delete;

  size_t hop() const { return hop_; }
  size_t window() const { return window_; }
  // Features of `samples` samples as mfcc() frames them: their rate, hop, window and number of
  // frames, the values all 0.
  Features frames_of(size_t samples) const;
  // The frame that starts at samples[0] (zero-padded past the end if fewer than window()):
  // its Features::kMfccs coefficients into `mfccs`; returns its level in dBFS.
  float analyze(std::span<const int16_t> samples, float* mfccs);

 private:
  struct Aubio;
  unsigned rate_;
  size_t hop_, window_;
  std::unique_ptr<Aubio> aubio_;
};

// mfcc()'s normalization of each MFCC over `f`'s frames (the level dimension left alone).
void normalize_mfccs(Features& f);

}  // namespace pfap::align
