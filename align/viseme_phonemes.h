// SPDX-License-Identifier: LGPL-2.1-or-later
// pfapalign recognizer=visemes: the viseme detector's runs (viseme_detector.h) as PFAP
// phonemes of pfap::kOculusVisemeAlphabet over the audio's samples, offline and live.
// docs/align.md, "The viseme detector in pfapalign".
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "speech.h"
#include "viseme_detector.h"

namespace pfap::align {

// Whether the detector takes audio at `rate` (kMinVisemeInputRate..kMaxVisemeInputRate).
bool visemes_take_rate(unsigned rate);

class VisemePhonemes {
 public:
  // Audio at `rate`; runs longer than `max_run_frames` (0: no limit) in pieces of that many
  // frames (kLiveVisemeRunFrames live). At a rate the detector does not take, the audio is
  // a pause, given out as it comes.
  VisemePhonemes(unsigned rate, size_t max_run_frames);

  // Takes the next samples; appends to `out` the phonemes now settled, contiguous from
  // sample 0: symbol k is viseme k, no stress or f0, a word begins where a viseme follows a
  // pause.
  void push(std::span<const int16_t> samples, std::vector<tts::SpokenPhoneme>& out);
  // The audio has ended: the rest, the last phoneme ending at the last sample.
  void finish(std::vector<tts::SpokenPhoneme>& out);

 private:
  void add(std::span<const VisemeRun> runs, bool at_end, std::vector<tts::SpokenPhoneme>& out);
  void add_phoneme(Viseme viseme, size_t end, std::vector<tts::SpokenPhoneme>& out);

  unsigned rate_;
  std::optional<VisemeDetector> detector_;  // none at a rate it does not take
  std::vector<VisemeRun> runs_;
  size_t samples_ = 0;  // pushed so far
  size_t given_ = 0;    // samples given out in phonemes
  Viseme last_ = Viseme::kNone;
};

}  // namespace pfap::align
