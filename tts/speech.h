// SPDX-License-Identifier: LGPL-2.1-or-later
// An utterance spoken: the audio and its phonemes as x-pfap events (x-pfap-arpabet symbols),
// each with the FAPs of the bookmarks that start with it. The whole of tts/ put together.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "espeak.h"
#include "pfap/markup_event.h"
#include "utterance.h"

namespace pfap::tts {

struct SpokenPhoneme {
  MarkupEvent event;     // a phoneme event; duration_ms on the utterance's ms grid
  size_t start = 0;      // first sample
  size_t n_samples = 0;  // its length in samples (a split phoneme: this piece's)
};

struct Speech {
  unsigned sample_rate = 0;
  std::vector<int16_t> samples;
  // Contiguous from sample 0 to the end of `samples`, in order.
  std::vector<SpokenPhoneme> phonemes;
  // Each mnemonic with no exact x-pfap-arpabet symbol (found by its base, or else a pause),
  // once, with the symbol's name it was sent as.
  struct Inexact {
    std::string mnemonic;
    std::string_view sent_as;
  };
  std::vector<Inexact> inexact;
};

// Appends the phoneme `event` that lasts samples [start, end) of an utterance at `rate`, with
// its duration_ms on the utterance's ms grid (below); longer than 4095 ms, as the pieces of
// pfap::split_long_phoneme, the FAPs and sentence start on the first.
void add_phoneme(const MarkupEvent& event, size_t start, size_t end, unsigned rate,
                 std::vector<SpokenPhoneme>& out);

// Speaks `utterance`. False with `error` when espeak-ng cannot (no such voice).
//  - A phoneme lasts from its start to the next one's; the last to the end of the audio. The
//    audio before espeak-ng's first phoneme (about 12 ms) is a pause; phonemes of no samples
//    are left out.
//  - Word begin: the first phoneme of each word. Stress: the primary stress mark of the
//    transcription. Sentence start and end of text: the first and last phoneme of each
//    sentence espeak-ng reports.
//  - f0: segment_f0 over each phoneme, as pfap::f0_code.
//  - Bookmarks: place_bookmark; with no word, the first phoneme; an utterance with no
//    phonemes gets one pause of 0 ms for them.
//  - duration_ms: the phoneme's start and end rounded to whole ms from the utterance's start,
//    subtracted, so that the durations add up to the audio's length and a receiver that adds
//    them up stays within 0.5 ms of every start. Longer than 4095 ms: split.
// With `cancel`: when `*cancel` becomes true, returns within a few ms (espeak-ng and the f0
// stop), `out` then incomplete, for the caller to drop.
bool speak(const Utterance& utterance, const VoiceSettings& settings, Speech& out,
           std::string& error, const std::atomic<bool>* cancel = nullptr);

}  // namespace pfap::tts
