// SPDX-License-Identifier: LGPL-2.1-or-later
// Alignment of one utterance while its audio arrives, for live sources: the text is spoken by
// espeak-ng once, its phoneme starts put in phonetic convention as align() puts them, and each
// time more audio has come, dynamic time warping with an open end matches the audio since the
// last settled boundary to the synthetic speech that follows it, a pause allowed between
// words; boundaries next to a pause move onto the recording's edge of silence as in align().
// A boundary is settled once kLookahead of audio follows it (the first sound's start once
// kLookahead + kHold does: whether a hum starts there shows in the speech after it). The pause
// before the first sound is given out up to that start and no further, and before the warp has
// placed it, up to where the first edge into sound would start it (a weak onset, which the warp
// places late), for kHold at most. A phoneme still going on kLookahead + kHold before the newest
// audio is sent in pieces.
// So every phoneme (or piece) is given out by the time kLookahead + kHold + kStep and one block
// of push() more audio than its start has come.
// The method, its bound and its measured accuracy: docs/align.md, "Live".
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "aligner.h"  // Problem
#include "boundaries.h"
#include "mfcc.h"
#include "speech.h"
#include "utterance.h"

namespace pfap::align {

// In ms. The audio after a boundary that the warp sees before the boundary is settled; it
// holds the audio snap_to_silence() looks at after a boundary, so that a boundary is refined
// as align() refines it before it is settled.
inline constexpr unsigned kLookaheadMs = 200;
static_assert(kLookaheadMs >= kSnapRadiusMs + kMinSilenceMs);
// How long a phoneme still going on may wait past the settled point before a piece is sent.
inline constexpr unsigned kHoldMs = 100;
// The warp runs again once this much new audio has come.
inline constexpr unsigned kStepMs = 50;
// What the element declares in the LATENCY query, beside upstream's (which counts the block:
// a live source's latency is at least its buffer's duration): the bound above, plus 50 ms for
// the work itself (a few ms a step, docs/align.md) and for a loaded machine.
inline constexpr unsigned kLiveLatencyMs = kLookaheadMs + kHoldMs + kStepMs + 50;

class LiveAligner {
 public:
  // Speaks `utterance` and waits for its audio (mono, `rate` Hz). False with `error` only when
  // espeak-ng cannot speak; problem() says when the text or rate cannot be aligned (the audio
  // is then one pause, sent in pieces as it comes).
  bool start(const tts::Utterance& utterance, const tts::VoiceSettings& voice, unsigned rate,
             std::string& error);

  // Takes the utterance's next samples; appends to `out` the phonemes (and pieces of a phoneme
  // still going on) that are now settled, each from the utterance's first sample, contiguous
  // with those given before.
  void push(std::span<const int16_t> samples, std::vector<tts::SpokenPhoneme>& out);

  // The utterance's audio has ended: appends every phoneme left, the last ending at the last
  // sample (those the audio had no time for: squeezed in at its end).
  void finish(std::vector<tts::SpokenPhoneme>& out);

  Problem problem() const { return problem_; }
  const std::vector<tts::Speech::Inexact>& inexact() const { return syn_.inexact; }
  size_t samples() const { return rec_first_ + rec_.size(); }  // pushed so far
  size_t settled() const { return rec_settled_; }              // given out so far

 private:
  void step(bool at_end, std::vector<tts::SpokenPhoneme>& out);
  // mfcc()'s frames of the audio from sample w0 to the newest, the MFCCs normalized over them
  // (the level dimension is step()'s), each frame's analysis done once (frames_).
  Features features_from(size_t w0);
  // Phoneme k's start `at` (a sample of the utterance) moved as align() moves it next to a
  // pause (snap_to_silence), on the audio kept.
  size_t snap(size_t k, size_t at) const;
  // Gives out phoneme `next_` (or the rest of it) over [rec_settled_, to).
  void emit(size_t to, bool whole, std::vector<tts::SpokenPhoneme>& out);

  unsigned rate_ = 0;
  Problem problem_ = Problem::kNone;
  tts::Speech syn_;  // padded with pauses at its ends, as align() does
  Features synf_;
  std::vector<bool> rest_;    // per frame of synf_: a pause may be matched here (open_warp)
  std::vector<int16_t> rec_;  // the utterance's audio from sample rec_first_ (what is needed)
  size_t rec_first_ = 0;
  // The frames that features_from() computed, from sample frames_first_ a hop apart, each its
  // MFCCs as FrameAnalyzer gives them and its level (Features::kDims values).
  std::unique_ptr<FrameAnalyzer> analyzer_;
  std::vector<float> frames_;
  size_t frames_first_ = 0;
  float loudest_db_ = -100;    // the utterance's loudest frame so far
  size_t rec_settled_ = 0;     // samples of the utterance given out
  size_t syn_settled_ = 0;     // the sample of syn_ matched with rec_settled_
  size_t next_ = 0;            // the phoneme of syn_ going on at rec_settled_
  bool next_started_ = false;  // a piece of it has been given out
  size_t last_step_ = 0;       // samples() at the last step
};

}  // namespace pfap::align
