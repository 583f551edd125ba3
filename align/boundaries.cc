// SPDX-License-Identifier: LGPL-2.1-or-later
#include "boundaries.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <string_view>

#include "pfap/phoneme_table.h"

namespace pfap::align {
namespace {

bool is_pause(const tts::SpokenPhoneme& p) { return p.event.phoneme.symbol == 0; }

// p, t, k, b, d, g, ch, jh: their closure is silence.
bool is_stop(const tts::SpokenPhoneme& p) {
  static const PhonemeAlphabet& arpabet = *find_alphabet(kArpabetAlphabet);
  const PhonemeInfo* info = find_phoneme(arpabet, p.event.phoneme.symbol);
  if (info == nullptr) return false;
  for (std::string_view stop : {"P", "T", "K", "B", "D", "G", "CH", "JH"}) {
    if (info->name == stop) return true;
  }
  return false;
}

}  // namespace

void to_phonetic_boundaries(tts::Speech& syn) {
  constexpr int kQuiet = 8;  // espeak-ng's closures are zeros; its speech is far louder
  const size_t min_run = syn.sample_rate / 200;      // 5 ms
  const size_t max_burst = syn.sample_rate / 100;    // 10 ms of release before the event
  const size_t max_back = syn.sample_rate * 3 / 20;  // 150 ms
  std::vector<tts::SpokenPhoneme>& ph = syn.phonemes;
  for (size_t k = 1; k < ph.size(); ++k) {
    if (is_pause(ph[k]) || is_pause(ph[k - 1])) continue;
    const size_t start = ph[k].start, floor = ph[k - 1].start;
    size_t j = start;
    while (j > floor && start - j <= max_burst && std::abs(syn.samples[j - 1]) > kQuiet) --j;
    const size_t silence_end = j;
    while (j > floor && start - j <= max_back && std::abs(syn.samples[j - 1]) <= kQuiet) --j;
    if (silence_end - j >= min_run && j > floor) ph[k].start = j;
  }
  const auto lead = static_cast<size_t>(std::lround(kPhoneticLeadSeconds * syn.sample_rate));
  for (size_t k = 1; k < ph.size(); ++k) {
    ph[k].start = std::max(ph[k - 1].start, ph[k].start > lead ? ph[k].start - lead : 0);
  }
}

EndPauses pad_with_pauses(tts::Speech& syn, size_t pad) {
  EndPauses put;
  std::vector<tts::SpokenPhoneme>& ph = syn.phonemes;
  const size_t end = syn.samples.size() + pad;
  syn.samples.insert(syn.samples.begin(), pad, 0);
  syn.samples.resize(syn.samples.size() + pad, 0);
  for (size_t k = 1; k < ph.size(); ++k) ph[k].start += pad;
  MarkupEvent pause;
  pause.kind = PFAP_EVENT_PHONEME;
  if (ph.empty() || !is_pause(ph.front())) {
    if (!ph.empty()) ph.front().start = pad;
    ph.insert(ph.begin(), tts::SpokenPhoneme{pause, 0, 0});
    put.first = true;
  }
  if (!is_pause(ph.back())) {
    std::swap(pause.phoneme.end_of_text, ph.back().event.phoneme.end_of_text);
    ph.push_back(tts::SpokenPhoneme{pause, end, 0});
    put.last = true;
  }
  return put;
}

std::vector<bool> pause_frames(const std::vector<tts::SpokenPhoneme>& phonemes, size_t offset,
                               const Features& features) {
  std::vector<bool> rest(features.n_frames, false);
  if (phonemes.empty()) return rest;
  // The pauses at the ends: every frame up to the first sound's start, from the last pause's.
  if (is_pause(phonemes.front()) && phonemes.size() > 1) {
    const size_t to = std::min(features.frame_at(phonemes[1].start + offset), rest.size());
    std::fill(rest.begin(), rest.begin() + static_cast<std::ptrdiff_t>(to), true);
  }
  if (is_pause(phonemes.back()) && phonemes.size() > 1) {
    const size_t from =
        std::min(features.frame_at(phonemes.back().start + offset) + 1, rest.size());
    std::fill(rest.begin() + static_cast<std::ptrdiff_t>(from), rest.end(), true);
  }
  for (size_t k = 1; k < phonemes.size(); ++k) {
    if (!phonemes[k].event.phoneme.word_begin || is_pause(phonemes[k]) ||
        is_pause(phonemes[k - 1])) {
      continue;
    }
    // The frame whose centre is the last before the start (as the warp's boundaries map).
    const size_t at = phonemes[k].start + offset;
    const size_t i = features.frame_at(at);
    rest[features.centre(i) >= at && i > 0 ? i - 1 : i] = true;
  }
  return rest;
}

namespace {

// The length of the blocks whose levels snap_to_silence() hears, and a length in whole blocks.
constexpr unsigned kBlockMs = 5;
constexpr long blocks_in(unsigned ms) { return static_cast<long>(ms / kBlockMs); }

// A recording's kBlockMs blocks, loud or silent as snap_to_silence() (boundaries.h) hears them,
// and where a sound after a pause starts among them.
class Silence {
 public:
  Silence(std::span<const int16_t> audio, unsigned rate)
      : rate_(rate), block_(rate * kBlockMs / 1000) {
    const size_t n = block_ > 0 ? audio.size() / block_ : 0;
    if (n < 2 * kMinQuietBlocks) return;
    db_.resize(n);
    for (size_t b = 0; b < db_.size(); ++b) {
      double energy = 0;
      for (size_t i = 0; i < block_; ++i) {
        const double x = audio[b * block_ + i] / 32768.0;
        energy += x * x;
      }
      db_[b] = static_cast<float>(10 * std::log10(energy / static_cast<double>(block_) + 1e-12));
    }
    // The floor leaves out digital silence (blocks more than kFloorRangeDb below the loudest):
    // zeros before a recording put it at -120 dB, and every hum and fading end above it sounded.
    loudest_ = *std::max_element(db_.begin(), db_.end());
    std::vector<float> heard;
    std::copy_if(db_.begin(), db_.end(), std::back_inserter(heard),
                 [&](float d) { return d > loudest_ - kFloorRangeDb; });
    std::sort(heard.begin(), heard.end());
    threshold_ = std::min(heard[heard.size() / 10] + 20, loudest_ - 20);
  }

