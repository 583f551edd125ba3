// SPDX-License-Identifier: LGPL-2.1-or-later
// Phonemes from the audio alone, without its text: pocketsphinx's all-phone search (its US
// English acoustic model and phone language model) finds the most likely phone sequence, and
// each phone becomes an x-pfap-arpabet phoneme on the recording's timeline. Good enough for a
// mouth, which shows visemes; the measured viseme agreement is in docs/align.md. Built only
// with the `recognition` meson feature (pocketsphinx); the CMU phone mapping always is.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "speech.h"

namespace pfap::align {

// The x-pfap-arpabet symbol of a pocketsphinx CMU phone ("AA" .. "ZH"): the same names, as
// x-pfap-arpabet is the CMU dictionary's phone set. SIL and the fillers (+NSN+, +SPN+, ...,
// breath and noise) are 0, a pause: the mouth rests.
uint8_t arpabet_symbol(std::string_view cmu_phone);

// Why a recognition is only a pause; each a warning for the user.
enum class RecognitionProblem {
  kNone,
  kNoSpeech,      // the audio is all below kSpeechLevelDb (aligner.h): one pause
  kBadRate,       // the rate is outside kMinRate..kMaxRate (mfcc.h): one pause
  kNothingHeard,  // audible, but no phone was recognized (noise, music): one pause
};

const char* problem_text(RecognitionProblem p);

struct Recognition {
  // Phonemes contiguous from sample 0 to the audio's end, as align::Alignment's: starts in
  // samples, duration_ms on the ms grid; f0 measured on the recording; no stress, and a word
  // begins only after a pause (the recognizer knows no words).
  std::vector<tts::SpokenPhoneme> phonemes;
  RecognitionProblem problem = RecognitionProblem::kNone;
};

// Whether this build has the recognizer (pocketsphinx found at build time).
bool recognition_available();

// Recognizes `audio` (mono, `rate` Hz, kMinRate..kMaxRate: the acoustic front end takes the
// rate as it is, over the model's 130..6800 Hz band). False with `error`, and `out` one pause,
// when the model cannot be loaded or the build has no recognizer; every audio input gives
// phonemes, with `problem` saying what was wrong. Thread-safe: one pocketsphinx decoder per
// sample rate serves the whole process, made at the first audio of that rate and kept (the
// model loads in 0.3 s, and pocketsphinx 5prealpha leaks part of each decoder it frees); two
// threads recognizing at one rate take turns.
bool recognize(std::span<const int16_t> audio, unsigned rate, Recognition& out, std::string& error);

}  // namespace pfap::align
