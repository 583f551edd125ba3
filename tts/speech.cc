// SPDX-License-Identifier: LGPL-2.1-or-later
#include "speech.h"

#include <algorithm>
#include <cmath>

#include "arpabet.h"
#include "f0.h"
#include "pfap/phoneme_table.h"
#include "placement.h"
#include "stress.h"

namespace pfap::tts {
namespace {

struct Segment {
  size_t start;
  size_t end;
  size_t espeak_index;  // SIZE_MAX for the lead-in pause
  size_t sentence;
};

uint64_t to_ms(size_t sample, unsigned rate) {
  return (static_cast<uint64_t>(sample) * 1000 + rate / 2) / rate;
}

}  // namespace

void add_phoneme(const MarkupEvent& event, size_t start, size_t end, unsigned rate,
                 std::vector<SpokenPhoneme>& out) {
  const uint64_t ms = to_ms(end, rate) - to_ms(start, rate);
  std::vector<Phoneme> pieces;
  split_long_phoneme(event.phoneme, static_cast<uint32_t>(ms), pieces);
  size_t piece_start = start;
  for (size_t i = 0; i < pieces.size(); ++i) {
    // Every piece but the last is 4095 ms on the ms grid.
    const size_t piece_end =
        i + 1 < pieces.size()
            ? static_cast<size_t>(
                  ((to_ms(piece_start, rate) + kMaxPhonemeDurationMs) * rate + 500) / 1000)
            : end;
    SpokenPhoneme p;
    p.event = event;
    p.event.phoneme = pieces[i];
    if (i > 0) {
      p.event.faps.clear();
      p.event.sentence_start = false;
    }
    p.start = piece_start;
    p.n_samples = piece_end - piece_start;
    out.push_back(std::move(p));
    piece_start = piece_end;
  }
}

bool speak(const Utterance& utterance, const VoiceSettings& settings, Speech& out,
           std::string& error, const std::atomic<bool>* cancel) {
  Synthesis syn;
  if (!synthesize(utterance.text_utf8(), settings, syn, error, cancel)) return false;
  out = Speech{};
  if (cancel != nullptr && *cancel) return true;
  out.sample_rate = syn.sample_rate;
  const size_t total = syn.samples.size();

  // The segments that tile the audio, and where each espeak-ng phoneme went.
  std::vector<Segment> segments;
  std::vector<size_t> segment_of(syn.phonemes.size(), SIZE_MAX);
  if (!syn.phonemes.empty() && syn.phonemes[0].sample > 0) {
    segments.push_back({0, std::min(syn.phonemes[0].sample, total), SIZE_MAX, 0});
  }
  // espeak-ng's positions may step back a little at high rates: each start is taken no
  // earlier than the one before, so that the segments tile the audio whatever it reports.
  std::vector<size_t> starts(syn.phonemes.size() + 1, total);
  for (size_t i = 0, floor = 0; i < syn.phonemes.size(); ++i) {
    floor = std::min(std::max(syn.phonemes[i].sample, floor), total);
    starts[i] = floor;
  }
  for (size_t i = 0; i < syn.phonemes.size(); ++i) {
    if (starts[i + 1] <= starts[i]) continue;
    segment_of[i] = segments.size();
    segments.push_back({starts[i], starts[i + 1], i, syn.phonemes[i].sentence});
  }
  if (segments.empty()) segments.push_back({0, total, SIZE_MAX, 0});

  // Words by segment: the first and last of their phonemes that have samples.
  std::vector<Word> words;
  for (const Synthesis::Word& w : syn.words) {
    size_t first = SIZE_MAX, last = SIZE_MAX;
    for (size_t p = w.first_phoneme; p < w.end_phoneme; ++p) {
      if (segment_of[p] == SIZE_MAX) continue;
      if (first == SIZE_MAX) first = segment_of[p];
      last = segment_of[p];
    }
    if (first != SIZE_MAX) words.push_back({w.start, w.sentence, first, last});
  }

  std::vector<std::string> mnemonics;
  for (const Synthesis::Phoneme& p : syn.phonemes) mnemonics.push_back(p.mnemonic);
  const std::vector<bool> stressed = primary_stress(syn.transcription, mnemonics);

  std::vector<size_t> bounds;
  for (const Segment& s : segments) bounds.push_back(s.start);
  bounds.push_back(segments.back().end);
  const std::vector<double> f0 = segment_f0(syn.samples, syn.sample_rate, bounds, cancel);
  if (cancel != nullptr && *cancel) return true;

  const PhonemeAlphabet& arpabet = *find_alphabet(kArpabetAlphabet);
  std::vector<MarkupEvent> events(segments.size());
  for (size_t k = 0; k < segments.size(); ++k) {
    const Segment& s = segments[k];
    MarkupEvent& e = events[k];
    e.kind = PFAP_EVENT_PHONEME;
    if (s.espeak_index != SIZE_MAX) {
      const std::string& m = syn.phonemes[s.espeak_index].mnemonic;
      const std::optional<ArpabetSymbol> symbol = arpabet_symbol(m);
      e.phoneme.symbol = symbol ? symbol->symbol : 0;
      if ((!symbol || !symbol->exact) &&
          std::none_of(out.inexact.begin(), out.inexact.end(),
                       [&](const Speech::Inexact& i) { return i.mnemonic == m; })) {
        out.inexact.push_back({m, find_phoneme(arpabet, e.phoneme.symbol)->name});
      }
      e.phoneme.stress = stressed[s.espeak_index];
    }
    e.phoneme.f0 = f0_code(static_cast<unsigned>(std::lround(f0[k])));
    e.sentence_start = k == 0 || segments[k - 1].sentence != s.sentence;
    e.phoneme.end_of_text = k + 1 == segments.size() || segments[k + 1].sentence != s.sentence;
  }
  for (const Word& w : words) events[w.first_phoneme].phoneme.word_begin = true;
  for (const Bookmark& b : utterance.bookmarks) {
    const size_t at = place_bookmark(words, utterance.text, b.position).value_or(0);
    events[at].faps.insert(events[at].faps.end(), b.faps.begin(), b.faps.end());
  }

  for (size_t k = 0; k < segments.size(); ++k) {
    const Segment& seg = segments[k];
    add_phoneme(events[k], seg.start, seg.end, syn.sample_rate, out.phonemes);
  }
  out.samples = std::move(syn.samples);
  return true;
}

}  // namespace pfap::tts
