// SPDX-License-Identifier: LGPL-2.1-or-later
#include "live.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "boundaries.h"
#include "dtw.h"  // from_silence
#include "f0.h"

namespace pfap::align {
namespace {

// The recording's features are computed over the audio since the settled point and up to this
// much before it: enough speech for the MFCCs' normalization, a bounded cost per step.
constexpr unsigned kContextMs = 1000;
// The audio before the context is dropped once there is this much of it.
constexpr unsigned kTrimMs = 2000;
// Quieter than this, the recording's loudest frame so far is not taken for speech: the level
// dimension is measured below this, so that the silence before someone speaks stays a pause.
constexpr float kMinLoudestDb = kSpeechLevelDb + 20;
constexpr size_t kNone = std::numeric_limits<size_t>::max();

size_t samples_of(unsigned ms, unsigned rate) { return size_t{ms} * rate / 1000; }

// An open-end warp of recording frames [r0, r0 + rows) against synthetic frames [s0, s0 +
// cols), both from their first frames, with align()'s steps; the path ends at the recording's
// last frame and at the synthetic frame j where the summed distance over rows + j is least (the
// last frame when `closed`). Of the ends tried (docs/align.md, "Live"), this one gave the
// least error: the mean over the path's own steps ran ahead into the speech, the plain sum
// lagged behind it. On a synthetic frame where `rest` is true (the last before a word), the
// path may stay over recording frames at their distance from silence: a pause the speaker
// makes and the text's synthesis lacks costs nothing there, where without it the open end ran
// on into the next words. For each synthetic frame up to `end`, the first and last recording
// frame on the path (counted from r0, s0).
struct OpenWarp {
  size_t end = 0;
  std::vector<size_t> first, last;
};

// Frames quieter than kSpeechLevelDb become one and the same silence: MFCCs at their mean
// (0) and the level at its lowest. Normalized MFCCs of silence or of a microphone's hiss are
// anything, and without this the warp went on into the text's speech while the speaker had
// not yet begun.
void silence_quiet_frames(Features& f) {
  for (size_t k = 0; k < f.n_frames; ++k) {
    if (f.level_db[k] >= kSpeechLevelDb) continue;
    float* x = f.data.data() + k * Features::kDims;
    std::fill(x, x + Features::kMfccs, 0.0f);
    x[Features::kMfccs] = -kLevelWeight;
  }
}

OpenWarp open_warp(const Features& rec, size_t r0, size_t rows, const Features& syn, size_t s0,
                   size_t cols, const std::vector<bool>& rest, bool closed) {
  std::vector<float> d(rows * cols);      // the least summed distance from (0, 0) to each cell
  std::vector<size_t> back(rows * cols);  // the cell it came from
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (size_t r = 0; r < rows; ++r) {
    const std::span<const float> x = rec.frame(r0 + r);
    const float silence = from_silence(x);
    for (size_t j = 0; j < cols; ++j) {
      const std::span<const float> y = syn.frame(s0 + j);
      float sum = 0;
      for (size_t k = 0; k < Features::kDims; ++k) sum += (x[k] - y[k]) * (x[k] - y[k]);
      float best = r == 0 && j == 0 ? 0 : kInf;
      size_t from = 0;
      auto consider = [&](size_t cell) {
        if (d[cell] < best) best = d[cell], from = cell;
      };
      if (r > 0 && j > 0) consider((r - 1) * cols + j - 1);
      if (r > 0) consider((r - 1) * cols + j);
      if (j > 0) consider(r * cols + j - 1);
      d[r * cols + j] = best + std::sqrt(sum);
      back[r * cols + j] = from;
      if (r > 0 && rest[s0 + j] && d[(r - 1) * cols + j] + silence < d[r * cols + j]) {
        d[r * cols + j] = d[(r - 1) * cols + j] + silence;
        back[r * cols + j] = (r - 1) * cols + j;
      }
    }
  }
  OpenWarp w;
  w.end = cols - 1;
  if (!closed) {
    double best = std::numeric_limits<double>::infinity();
    for (size_t j = 0; j < cols; ++j) {
      const double mean = d[(rows - 1) * cols + j] / static_cast<double>(rows + j + 1);
      if (mean < best) best = mean, w.end = j;
    }
  }
  w.first.assign(w.end + 1, kNone);
  w.last.assign(w.end + 1, 0);
  for (size_t r = rows - 1, j = w.end;;) {
    w.first[j] = std::min(w.first[j], r);
    w.last[j] = std::max(w.last[j], r);
    if (r == 0 && j == 0) break;
    const size_t from = back[r * cols + j];
    r = from / cols, j = from % cols;
  }
  return w;
}

}  // namespace

bool LiveAligner::start(const tts::Utterance& utterance, const tts::VoiceSettings& voice,
                        unsigned rate, std::string& error) {
  *this = LiveAligner{};
  rate_ = rate;
  // The audio to come is unknown: the text is bounded as for the most align() takes.
  if (utterance.text.size() > max_text_characters(kMaxAudioSeconds)) {
    problem_ = Problem::kTextTooLong;
  } else if (!tts::speak(utterance, voice, syn_, error)) {
    return false;
  } else if (rate < kMinRate || rate > kMaxRate) {
    problem_ = Problem::kBadRate;
  } else if (std::none_of(syn_.phonemes.begin(), syn_.phonemes.end(),
                          [](const auto& p) { return p.event.phoneme.symbol != 0; })) {
    problem_ = Problem::kEmptyText;
  }
  if (problem_ != Problem::kNone) {
    syn_.phonemes.assign(1, tts::SpokenPhoneme{pause_event(utterance), 0, 0});
    return true;
  }
  to_phonetic_boundaries(syn_);
  // As align() does: a pause at each end holds the recording's silence before and after.
  pad_with_pauses(syn_, syn_.sample_rate / 10);
  synf_ = mfcc(syn_.samples, syn_.sample_rate);
  analyzer_ = std::make_unique<FrameAnalyzer>(rate);
  silence_quiet_frames(synf_);
  rest_ = pause_frames(syn_.phonemes, 0, synf_);
  return true;
}

void LiveAligner::push(std::span<const int16_t> samples, std::vector<tts::SpokenPhoneme>& out) {
  rec_.insert(rec_.end(), samples.begin(), samples.end());
  if (this->samples() - last_step_ < samples_of(kStepMs, rate_)) return;
  last_step_ = this->samples();
  step(false, out);
}

void LiveAligner::finish(std::vector<tts::SpokenPhoneme>& out) {
  if (next_ < syn_.phonemes.size()) step(true, out);
}

void LiveAligner::step(bool at_end, std::vector<tts::SpokenPhoneme>& out) {
  const size_t n = samples();
  const size_t lookahead = samples_of(kLookaheadMs, rate_);
  const size_t horizon = at_end ? n : n - std::min(n, lookahead);

  if (problem_ == Problem::kNone && rec_settled_ < n) {
    const size_t context = samples_of(kContextMs, rate_);
    const size_t w0 = std::min(rec_settled_, n - std::min(n, context));
    Features rec = features_from(w0);
    // The level below the loudest frame of the utterance so far, not of this window.
    loudest_db_ =
        std::max(loudest_db_, *std::max_element(rec.level_db.begin(), rec.level_db.end()));
    const float reference = std::max(loudest_db_, kMinLoudestDb);
    for (size_t k = 0; k < rec.n_frames; ++k) {
      const float below = std::clamp(rec.level_db[k] - reference, -kLevelRangeDb, 0.0f);
      rec.data[k * Features::kDims + Features::kMfccs] = below / kLevelRangeDb * kLevelWeight;
    }
    silence_quiet_frames(rec);
    const size_t r0 = rec.frame_at(rec_settled_ - w0);
    const size_t rows = rec.n_frames - r0;
    const size_t s0 = synf_.frame_at(syn_settled_);
    const size_t cols = at_end ? synf_.n_frames - s0 : std::min(synf_.n_frames - s0, 3 * rows + 40);
    const OpenWarp w = open_warp(rec, r0, rows, synf_, s0, cols, rest_, at_end);
    auto rec_centre = [&](size_t r) { return w0 + rec.centre(r0 + r); };

    // Where the synthetic sample `b` falls in the recording, as align()'s map_boundary; kNone
    // past the warp's end.
    auto map = [&](size_t b) -> size_t {
      const double pos = (static_cast<double>(b) - static_cast<double>(synf_.centre(s0))) /
                         static_cast<double>(synf_.hop);
      if (pos <= 0) return rec_settled_;
      const size_t i = static_cast<size_t>(std::ceil(pos));
      if (i > w.end) return at_end ? n : kNone;
      const double t = pos - static_cast<double>(i - 1);
      const double from = static_cast<double>(rec_centre(w.last[i - 1]));
      const double to = static_cast<double>(rec_centre(w.first[i]));
      return static_cast<size_t>(std::lround(from + t * (to - from)));
    };
    const size_t hold = samples_of(kHoldMs, rate_);
    size_t piece_end = horizon;
    bool first_waits = false;  // the first sound's start is placed, and waits for the hold
    while (next_ + 1 < syn_.phonemes.size()) {
      const size_t b = syn_.phonemes[next_ + 1].start;
      size_t at = map(b);
      if (at == kNone || at > horizon) break;
      at = snap(next_ + 1, at);  // the lookahead holds the audio it looks at (live.h)
      // The first sound's start waits for kHoldMs more audio: whether what starts there is a
      // hum (snap_to_silence) shows in what follows it, louder speech. The pause before it is
      // not given out past it meanwhile.
      if (!at_end && next_ == 0 && at + hold > horizon) {
        piece_end = std::max(at, rec_settled_);
        first_waits = true;
        break;
      }
      syn_settled_ = b;
      emit(std::clamp(at, rec_settled_, n), true, out);
    }
    if (!at_end && next_ == 0 && !first_waits && syn_.phonemes.size() > 1) {
      // Before the warp places the first sound, the pause stops where the first sound would
      // start at the first edge into sound, for kHoldMs at most: the warp hears frames below
      // kSpeechLevelDb as silence, so it places a weak onset late, and a start is never put
      // before what was given out.
      const size_t onset =
          rec_first_ + next_sound_start(syn_.phonemes[1], rec_, rate_, rec_settled_ - rec_first_);
      piece_end = std::max(std::min(onset, horizon), horizon - std::min(horizon, hold));
    }
    if (!at_end && horizon > rec_settled_ + hold && piece_end > rec_settled_) {
      // The phoneme goes on past the hold: a piece up to the horizon, and the warp restarts
      // from the synthetic frame matched there (within the phoneme).
      const size_t fr = std::min(
          rec.frame_at(piece_end - w0) - std::min(rec.frame_at(piece_end - w0), r0), rows - 1);
      size_t j = 0;
      while (j < w.end && w.last[j] < fr) ++j;
      const size_t lo = syn_.phonemes[next_].start;
      const size_t hi = next_ + 1 < syn_.phonemes.size() ? syn_.phonemes[next_ + 1].start - 1
                                                         : syn_.samples.size();
      syn_settled_ = std::clamp(synf_.centre(s0 + j), std::max(lo, syn_settled_), std::max(lo, hi));
      emit(piece_end, false, out);
    }
  } else if (!at_end && horizon > rec_settled_ + samples_of(kHoldMs, rate_)) {
    emit(horizon, false, out);  // a pause for the whole utterance, in pieces
  }
  if (at_end) {
    while (next_ < syn_.phonemes.size()) emit(n, true, out);
  }
  // The audio the next steps need: the context before the settled point, which covers
  // emit()'s half window. The rest goes, a block of kTrimMs at a time.
  const size_t keep_from = rec_settled_ - std::min(rec_settled_, samples_of(kContextMs, rate_));
  if (keep_from >= rec_first_ + samples_of(kTrimMs, rate_)) {
    rec_.erase(rec_.begin(), rec_.begin() + static_cast<std::ptrdiff_t>(keep_from - rec_first_));
    rec_first_ = keep_from;
  }
}

Features LiveAligner::features_from(size_t w0) {
  const std::span<const int16_t> audio = std::span(rec_).subspan(w0 - rec_first_);
  Features f = analyzer_->frames_of(audio.size());
  // w0 never goes back. The frames kept are those of w0's grid (the settled point and the
  // context's start move by any number of samples): those from w0 on, or none.
  if (w0 < frames_first_ || (w0 - frames_first_) % f.hop != 0) {
    frames_.clear();
  } else {
    const size_t gone = std::min(frames_.size(), (w0 - frames_first_) / f.hop * Features::kDims);
    frames_.erase(frames_.begin(), frames_.begin() + static_cast<std::ptrdiff_t>(gone));
  }
  frames_first_ = w0;
  // A frame past the audio's end (zero-padded, when there is less than a window) is not kept.
  const size_t whole = audio.size() < f.window ? 0 : f.n_frames;
  for (size_t k = frames_.size() / Features::kDims; k < whole; ++k) {
    frames_.resize((k + 1) * Features::kDims);
    frames_[k * Features::kDims + Features::kMfccs] =
        analyzer_->analyze(audio.subspan(k * f.hop), &frames_[k * Features::kDims]);
  }
  if (whole == 0) {
    f.level_db[0] = analyzer_->analyze(audio, f.data.data());
  } else {
    for (size_t k = 0; k < f.n_frames; ++k) {
      const float* x = &frames_[k * Features::kDims];
      std::copy(x, x + Features::kMfccs,
                f.data.begin() + static_cast<std::ptrdiff_t>(k * Features::kDims));
      f.level_db[k] = x[Features::kMfccs];
    }
  }
  normalize_mfccs(f);
  return f;
}

size_t LiveAligner::snap(size_t k, size_t at) const {
  const bool pause_before = syn_.phonemes[k - 1].event.phoneme.symbol == 0;
  if (pause_before == (syn_.phonemes[k].event.phoneme.symbol == 0)) return at;  // no edge
  const std::vector<tts::SpokenPhoneme> pair = {syn_.phonemes[k - 1], syn_.phonemes[k]};
  std::vector<double> starts = {static_cast<double>(std::max(at, rec_first_) - rec_first_)};
  snap_to_silence(pair, rec_, rate_, starts);
  return rec_first_ + static_cast<size_t>(std::lround(starts[0]));
}

void LiveAligner::emit(size_t to, bool whole, std::vector<tts::SpokenPhoneme>& out) {
  MarkupEvent e = syn_.phonemes[next_].event;
  if (next_started_) {
    // As pfap::split_long_phoneme's pieces: what marks the phoneme's start is on the first.
    e.faps.clear();
    e.sentence_start = false;
    e.phoneme.stress = false;
    e.phoneme.word_begin = false;
  }
  if (!whole) e.phoneme.end_of_text = false;
  // The pause put before the first sound (pad_with_pauses) when the speech starts at once:
  // no length, nothing it marks, left out.
  if (whole && to == rec_settled_ && e.phoneme.symbol == 0 && e.faps.empty() && !e.sentence_start &&
      !e.phoneme.end_of_text) {
    ++next_;
    return;
  }
  // f0 on the piece, YIN's windows centred in it.
  const size_t half_window = 512;
  const size_t a = rec_settled_ - std::min(rec_settled_, half_window);
  const size_t b = std::min(samples(), to + half_window);
  const size_t bounds[] = {rec_settled_ - a, to - a};
  const double hz =
      to > rec_settled_
          ? tts::segment_f0(std::span(rec_).subspan(a - rec_first_, b - a), rate_, bounds)[0]
          : 0;
  e.phoneme.f0 = f0_code(static_cast<unsigned>(std::lround(hz)));
  tts::add_phoneme(e, rec_settled_, to, rate_, out);
  rec_settled_ = to;
  next_started_ = !whole;
  if (whole) ++next_;
}

}  // namespace pfap::align