  bool empty() const { return db_.empty(); }
  long blocks() const { return static_cast<long>(db_.size()); }
  size_t block() const { return block_; }

  // Speech ends (sound, then silence) or begins (silence, then sound) between blocks b - 1 and b.
  bool ends_at(long b) const {
    return b >= 1 && b < blocks() && loud(b - 1) && quiet_blocks(b, 1) >= kMinQuietBlocks;
  }
  bool begins_at(long b) const {
    return b >= 1 && b < blocks() && loud(b) && quiet_blocks(b - 1, -1) >= kMinQuietBlocks;
  }

  // The first edge into sound within kMaxHumMs after block `b`, when `b` starts a silence.
  long next_onset(long b) const {
    if (b < 1 || quiet_blocks(b, 1) < kMinQuietBlocks) return -1;
    for (long e = b + 1; e < blocks() && e - b <= blocks_in(kMaxHumMs); ++e) {
      if (begins_at(e)) return e;
    }
    return -1;
  }

  // Where `sound` starts, in samples, when speech begins with it at the edge `b`: past a hum
  // when it is the first sound, at its closure when it is a stop, else where it rises out of
  // the silence.
  double sound_start(const tts::SpokenPhoneme& sound, bool first, long b) const {
    const long edge = first ? past_hum(b) : b;
    const auto block = static_cast<double>(block_);
    // A stop's closure is as silent as the pause before it: the edge is its release. What
    // rises before a release is in its closure (ked's /t/): the closure rule alone.
    if (is_stop(sound)) {
      return std::max(static_cast<double>(edge) * block - double{kStopClosureMs} * rate_ / 1000,
                      0.0);
    }
    return static_cast<double>(rise_start(edge)) * block;
  }

  // Where `sound` ends, in samples, when speech ends with it at the edge `b`: a stop's closure
  // is silence, so at the last edge into silence within kMaxStopReleaseMs, its release's end.
  double sound_end(const tts::SpokenPhoneme& sound, long b) const {
    long end = b;
    if (is_stop(sound)) {
      for (long e = b + 1; e < blocks() && e - b <= blocks_in(kMaxStopReleaseMs); ++e) {
        if (ends_at(e)) end = e;
      }
    }
    return static_cast<double>(end) * static_cast<double>(block_);
  }

