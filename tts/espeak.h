// SPDX-License-Identifier: LGPL-2.1-or-later
// espeak-ng 1.51 as a function: text in, audio and its events out. espeak-ng is one
// process-wide synthesizer that is not reentrant and keeps state from one synthesis to the
// next that no call resets, so it runs in a helper program, pfap-espeak, installed beside
// libpfaptts and started by the first call of a process: each call is spoken by a child of it
// whose espeak-ng has started and never spoken, so the same text and settings give the same
// audio and events whatever was spoken before (espeak.cc and pfap-espeak.cc say why).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pfap::tts {

struct VoiceSettings {
  std::string voice = "en";  // an espeak-ng voice name, e.g. "en", "en-us", "de"
  int rate = 175;            // words per minute, 80..450
  int pitch = 50;            // 0..100
  int volume = 100;          // 0..200
};

struct Synthesis {
  unsigned sample_rate = 0;      // from espeak-ng's sample rate event
  std::vector<int16_t> samples;  // mono

  struct Phoneme {
    std::string mnemonic;  // espeak-ng's name, as in its -x transcription
    size_t sample = 0;     // where it starts in `samples`
    size_t sentence = 0;   // counted from 0
  };
  std::vector<Phoneme> phonemes;

  struct Word {
    size_t start = 0;  // code point of the text, from 0
    size_t sentence = 0;
    size_t first_phoneme = 0;  // index of its first phoneme; == end_phoneme when it has none
    size_t end_phoneme = 0;
  };
  std::vector<Word> words;

  std::string transcription;  // espeak_TextToPhonemes, with stress marks
};

// Whether espeak-ng starts and has the voice; `sample_rate` is the rate espeak-ng starts with
// (a synthesis reports its own, which is the one to use).
bool check_voice(const VoiceSettings& settings, unsigned& sample_rate, std::string& error);

// Speaks plain UTF-8 `text` (no SSML). False with `error` set when pfap-espeak or espeak-ng
// cannot start, has no such voice or dies, or when `text` is longer than one request to
// pfap-espeak holds (about 128 KiB). When `*cancel` becomes true, espeak-ng is stopped within
// 10 ms and `out` is empty.
bool synthesize(std::string_view text, const VoiceSettings& settings, Synthesis& out,
                std::string& error, const std::atomic<bool>* cancel = nullptr);

}  // namespace pfap::tts
