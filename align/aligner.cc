// SPDX-License-Identifier: LGPL-2.1-or-later
#include "aligner.h"

#include <algorithm>
#include <cmath>

#include "boundaries.h"
#include "dtw.h"
#include "f0.h"
#include "mfcc.h"
#include "recognizer.h"
#include "viseme_frames.h"

namespace pfap::align {
namespace {

// The whole audio as one pause carrying every bookmark's FAPs.
void pause_over(const tts::Utterance& utterance, size_t n_samples, unsigned rate, Alignment& out) {
  tts::add_phoneme(pause_event(utterance), 0, n_samples, rate, out.phonemes);
}

// Where the synthetic boundary at `sample` falls in the recording, by the warp between the
// frames either side of it.
double map_boundary(size_t sample, const Features& syn, const Features& rec, const Warp& w) {
  const double centre0 = static_cast<double>(syn.centre(0));
  const double pos = (static_cast<double>(sample) - centre0) / static_cast<double>(syn.hop);
  const double scale = static_cast<double>(rec.rate) / syn.rate;
  if (pos <= 0) return static_cast<double>(sample) * scale;
  const size_t i = static_cast<size_t>(std::ceil(pos));
  if (i >= syn.n_frames) {
    return static_cast<double>(rec.centre(w.last.back())) +
           (static_cast<double>(sample) - static_cast<double>(syn.centre(syn.n_frames - 1))) *
               scale;
  }
  const double t = pos - static_cast<double>(i - 1);  // 0..1 between the two centres
  const double from = static_cast<double>(rec.centre(w.last[i - 1]));
  const double to = static_cast<double>(rec.centre(w.first[i]));
  return from + t * (to - from);
}

// How long `f` has speech: its frames within 30 dB of the loudest, in seconds.
double speech_seconds(const Features& f) {
  const float loudest = *std::max_element(f.level_db.begin(), f.level_db.end());
  const auto n = std::count_if(f.level_db.begin(), f.level_db.end(),
                               [&](float db) { return db > loudest - 30; });
  return static_cast<double>(n) * static_cast<double>(f.hop) / f.rate;
}

}  // namespace

MarkupEvent pause_event(const tts::Utterance& utterance) {
  MarkupEvent e;
  e.kind = PFAP_EVENT_PHONEME;
  e.sentence_start = true;
  e.phoneme.end_of_text = true;
  for (const tts::Bookmark& b : utterance.bookmarks) {
    e.faps.insert(e.faps.end(), b.faps.begin(), b.faps.end());
  }
  return e;
}

size_t max_text_characters(double seconds) {
  return kTextSlackCharacters +
         static_cast<size_t>(std::max(seconds, 0.0) * kMaxCharactersPerSecond);
}

const char* problem_text(Problem p) {
  switch (p) {
    case Problem::kNone:
      return "aligned";
    case Problem::kEmptyText:
      return "the text has nothing to speak: the audio is one pause";
    case Problem::kNoSpeech:
      return "the audio is silent: it is one pause";
    case Problem::kBadRate:
      return "the sample rate is outside 16000..48000 Hz: the audio is one pause";
    case Problem::kTextTooLong:
      return "the text is far longer than the audio can hold: the audio is one pause";
    case Problem::kPoorMatch:
      return "the audio matches the text poorly: the times may be wrong";
  }
  return "?";
}

namespace {

// The share of 10 ms frames on which `phonemes` show the viseme the recognizer hears in
// `audio`; -1 without a recognizer. The warp's cost alone does not tell a right text in another
// voice from a wrong one (docs/align.md, "Bad input"); what is heard does.
double heard_agreement(const std::vector<tts::SpokenPhoneme>& phonemes,
                       std::span<const int16_t> audio, unsigned rate) {
  Recognition heard;
  std::string error;
  if (!recognize(audio, rate, heard, error)) return -1;
  auto frames = [&](const std::vector<tts::SpokenPhoneme>& ps) {
    std::vector<TimedSymbol> timed;
    for (const tts::SpokenPhoneme& p : ps) {
      timed.push_back({static_cast<double>(p.start) / rate, p.event.phoneme.symbol});
    }
    return viseme_frames(timed, static_cast<double>(audio.size()) / rate);
  };
  return viseme_agreement(frames(phonemes), frames(heard.phonemes));
}

// A pause pad_with_pauses() put at an end that is shorter than kMinSilenceMs is no silence
// (snap_to_silence's rule): its samples go to the phoneme next to it, and end of text back
// onto the last. `bounds` holds each event's start and the end.
void drop_short_end_pauses(EndPauses put, std::vector<MarkupEvent>& events,
                           std::vector<size_t>& bounds, unsigned rate) {
  const size_t shortest = size_t{kMinSilenceMs} * rate / 1000;
  if (put.last && events.size() > 1 && bounds.end()[-1] - bounds.end()[-2] < shortest) {
    events.end()[-2].phoneme.end_of_text = events.back().phoneme.end_of_text;
    events.pop_back();
    bounds.erase(bounds.end() - 2);
  }
  if (put.first && events.size() > 1 && bounds[1] - bounds[0] < shortest) {
    events.erase(events.begin());
    bounds.erase(bounds.begin() + 1);
  }
}

}  // namespace

bool align(const tts::Utterance& utterance, const tts::VoiceSettings& voice,
           std::span<const int16_t> audio, unsigned rate, Alignment& out, std::string& error) {
  out = Alignment{};
  if (utterance.text.size() > max_text_characters(static_cast<double>(audio.size()) / rate)) {
    out.problem = Problem::kTextTooLong;
    pause_over(utterance, audio.size(), rate, out);
    return true;
  }
  tts::Speech syn;
  if (!tts::speak(utterance, voice, syn, error)) return false;
  out.inexact = syn.inexact;
  to_phonetic_boundaries(syn);

  if (rate < kMinRate || rate > kMaxRate) {
    out.problem = Problem::kBadRate;
    pause_over(utterance, audio.size(), rate, out);
    return true;
  }
  if (std::none_of(syn.phonemes.begin(), syn.phonemes.end(),
                   [](const tts::SpokenPhoneme& p) { return p.event.phoneme.symbol != 0; })) {
    out.problem = Problem::kEmptyText;
    pause_over(utterance, audio.size(), rate, out);
    return true;
  }
  const Features rec = mfcc(audio, rate);
  if (audio.empty() ||
      *std::max_element(rec.level_db.begin(), rec.level_db.end()) < kSpeechLevelDb) {
    out.problem = Problem::kNoSpeech;
    pause_over(utterance, audio.size(), rate, out);
    return true;
  }
  // The synthetic speech has almost no silence about it, a recording often has much: a pause
  // at each end holds the recording's, and a pause the speaker makes between words and
  // espeak-ng does not is held at the word's end.
  const EndPauses put = pad_with_pauses(syn, syn.sample_rate / 10);
  const Features synf = mfcc(syn.samples, syn.sample_rate);
  const std::vector<bool> rest = pause_frames(syn.phonemes, 0, synf);
  const Warp w = warp(synf, rec, kMaxWarpCells, &rest);
  out.relative_cost = w.relative_cost;
  const double ratio = speech_seconds(rec) / std::max(speech_seconds(synf), 0.01);
  if (w.relative_cost >= kPoorMatchCost || ratio < 1 / kMaxSpeechRatio || ratio > kMaxSpeechRatio) {
    out.problem = Problem::kPoorMatch;
  }

  std::vector<double> starts;
  for (size_t k = 1; k < syn.phonemes.size(); ++k) {
    starts.push_back(map_boundary(syn.phonemes[k].start, synf, rec, w));
  }
  snap_to_silence(syn.phonemes, audio, rate, starts);

  // Each phoneme's start on the recording, no earlier than the one before.
  std::vector<size_t> bounds;
  bounds.push_back(0);
  for (size_t k = 1; k < syn.phonemes.size(); ++k) {
    const double at = starts[k - 1];
    const size_t s =
        static_cast<size_t>(std::clamp(std::lround(at), 0L, static_cast<long>(audio.size())));
    bounds.push_back(std::max(s, bounds.back()));
  }
  bounds.push_back(audio.size());
  std::vector<MarkupEvent> events;
  for (const tts::SpokenPhoneme& p : syn.phonemes) events.push_back(p.event);
  drop_short_end_pauses(put, events, bounds, rate);

  const std::vector<double> f0 = tts::segment_f0(audio, rate, bounds);
  for (size_t k = 0; k < events.size(); ++k) {
    MarkupEvent e = events[k];
    e.phoneme.f0 = f0_code(static_cast<unsigned>(std::lround(f0[k])));
    tts::add_phoneme(e, bounds[k], bounds[k + 1], rate, out.phonemes);
  }
  if (out.problem == Problem::kNone && w.relative_cost >= kSureMatchCost) {
    out.heard_agreement = heard_agreement(out.phonemes, audio, rate);
    if (out.heard_agreement >= 0 && out.heard_agreement < kPoorHeardAgreement) {
      out.problem = Problem::kPoorMatch;
    }
  }
  return true;
}

}  // namespace pfap::align
