// SPDX-License-Identifier: LGPL-2.1-or-later
// The frame-level viseme detector's features, as the audio comes: any rate resampled to
// 16 kHz, then 13 MFCCs (c0..c12) of a 25 ms window every 10 ms, and the running mean that
// takes a channel out of c1..c12. Hand-written (no aubio) so that web/src/viseme_detector.js
// computes the same numbers in a browser; the training (tools/viseme-train) reads the MFCCs
// from this code through tools/pfap-viseme-data and computes the mean as CepstralMean does.
// docs/align.md, "A viseme detector".
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pfap::align {

inline constexpr unsigned kVisemeRate = 16000;           // the features' rate
inline constexpr size_t kVisemeHop = 160;                // samples per frame: 10 ms
inline constexpr size_t kVisemeWindow = 400;             // 25 ms Hann window
inline constexpr size_t kVisemeWindowLead = 120;         // the window starts this far before
                                                         // its frame: centred on the frame's
                                                         // middle (frame k: [160k, 160k+160))
inline constexpr size_t kVisemeMfccs = 13;               // c0 (the level) .. c12
inline constexpr unsigned kMinVisemeInputRate = 8000;    // the resampler's range
inline constexpr unsigned kMaxVisemeInputRate = 192000;

// A windowed-sinc resampler from `rate` to 16 kHz, as the audio comes: low-pass at 0.45 of the lower
// rate, 16 zero crossings of the filter each side (at most 2.25 ms of input ahead), one
// table of filter phases. At 16 kHz it passes the samples through.
class Resampler {
 public:
  explicit Resampler(unsigned rate);
  // Appends the 16 kHz samples that `in` completes to `out`.
  void push(std::span<const float> in, std::vector<float>& out);
  // The rest, as if zeros followed.
  void finish(std::vector<float>& out);
  // Input samples ahead of an output sample's time that it needs.
  size_t lookahead() const { return half_; }

 private:
  size_t up_ = 1, down_ = 1;  // output position n is input position n * down_ / up_
  size_t half_ = 0;           // taps each side of the centre
  std::vector<float> table_;  // up_ phases of 2 * half_ taps
  std::vector<float> in_;     // input from in_start_ on
  size_t in_start_ = 0;
  size_t next_ = 0;  // the next output sample
  bool passthrough_ = true;
};

// MFCC frames of 16 kHz audio, as it comes. Frame k stands for samples [160k, 160k + 160); its
// window is [160k - 120, 160k + 280), zeros before the stream's start and after its end.
class MfccFrames {
 public:
  MfccFrames();
  // Appends each completed frame's kVisemeMfccs coefficients to `out`.
  void push(std::span<const float> in, std::vector<float>& out);
  // The frames of the samples pushed that are not out yet, zeros after them.
  void finish(std::vector<float>& out);
  size_t frames() const { return frames_; }

 private:
  void frame(std::vector<float>& out);

  std::vector<float> buffer_;  // the samples from frame frames_'s window start (at_) on
  size_t at_ = 0;
  size_t frames_ = 0;
  size_t samples_ = 0;  // pushed in all
  std::vector<float> window_, mel_, dct_;  // tables
  std::vector<size_t> mel_first_;          // each band's first FFT bin
};

// A running mean of c1..c12 over the frames of sound, causal, taken from each frame: a
// channel's spectral tilt (a microphone, a room, a codec) shifts them alike in every frame,
// and goes with the mean. The mean starts at `prior` (the training set's, so that a stream's
// first frames are as they come), weighted as kCepstralPriorFrames - 1 frames, and then follows
// about the last kCepstralMeanFrames frames of sound: alpha = 1 / min(kCepstralPriorFrames +
// n, kCepstralMeanFrames) after n. A frame counts as sound when its c0 is above
// kCepstralSoundC0: digital silence (-117) and a quiet room's hiss (LibriVox's pauses, -45
// to -37) do not move it; speech is mostly above -30.
// Each frame becomes c1..c12 less the mean plus `prior`; c0 (the level) stays.
inline constexpr size_t kCepstralPriorFrames = 100;
inline constexpr size_t kCepstralMeanFrames = 300;
inline constexpr double kCepstralSoundC0 = -35;
class CepstralMean {
 public:
  explicit CepstralMean(std::span<const float> prior);  // kVisemeMfccs - 1 values
  // Takes the mean from each frame of `coefficients` (kVisemeMfccs each), in place.
  void apply(std::span<float> coefficients);

 private:
  std::vector<double> prior_, mean_;
  size_t sound_frames_ = 0;
};

// The frames of a whole recording at `rate`, as the two classes give them (frames x
// kVisemeMfccs): for tools and tests.
std::vector<float> viseme_features(std::span<const int16_t> samples, unsigned rate);

}  // namespace pfap::align
