// SPDX-License-Identifier: LGPL-2.1-or-later
// MPEG-4 FAP files as PFAP events and back (docs/fap-files.md).
#include "pfap/fap_animation.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace pfap {
namespace {

// A frame of the file with changes: where a phoneme must start.
struct Cut {
  int64_t time_ms;
  std::vector<Fap> faps;
};

TextEvent silence_phoneme(int64_t time_ms, int64_t duration_ms, uint8_t symbol) {
  TextEvent e;
  e.time_ms = time_ms;
  e.event.kind = PFAP_EVENT_PHONEME;
  e.event.phoneme.symbol = symbol;
  e.event.phoneme.duration_ms =
      static_cast<uint16_t>(std::min<int64_t>(duration_ms, kMaxPhonemeDurationMs));
  return e;
}

// Appends a phoneme; FAPs past the 40 MPEG-4 allows go first on 0 ms silence phonemes, the
// first of which takes the sentence start.
void append_phoneme(TextEvent event, uint8_t silence, std::vector<TextEvent>& out) {
  std::vector<Fap> faps = std::move(event.event.faps);
  size_t taken = 0;
  while (faps.size() - taken > size_t{kMaxBookmarksPerPhoneme}) {
    TextEvent piece = silence_phoneme(event.time_ms, 0, silence);
    piece.event.sentence_start = event.event.sentence_start;
    event.event.sentence_start = false;
    const auto from = faps.begin() + static_cast<std::ptrdiff_t>(taken);
    piece.event.faps.assign(from, from + kMaxBookmarksPerPhoneme);
    out.push_back(std::move(piece));
    taken += kMaxBookmarksPerPhoneme;
  }
  event.event.faps.assign(faps.begin() + static_cast<std::ptrdiff_t>(taken), faps.end());
  out.push_back(std::move(event));
}

}  // namespace

int64_t frame_time_ms(uint64_t frame, double frame_rate) {
  return std::llround(static_cast<double>(frame) * 1000.0 / frame_rate);
}

FapAmplitudes amplitudes_of(const FapFrame& frame, NotCarried& not_carried) {
  FapAmplitudes out{};
  for (int fap = kMinFapIndex; fap <= kFapFileFaps; ++fap) {
    if (frame.set[fap]) out[fap] = frame.value[fap];
  }
  if (frame.set[kExpressionFap]) {
    // select1 intensity1 select2 intensity2: the bookmark rule's FAPs 68 + select. A select
    // of 0 (neutral) sets nothing; the same expression twice keeps the second, as two
    // bookmarks for one FAP would.
    for (int slot = 0; slot < 2; ++slot) {
      const int32_t select = frame.expression[2 * slot];
      if (select != 0) out[kFirstExpressionIndex - 1 + select] = frame.expression[2 * slot + 1];
    }
    if (frame.expression[4] != 0 || frame.expression[5] != 0) ++not_carried.expression_flags;
  }
  if (frame.set[kVisemeFap]) ++not_carried.visemes;
  not_carried.rounded_values += frame.rounded;
  return out;
}

FapFileMarkup::FapFileMarkup(const FapFileHeader& header) : header_(header) {}

void FapFileMarkup::add(const FapFrame& frame, std::vector<TextEvent>& out) {
  const FapAmplitudes amplitudes = amplitudes_of(frame, not_carried_);
  std::vector<Fap> changes;
  for (int index = kMinFapIndex; index <= kMaxFapIndex; ++index) {
    if (amplitudes[index] == previous_[index]) continue;
    changes.push_back(Fap{static_cast<uint8_t>(index), amplitudes[index], 0, Curve::kLinear});
  }
  previous_ = amplitudes;

  const int64_t start = frame_time_ms(frame.number, header_.frame_rate);
  const int64_t end = frame_time_ms(uint64_t{frame.number} + 1, header_.frame_rate);
  const bool last = frame.number + 1 == header_.frame_count;
  // MPEG-4 allows 40 bookmarks before a phoneme: the rest go on 0 ms phonemes before it.
  size_t taken = 0;
  do {
    const size_t n = std::min(changes.size() - taken, size_t{kMaxBookmarksPerPhoneme});
    const bool final_piece = taken + n == changes.size();
    TextEvent event;
    event.time_ms = start;
    event.event.kind = PFAP_EVENT_PHONEME;
    event.event.sentence_start = frame.number == 0 && taken == 0;
    event.event.phoneme.symbol = kSilenceSymbol;
    event.event.phoneme.duration_ms = final_piece ? static_cast<uint16_t>(end - start) : 0;
    event.event.phoneme.end_of_text = last && final_piece;
    event.event.faps.assign(changes.begin() + static_cast<std::ptrdiff_t>(taken),
                            changes.begin() + static_cast<std::ptrdiff_t>(taken + n));
    out.push_back(std::move(event));
    taken += n;
  } while (taken < changes.size());
}

