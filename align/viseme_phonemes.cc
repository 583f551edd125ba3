// SPDX-License-Identifier: LGPL-2.1-or-later
#include "viseme_phonemes.h"

#include <algorithm>

namespace pfap::align {

bool visemes_take_rate(unsigned rate) {
  return rate >= kMinVisemeInputRate && rate <= kMaxVisemeInputRate;
}

VisemePhonemes::VisemePhonemes(unsigned rate, size_t max_run_frames) : rate_(rate) {
  if (visemes_take_rate(rate)) detector_.emplace(rate, max_run_frames);
}

void VisemePhonemes::push(std::span<const int16_t> samples, std::vector<tts::SpokenPhoneme>& out) {
  samples_ += samples.size();
  if (!detector_) {
    add_phoneme(Viseme::kNone, samples_, out);
    return;
  }
  runs_.clear();
  detector_->push(samples, runs_);
  add(runs_, false, out);
}

void VisemePhonemes::finish(std::vector<tts::SpokenPhoneme>& out) {
  runs_.clear();
  if (detector_) detector_->finish(runs_);
  add(runs_, true, out);
  add_phoneme(last_, samples_, out);  // a rounding's sample or two, or a pause where no audio
}

void VisemePhonemes::add(std::span<const VisemeRun> runs, bool at_end,
                         std::vector<tts::SpokenPhoneme>& out) {
  for (const VisemeRun& run : runs) {
    // Frame k starts at 10k ms: sample round(k * rate / 100). The last run may end past the
    // last sample (its frame holds it): it ends there.
    const uint64_t end_frame = run.start + run.frames;
    size_t end = static_cast<size_t>((end_frame * rate_ + 50) / 100);
    if (at_end) end = std::min(end, samples_);
    add_phoneme(run.viseme, end, out);
  }
}

void VisemePhonemes::add_phoneme(Viseme viseme, size_t end, std::vector<tts::SpokenPhoneme>& out) {
  if (end <= given_) return;
  MarkupEvent event;
  event.phoneme.symbol = static_cast<uint8_t>(viseme);
  event.phoneme.word_begin = viseme != Viseme::kNone && last_ == Viseme::kNone;
  tts::add_phoneme(event, given_, end, rate_, out);
  given_ = end;
  last_ = viseme;
}

}  // namespace pfap::align
