// SPDX-License-Identifier: LGPL-2.1-or-later
#include "espeak.h"

#include <espeak-ng/speak_lib.h>

#include <algorithm>
#include <cstring>
#include <mutex>

namespace pfap::tts {
namespace {

std::mutex espeak_mutex;
bool initialized = false;
int espeak_rate = 0;  // espeak_Initialize's answer; <= 0 when it failed

// The call in progress, under espeak_mutex.
struct Call {
  Synthesis* out = nullptr;
  size_t sentences = 0;  // sentence events so far
  const std::atomic<bool>* cancel = nullptr;
};
Call current;

size_t sentence_now() { return current.sentences > 0 ? current.sentences - 1 : 0; }

// espeak-ng hands over audio and the events up to it, in order.
int on_synth(short* wav, int n_samples, espeak_EVENT* events) {
  Synthesis& s = *current.out;
  for (espeak_EVENT* e = events; e != nullptr && e->type != espeakEVENT_LIST_TERMINATED; ++e) {
    switch (e->type) {
      case espeakEVENT_SAMPLERATE:
        s.sample_rate = static_cast<unsigned>(e->id.number);
        break;
      case espeakEVENT_SENTENCE:
        ++current.sentences;
        break;
      case espeakEVENT_WORD:
        // text_position counts code points from 1.
        s.words.push_back({static_cast<size_t>(std::max(e->text_position - 1, 0)), sentence_now(),
                           s.phonemes.size(), s.phonemes.size()});
        break;
      case espeakEVENT_PHONEME:
        s.phonemes.push_back({std::string(e->id.string, strnlen(e->id.string, sizeof e->id.string)),
                              static_cast<size_t>(std::max(e->sample, 0)), sentence_now()});
        break;
      default:
        break;
    }
  }
  if (wav != nullptr && n_samples > 0) s.samples.insert(s.samples.end(), wav, wav + n_samples);
  // Non-zero stops the synthesis.
  return current.cancel != nullptr && current.cancel->load() ? 1 : 0;
}

// A word's phonemes run to the next word's, without the pauses that end a clause.
void close_words(Synthesis& s) {
  for (size_t i = 0; i < s.words.size(); ++i) {
    Synthesis::Word& w = s.words[i];
    size_t end = i + 1 < s.words.size() ? s.words[i + 1].first_phoneme : s.phonemes.size();
    while (end > w.first_phoneme && s.phonemes[end - 1].mnemonic.starts_with('_')) --end;
    w.end_phoneme = end;
  }
}

bool set_voice(const VoiceSettings& settings, std::string& error) {
  if (espeak_SetVoiceByName(settings.voice.c_str()) != EE_OK) {
    error = "espeak-ng has no voice \"" + settings.voice + "\"";
    return false;
  }
  espeak_SetParameter(espeakRATE, settings.rate, 0);
  espeak_SetParameter(espeakPITCH, settings.pitch, 0);
  espeak_SetParameter(espeakVOLUME, settings.volume, 0);
  return true;
}

// Under espeak_mutex.
bool start(std::string& error) {
  if (!initialized) {
    initialized = true;
    espeak_rate = espeak_Initialize(AUDIO_OUTPUT_SYNCHRONOUS, 0, nullptr,
                                    espeakINITIALIZE_PHONEME_EVENTS | espeakINITIALIZE_DONT_EXIT);
    if (espeak_rate > 0) espeak_SetSynthCallback(on_synth);
  }
  if (espeak_rate <= 0) {
    error = "espeak-ng could not start (its data not installed?)";
    return false;
  }
  return true;
}

}  // namespace

bool check_voice(const VoiceSettings& settings, unsigned& sample_rate, std::string& error) {
  std::lock_guard lock(espeak_mutex);
  if (!start(error) || !set_voice(settings, error)) return false;
  sample_rate = static_cast<unsigned>(espeak_rate);
  return true;
}

bool synthesize(std::string_view text, const VoiceSettings& settings, Synthesis& out,
                std::string& error, const std::atomic<bool>* cancel) {
  std::lock_guard lock(espeak_mutex);
  if (!start(error) || !set_voice(settings, error)) return false;
  out = Synthesis{};
  out.sample_rate = static_cast<unsigned>(espeak_rate);  // until its event says otherwise
  const std::string input(text);

  // The stressed transcription, clause by clause, as espeak-ng -x prints it.
  const void* clause = input.c_str();
  while (clause != nullptr) {
    const char* phonemes = espeak_TextToPhonemes(&clause, espeakCHARS_UTF8, 0);
    if (phonemes == nullptr) break;
    if (!out.transcription.empty()) out.transcription += ' ';
    out.transcription += phonemes;
  }

  current = {&out, 0, cancel};
  const espeak_ERROR result = espeak_Synth(input.c_str(), input.size() + 1, 0, POS_CHARACTER, 0,
                                           espeakCHARS_UTF8, nullptr, nullptr);
  current = {};
  if (result != EE_OK) {
    error = "espeak-ng could not speak the text (error " + std::to_string(result) + ")";
    return false;
  }
  close_words(out);
  return true;
}

}  // namespace pfap::tts