std::vector<TextEvent> markup_of(const FapFile& file, NotCarried* not_carried) {
  FapFileMarkup markup(file.header);
  std::vector<TextEvent> events;
  for (const FapFrame& frame : file.frames) markup.add(frame, events);
  if (not_carried != nullptr) *not_carried = markup.not_carried();
  return events;
}

std::vector<TextEvent> merge_with_speech(const std::vector<TextEvent>& speech,
                                         const std::vector<TextEvent>& file_events,
                                         uint8_t silence_symbol) {
  std::vector<Cut> cuts;
  int64_t file_end_ms = 0;
  for (const TextEvent& e : file_events) {
    if (e.event.kind != PFAP_EVENT_PHONEME) continue;
    file_end_ms = std::max(file_end_ms, e.time_ms + e.event.phoneme.duration_ms);
    if (e.event.faps.empty()) continue;
    if (cuts.empty() || cuts.back().time_ms != e.time_ms) cuts.push_back({e.time_ms, {}});
    cuts.back().faps.insert(cuts.back().faps.end(), e.event.faps.begin(), e.event.faps.end());
  }

  std::vector<TextEvent> out;
  size_t next = 0;            // the first cut not placed yet
  bool sentence_next = true;  // the next silence phoneme starts a sentence
  // Silence phonemes for the cuts before `until_ms`, where no speech phoneme is.
  auto fill_silence = [&](int64_t until_ms) {
    for (; next < cuts.size() && cuts[next].time_ms < until_ms; ++next) {
      const int64_t end_ms =
          next + 1 < cuts.size() ? std::min(cuts[next + 1].time_ms, until_ms) : until_ms;
      TextEvent e =
          silence_phoneme(cuts[next].time_ms, end_ms - cuts[next].time_ms, silence_symbol);
      e.event.sentence_start = sentence_next;
      sentence_next = false;
      e.event.faps = std::move(cuts[next].faps);
      append_phoneme(std::move(e), silence_symbol, out);
    }
  };

  for (const TextEvent& s : speech) {
    fill_silence(s.time_ms);
    if (s.event.kind != PFAP_EVENT_PHONEME) {
      out.push_back(s);
      continue;
    }
    const int64_t end_ms = s.time_ms + s.event.phoneme.duration_ms;
    std::vector<Fap> faps = s.event.faps;
    for (int64_t piece_ms = s.time_ms;;) {
      if (next < cuts.size() && cuts[next].time_ms == piece_ms) {
        faps.insert(faps.end(), cuts[next].faps.begin(), cuts[next].faps.end());
        ++next;
      }
      const int64_t piece_end_ms =
          next < cuts.size() && cuts[next].time_ms < end_ms ? cuts[next].time_ms : end_ms;
      TextEvent piece = s;
      piece.time_ms = piece_ms;
      piece.event.phoneme.duration_ms = static_cast<uint16_t>(piece_end_ms - piece_ms);
      piece.event.faps = std::move(faps);
      faps.clear();
      if (piece_ms != s.time_ms) {
        piece.event.phoneme.stress = piece.event.phoneme.word_begin = false;
        piece.event.sentence_start = false;
      }
      if (piece_end_ms != end_ms) piece.event.phoneme.end_of_text = false;
      append_phoneme(std::move(piece), silence_symbol, out);
      if (piece_end_ms == end_ms) break;
      piece_ms = piece_end_ms;
    }
    sentence_next = s.event.phoneme.end_of_text;
  }
  fill_silence(std::max(file_end_ms, cuts.empty() ? 0 : cuts.back().time_ms + 1));
  for (auto it = out.rbegin(); it != out.rend(); ++it) {
    if (it->event.kind == PFAP_EVENT_PHONEME) {
      it->event.phoneme.end_of_text = true;
      break;
    }
  }
  return out;
}

