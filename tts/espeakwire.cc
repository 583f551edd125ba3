// SPDX-License-Identifier: LGPL-2.1-or-later
#include "espeakwire.h"

namespace pfap::tts::wire {

void Reader::get(std::string& text) {
  uint64_t n = 0;
  get(n);
  if (!whole || rest.size() < n) {
    whole = false;
    return;
  }
  text.assign(rest.substr(0, n));
  rest.remove_prefix(n);
}

void put(Writer& w, const VoiceSettings& settings) {
  w.put(settings.voice);
  w.put(settings.rate);
  w.put(settings.pitch);
  w.put(settings.volume);
}

void get(Reader& r, VoiceSettings& settings) {
  r.get(settings.voice);
  r.get(settings.rate);
  r.get(settings.pitch);
  r.get(settings.volume);
}

void put(Writer& w, const Synthesis& s) {
  w.put(s.sample_rate);
  w.put(std::string_view(reinterpret_cast<const char*>(s.samples.data()),
                         s.samples.size() * sizeof(int16_t)));
  w.put(uint64_t{s.phonemes.size()});
  for (const Synthesis::Phoneme& p : s.phonemes) {
    w.put(p.mnemonic);
    w.put(p.sample);
    w.put(p.sentence);
  }
  w.put(uint64_t{s.words.size()});
  for (const Synthesis::Word& word : s.words) w.put(word);
  w.put(s.transcription);
}

void get(Reader& r, Synthesis& s) {
  r.get(s.sample_rate);
  std::string samples;
  r.get(samples);
  s.samples.resize(samples.size() / sizeof(int16_t));
  std::memcpy(s.samples.data(), samples.data(), s.samples.size() * sizeof(int16_t));
  uint64_t n = 0;
  r.get(n);
  for (uint64_t i = 0; i < n && r.whole; ++i) {
    Synthesis::Phoneme p;
    r.get(p.mnemonic);
    r.get(p.sample);
    r.get(p.sentence);
    s.phonemes.push_back(std::move(p));
  }
  r.get(n);
  for (uint64_t i = 0; i < n && r.whole; ++i) {
    Synthesis::Word word;
    r.get(word);
    s.words.push_back(word);
  }
  r.get(s.transcription);
}

}  // namespace pfap::tts::wire
