// SPDX-License-Identifier: LGPL-2.1-or-later
// A frame-level viseme detector for live audio without a text: the 15 Oculus visemes (the
// MPEG-4 visemes with silence, pfap::Viseme) of each 10 ms frame, from MFCCs with the model's
// past (160 ms in today's) and 40 ms ahead through a small network (align/viseme_model.txt,
// made by tools/viseme-train), smoothed into runs. Live: push audio as it comes, take the runs
// that are settled; each needs at most kVisemeLookaheadMs of audio after its frames. No
// GStreamer; web/src/viseme_detector.js is the same in JavaScript. docs/align.md, "A viseme
// detector".
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "pfap/phoneme_table.h"
#include "viseme_features.h"

namespace pfap::align {

// The detector's phonemes are of pfap::kOculusVisemeAlphabet: symbol k is Oculus viseme k,
// which is MPEG-4 viseme k (docs/visemes.md).
inline constexpr size_t kVisemeCount = 15;

// The model's context: frames after the one it decides (fixed: the lookahead), and at most
// how many before (the model file says how many).
inline constexpr size_t kVisemeAheadFrames = 4;
inline constexpr size_t kMaxVisemePastFrames = 100;
// Smoothing: each frame's probabilities averaged with its neighbours' kSmoothFrames either
// side; the viseme shown changes when another's averaged probability beats it by a margin,
// and not before it has been shown a number of frames (docs/align.md).
inline constexpr size_t kSmoothFrames = 1;
struct VisemeSmoothing {
  float switch_margin = 0.1f;
  size_t min_run_frames = 2;
};
// The audio after a frame's end needed to settle it: the window's 17.5 ms past its frame's
// start less the frame, the frames ahead of the model and of the smoothing, and the
// resampler's filter (at most 2.25 ms, at 8 kHz).
inline constexpr double kVisemeLookaheadMs =
    (kVisemeWindow - kVisemeWindowLead - kVisemeHop) * 1000.0 / kVisemeRate +
    (kVisemeAheadFrames + kSmoothFrames) * 10.0 + 2.25;
static_assert(kVisemeLookaheadMs <= 60, "the detector looks at most 60 ms ahead");

// Live (pfapalign live=true recognizer=visemes): runs go out in pieces of at most
// kLiveVisemeRunFrames frames, so that a frame goes out once its piece's frames and the
// lookahead have come: at most kLiveVisemeBoundMs after its start (a run is given out when
// the next one's first frame is decided, or when it is a piece long). Smaller pieces: less
// latency, more phonemes (at 3, 33 a second through a long pause). The latency pfapalign
// declares adds kVisemeWorkMs for the work before the push (about 0.1 ms a 20 ms block,
// docs/align.md) on a loaded machine, rounded up to a ms.
inline constexpr size_t kLiveVisemeRunFrames = 3;
inline constexpr double kLiveVisemeBoundMs = kLiveVisemeRunFrames * 10.0 + kVisemeLookaheadMs;
inline constexpr double kVisemeWorkMs = 5;
inline constexpr unsigned kLiveVisemeLatencyMs =
    static_cast<unsigned>(kLiveVisemeBoundMs + kVisemeWorkMs + 0.999);
static_assert(kLiveVisemeLatencyMs <= 100, "lips within 100 ms (issue 30)");

// A run of frames showing one viseme: frames [start, start + frames), 10 ms each from the
// stream's first sample.
struct VisemeRun {
  uint64_t start = 0;
  uint32_t frames = 0;
  Viseme viseme = Viseme::kNone;
};

// The network's weights (a multilayer perceptron: kVisemeMfccs x the context's frames in, two
// hidden layers with ReLU, kVisemeCount out), read from the text of align/viseme_model.txt.
class VisemeModel {
 public:
  // The model built into the library (align/viseme_model.txt at build time).
  static const VisemeModel& builtin();
  // The model of `numbers` (the file's numbers in order); nullptr if they do not make one.
  static std::unique_ptr<VisemeModel> from_numbers(std::span<const float> numbers);

  // Each viseme's probability for the frame of `context` (past_frames() + 1 +
  // kVisemeAheadFrames frames of kVisemeMfccs, oldest first), into `out` (kVisemeCount).
  void probabilities(std::span<const float> context, std::span<float> out) const;
  size_t past_frames() const { return past_; }
  // The network's inputs: kVisemeMfccs a frame of the context.
  size_t inputs() const { return (past_ + 1 + kVisemeAheadFrames) * kVisemeMfccs; }
  size_t weights() const { return params_.size(); }
  // The training set's mean of c1..c12 over frames of sound: where CepstralMean starts.
  std::span<const float> cepstral_prior() const {
    return std::span(params_).subspan(2 * kVisemeMfccs, kVisemeMfccs - 1);
  }

 private:
  size_t past_ = 0, hidden1_ = 0, hidden2_ = 0;
  std::vector<float> params_;  // mean, scale, cepstral prior, then W1 b1 W2 b2 W3 b3, row-major
};

class VisemeDetector {
 public:
  // Audio at `rate` (kMinVisemeInputRate..kMaxVisemeInputRate; outside, the nearest). Runs
  // longer than `max_run_frames` (0: no limit) are given out in pieces of that many frames,
  // so that a long pause or vowel still goes out within that bound.
  explicit VisemeDetector(unsigned rate, size_t max_run_frames = 0,
                          VisemeSmoothing smoothing = {},
                          const VisemeModel& model = VisemeModel::builtin());

  // Appends the runs the new audio settles to `out`, in order, each frame once.
  void push(std::span<const int16_t> samples, std::vector<VisemeRun>& out);
  void push(std::span<const float> samples, std::vector<VisemeRun>& out);  // -1..1
  // The stream ends: the rest, up to the frame holding the last sample.
  void finish(std::vector<VisemeRun>& out);

  // Frames settled so far (given out in runs or in the run still open).
  uint64_t frames() const { return decided_; }
  // If set, each frame's probabilities (kVisemeCount floats) before smoothing are appended.
  void trace(std::vector<float>* probabilities) { trace_ = probabilities; }

 private:
  void take_frames(std::vector<VisemeRun>& out);
  void classify(std::vector<VisemeRun>& out);
  void decide(std::vector<VisemeRun>& out);

  const VisemeModel& model_;
  size_t max_run_frames_;
  VisemeSmoothing smoothing_;
  Resampler resampler_;
  MfccFrames mfcc_;
  CepstralMean cepstral_mean_;
  std::vector<float> resampled_, coefficients_;
  std::vector<float> context_;  // the last frames' coefficients, oldest first
  uint64_t classified_ = 0;     // frames whose probabilities are known
  std::vector<float> probs_;    // the last 2 * kSmoothFrames + 1 frames' probabilities
  uint64_t decided_ = 0;
  std::vector<float>* trace_ = nullptr;
  Viseme shown_ = Viseme::kNone;
  VisemeRun open_;   // the run being shown (a piece of it, with max_run_frames)
  size_t held_ = 0;  // frames shown_ has been shown
};

}  // namespace pfap::align
