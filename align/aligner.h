// SPDX-License-Identifier: LGPL-2.1-or-later
// Forced alignment of a text to a recording of it: the text is spoken by espeak-ng (tts/,
// with its phonemes' times, stress, word starts and bookmarks), both are turned into MFCC
// frames, dynamic time warping matches the frames, and each synthetic phoneme boundary (in
// phonetic convention, boundaries.h) is moved to the recording's time it matches, those next
// to a pause onto the recording's edge of silence. f0 is measured on the recording. The
// method and its measured accuracy: docs/align.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "espeak.h"
#include "mfcc.h"  // kMinRate, kMaxRate: the rates align() takes
#include "speech.h"
#include "utterance.h"

namespace pfap::align {

// Why an alignment is only a pause or may be wrong; each a warning for the user.
enum class Problem {
  kNone,
  kEmptyText,    // no phonemes to align: one pause over the audio
  kNoSpeech,     // the audio is all below kSpeechLevelDb: one pause, bookmarks on it
  kBadRate,      // the rate is outside kMinRate..kMaxRate: one pause, bookmarks on it
  kTextTooLong,  // more text than max_text_characters(): one pause, bookmarks on it, the text
                 // not spoken
  kPoorMatch,    // aligned, but the audio matches the text poorly: the recognizer hears other
                 // visemes than the aligned ones, relative_cost very high, or the speech much
                 // longer or shorter than the text's spoken by espeak-ng
};

const char* problem_text(Problem p);

inline constexpr float kSpeechLevelDb = -50;  // a frame this loud or louder may be speech
// When the text matches its audio (docs/align.md, "Bad input": both statistics measured on
// right and shuffled texts). Below kSureMatchCost the warp's relative cost says it does; from
// there, where the build has the recognizer (recognizer.h), the audio matches poorly when the
// share of 10 ms frames on which the aligned phonemes show the viseme the recognizer hears is
// below kPoorHeardAgreement; and whatever the recognizer, from kPoorMatchCost.
inline constexpr double kSureMatchCost = 0.72;
inline constexpr double kPoorHeardAgreement = 0.44;
inline constexpr double kPoorMatchCost = 0.97;
inline constexpr double kMaxSpeechRatio = 2.5;  // recording's speech over espeak-ng's, or back

// The most audio one alignment takes, in seconds: pfapalign keeps no more of a stream, and a
// live utterance's text is bounded as for this much audio.
inline constexpr unsigned kMaxAudioSeconds = 600;
// The most text (code points, bookmarks left out) that `seconds` of audio can hold:
// kMaxCharactersPerSecond, about three times fast speech (the Festival corpus speaks 14 a
// second), and kTextSlackCharacters for short audio. espeak-ng's work and memory grow with the
// text, whatever the audio (a 1 MB text took 7.7 GB for 1.9 s of audio): a longer text is
// refused before it is spoken (docs/security.md).
inline constexpr double kMaxCharactersPerSecond = 40;
inline constexpr size_t kTextSlackCharacters = 200;
size_t max_text_characters(double seconds);

struct Alignment {
  // Phonemes on the recording: contiguous from sample 0 to the audio's end; starts in
  // samples of the recording, duration_ms on its ms grid as tts::speak gives them.
  std::vector<tts::SpokenPhoneme> phonemes;
  Problem problem = Problem::kNone;
  double relative_cost = 0;  // dtw.h; 0 when nothing was aligned
  // The share of frames on which the recognizer hears the aligned phonemes' visemes; -1 when
  // not measured (relative_cost below kSureMatchCost, or no recognizer).
  double heard_agreement = -1;
  // espeak-ng's mnemonics with no exact x-pfap-arpabet symbol, as tts::Speech gives them.
  std::vector<tts::Speech::Inexact> inexact;
};

// A pause carrying every bookmark's FAPs, sentence start and end of text: what stands for an
// utterance that cannot be aligned.
MarkupEvent pause_event(const tts::Utterance& utterance);

// Aligns `utterance` to `audio` (mono, `rate` Hz). False with `error` only when espeak-ng
// cannot speak (no such voice); every other input gives phonemes, with `problem` saying what
// was wrong. The voice should speak the recording's language; its rate and pitch matter little.
bool align(const tts::Utterance& utterance, const tts::VoiceSettings& voice,
           std::span<const int16_t> audio, unsigned rate, Alignment& out, std::string& error);

}  // namespace pfap::align