FapRecorder::FapRecorder(double frame_rate, uint32_t max_frames)
    : frame_rate_(frame_rate), max_frames_(max_frames) {}

void FapRecorder::reset() {
  state_.reset();
  frames_.clear();
}

bool FapRecorder::sample_before(int64_t time_ns) {
  while (frame_time_ms(frames_.size(), frame_rate_) * kNsPerMs < time_ns) {
    if (frames_.size() >= max_frames_) return false;
    const int64_t at = frame_time_ms(frames_.size(), frame_rate_) * kNsPerMs;
    FapAmplitudes& frame = frames_.emplace_back();
    for (int index = kMinFapIndex; index <= kMaxFapIndex; ++index) {
      frame[index] = static_cast<int32_t>(std::lround(state_.amplitude(index, at)));
    }
  }
  return true;
}

bool FapRecorder::apply(const MarkupEvent& event, int64_t time_ns) {
  if (!sample_before(time_ns)) return false;
  apply_markup(event, time_ns, state_);
  return true;
}

bool FapRecorder::finish(int64_t end_ns) {
  // At least frame 0: a FAP file has one frame or more.
  if (!sample_before(std::max<int64_t>(end_ns, 1))) return false;
  // Transitions still running at the last frame: frames on until they are over, so that the
  // file ends on what the FAPs settle to (at most 16.4 s, the longest transition).
  for (;;) {
    const int64_t last_ns = frame_time_ms(frames_.size() - 1, frame_rate_) * kNsPerMs;
    bool running = false;
    for (int index = kMinFapIndex; index <= kMaxFapIndex && !running; ++index) {
      running = !state_.at_rest(index, last_ns);
    }
    if (!running) break;
    if (!sample_before(frame_time_ms(frames_.size(), frame_rate_) * kNsPerMs + 1)) return false;
  }
  return true;
}

FapFileHeader FapRecorder::header(const std::string& name) const {
  return {"2.1", name, frame_rate_, frames()};
}

FapRecorder::Mask FapRecorder::mask() const {
  Mask used{};
  for (const FapAmplitudes& amplitudes : frames_) {
    for (int index = kMinFapIndex; index <= kMaxFapIndex; ++index) {
      if (amplitudes[index] == 0) continue;
      used[index < kFirstExpressionIndex ? index : kExpressionFap] = true;
    }
  }
  return used;
}

FapFrame FapRecorder::frame(uint32_t number, const Mask& mask, NotWritten& not_written) const {
  const FapAmplitudes& amplitudes = frames_[number];
  FapFrame frame;
  frame.number = number;
  frame.set = mask;
  for (int fap = kMinFapIndex; fap <= kFapFileFaps; ++fap) {
    if (mask[fap]) frame.value[fap] = amplitudes[fap];
  }
  if (!mask[kExpressionFap]) return frame;
  // The two strongest expressions, as select and intensity pairs.
  std::array<int, 6> order = {0, 1, 2, 3, 4, 5};
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return std::abs(amplitudes[kFirstExpressionIndex + a]) >
           std::abs(amplitudes[kFirstExpressionIndex + b]);
  });
  for (int slot = 0; slot < 6; ++slot) {
    const int32_t amplitude = amplitudes[kFirstExpressionIndex + order[slot]];
    if (amplitude == 0) continue;
    if (slot >= 2) {
      ++not_written.expressions_dropped;
      continue;
    }
    const int32_t intensity = std::clamp(amplitude, 0, kMaxExpressionIntensity);
    if (intensity != amplitude) ++not_written.intensities_clamped;
    frame.expression[2 * slot] = order[slot] + 1;
    frame.expression[2 * slot + 1] = intensity;
  }
  return frame;
}

FapFile FapRecorder::file(const std::string& name, NotWritten* not_written) const {
  FapFile file;
  file.header = header(name);
  const Mask used = mask();
  NotWritten dropped;
  file.frames.reserve(frames_.size());
  for (uint32_t k = 0; k < frames(); ++k) file.frames.push_back(frame(k, used, dropped));
  if (not_written != nullptr) *not_written = dropped;
  return file;
}

}  // namespace pfap
