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

#include "live.h"  // kLookaheadMs, kHoldMs, kStepMs: the live bound, one for both modes
#include "mfcc.h"
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

// pocketsphinx keeps every frame of an utterance (its features, for the mean over the
// utterance, and the search's history): 4.7 MB per second of audio, 2.9 GB for 600 s of noise.
// recognize() therefore decodes audio longer than kMaxWindowSeconds in windows, each cut at the
// quietest 5 ms frame between kMinWindowSeconds and kMaxWindowSeconds after its start (a pause
// where there is one); its memory is that of one window (docs/security.md).
inline constexpr double kMinWindowSeconds = 10;
inline constexpr double kMaxWindowSeconds = 20;

// Where recognize() cuts audio whose frames' levels are `level` (mfcc()'s, over the audio):
// each window's first sample, the first 0.
std::vector<size_t> recognition_windows(const Features& level, size_t n_samples);

// Recognizes `audio` (mono, `rate` Hz, kMinRate..kMaxRate: the acoustic front end takes the
// rate as it is, over the model's 130..6800 Hz band). False with `error`, and `out` one pause,
// when the model cannot be loaded or the build has no recognizer; every audio input gives
// phonemes, with `problem` saying what was wrong. Thread-safe: one pocketsphinx decoder per
// sample rate serves the whole process, made at the first audio of that rate and kept (the
// model loads in 0.3 s, and pocketsphinx 5prealpha leaks part of each decoder it frees); two
// threads recognizing at one rate take turns.
bool recognize(std::span<const int16_t> audio, unsigned rate, Recognition& out, std::string& error);

struct LiveDecoder;  // a pocketsphinx decoder of the live pool (recognizer.cc)

// Recognition as the audio comes, for live sources (pfapalign live=true without a text): the
// audio goes to pocketsphinx as it arrives, and after every kStepMs of it the best path so far
// is traced back; a phone is settled, and given out, once it ends at least kLookaheadMs before
// the newest audio, and a phone still going on kLookaheadMs + kHoldMs before it is given out
// in pieces, as LiveAligner does: the same bound. pocketsphinx's utterance restarts at a
// pause once it is kRestartMs long (its history grows with it). docs/align.md, "Live without
// the text".
class LiveRecognizer;

// What pfapalign declares in the LATENCY query when it recognizes live: the bound, as with a
// text (kLiveLatencyMs), and 300 ms more for the search's own work, which takes a quarter of
// real time in bursts (a step's traceback, an utterance's restart): phonemes came up to 577 ms
// after their start by the clock on a lightly loaded machine (docs/align.md).
inline constexpr unsigned kLiveRecognitionLatencyMs = kLiveLatencyMs + 300;

class LiveRecognizer {
 public:
  LiveRecognizer() = default;
  LiveRecognizer(const LiveRecognizer&) = delete;
  LiveRecognizer& operator=(const LiveRecognizer&) = delete;
  ~LiveRecognizer();

  // Starts recognizing audio (mono, `rate` Hz). False with `error` when the model cannot be
  // loaded or the build has no recognizer; a rate outside kMinRate..kMaxRate is problem()
  // kBadRate at once, and the audio one pause, in pieces as it comes.
  bool start(unsigned rate, std::string& error);

  // Takes the next samples; appends to `out` the phonemes (or pieces) now settled, starts
  // counted from the first sample, contiguous with those given before.
  void push(std::span<const int16_t> samples, std::vector<tts::SpokenPhoneme>& out);

  // The audio has ended: appends every phoneme left, the last ending at the last sample (end
  // of text on it); problem() then also says when nothing was heard.
  void finish(std::vector<tts::SpokenPhoneme>& out);

  RecognitionProblem problem() const { return problem_; }
  size_t samples() const { return first_ + audio_.size(); }  // pushed so far
  size_t settled() const { return settled_; }                // given out so far

 private:
  // A phone of the best path, in samples from the first pushed.
  struct Segment {
    uint8_t symbol;
    size_t start, end;
  };
  std::vector<Segment> best_path() const;
  void release();  // gives the decoder back
  void step(bool at_end, std::vector<tts::SpokenPhoneme>& out);
  // Ends pocketsphinx's utterance and gives out its final path to the newest sample; starts
  // the next unless `at_end`.
  void end_utterance(bool at_end, std::vector<tts::SpokenPhoneme>& out);
  // Gives out `symbol` over [settled_, to); `whole` ends the phoneme, else it is a piece.
  void emit(uint8_t symbol, size_t to, bool whole, bool end_of_text,
            std::vector<tts::SpokenPhoneme>& out);

  unsigned rate_ = 0;
  RecognitionProblem problem_ = RecognitionProblem::kNone;
  LiveDecoder* decoder_ = nullptr;
  bool in_utterance_ = false;   // pocketsphinx's
  std::vector<int16_t> audio_;  // from sample first_: what f0 of the pieces to come needs
  size_t first_ = 0;            // the sample audio_ starts at
  size_t utterance_from_ = 0;   // pocketsphinx's utterance's first sample
  size_t settled_ = 0;
  size_t last_step_ = 0;
  float loudest_db_ = -100;
  uint8_t last_symbol_ = 0;  // of the phoneme given out last
  bool piece_open_ = false;  // that phoneme was a piece: its rest continues it
  bool any_speech_ = false;  // a phone other than a pause was given out
  bool any_out_ = false;
};

}  // namespace pfap::align