 private:
  static constexpr size_t kMinQuietBlocks = blocks_in(kMinSilenceMs);

  bool loud(long b) const { return db_[static_cast<size_t>(b)] >= threshold_; }

  size_t quiet_blocks(long from, long step) const {
    size_t count = 0;
    for (long b = from; b >= 0 && b < blocks() && !loud(b); b += step) ++count;
    return count;
  }

  // From the edge at block `b`: the edge after the hum that `b` starts, or `b` when what
  // follows it is louder or goes on without silence.
  long past_hum(long b) const {
    for (long e = b; e < blocks() && e - b <= blocks_in(kMaxHumMs); ++e) {
      if (db_[static_cast<size_t>(e)] >= loudest_ - kHumBelowLoudestDb) return b;
      const auto quiet = static_cast<long>(quiet_blocks(e, 1));
      if (quiet >= static_cast<long>(kMinQuietBlocks)) {
        if (e + quiet >= blocks()) return b;
        b = e + quiet;
        e = b - 1;
      }
    }
    return b;
  }

  // From the onset edge at block `b`: where the sound starts to rise out of the silence just
  // before it (the median of its blocks, digital silence left out), at most kMaxRiseMs back.
  long rise_start(long b) const {
    std::vector<float> before;
    for (long e = std::max(0L, b - blocks_in(kSnapRadiusMs)); e < b; ++e) {
      const float d = db_[static_cast<size_t>(e)];
      if (d < threshold_ && d > loudest_ - kFloorRangeDb) before.push_back(d);
    }
    if (before.empty()) return b;
    std::nth_element(before.begin(), before.begin() + static_cast<long>(before.size() / 2),
                     before.end());
    const float rising = before[before.size() / 2] + kOnsetRiseDb;
    long e = b;
    while (e > 0 && b - e < blocks_in(kMaxRiseMs) && db_[static_cast<size_t>(e - 1)] >= rising) --e;
    return e > 0 && db_[static_cast<size_t>(e - 1)] < rising ? e : b;  // else no silence before
  }

  unsigned rate_;
  size_t block_;
  std::vector<float> db_;
  float loudest_ = 0, threshold_ = 0;
};

}  // namespace

void snap_to_silence(const std::vector<tts::SpokenPhoneme>& phonemes,
                     std::span<const int16_t> audio, unsigned rate, std::vector<double>& starts) {
  const Silence silence(audio, rate);
  if (silence.empty()) return;
  const auto block = static_cast<double>(silence.block());
  for (size_t k = 1; k < phonemes.size() && k <= starts.size(); ++k) {
    const bool speech_ends = is_pause(phonemes[k]) && !is_pause(phonemes[k - 1]);
    const bool speech_begins = !is_pause(phonemes[k]) && is_pause(phonemes[k - 1]);
    if (!speech_ends && !speech_begins) continue;
    // The edge between blocks b - 1 and b nearest the warp's boundary.
    const long at = std::lround(starts[k - 1] / block);
    for (long d = 0; d <= blocks_in(kSnapRadiusMs); ++d) {
      long found = -1;
      for (long b : {at - d, at + d}) {
        if (speech_ends ? silence.ends_at(b) : silence.begins_at(b)) {
          found = b;
          break;
        }
      }
      // The warp can put the first sound in the silence before it, at a hum quieter than the
      // threshold, farther than the radius: it starts at the next edge.
      if (found < 0 && d == blocks_in(kSnapRadiusMs) && speech_begins && k == 1) {
        found = silence.next_onset(at);
      }
      if (found >= 0) {
        starts[k - 1] = speech_begins ? silence.sound_start(phonemes[k], k == 1, found)
                                      : silence.sound_end(phonemes[k - 1], found);
        break;
      }
    }
  }
}

size_t next_sound_start(const tts::SpokenPhoneme& sound, std::span<const int16_t> audio,
                        unsigned rate, size_t from) {
  const Silence silence(audio, rate);
  if (silence.empty()) return audio.size();
  const auto b0 = static_cast<long>((from + silence.block() - 1) / silence.block());
  for (long b = std::max(b0, 1L); b < silence.blocks(); ++b) {
    if (silence.begins_at(b)) {
      return static_cast<size_t>(std::lround(silence.sound_start(sound, true, b)));
    }
  }
  return audio.size();
}

}  // namespace pfap::align
