// MPEG-4 FAP files as PFAP events and back (docs/fap-files.md).
#include "pfap/fap_animation.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace pfap {
namespace {

// MPEG-4's expression_intensity is 6 bits.
constexpr int32_t kMaxExpressionIntensity = 63;

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

FapRecorder::FapRecorder(double frame_rate, uint32_t max_frames)
    : frame_rate_(frame_rate), max_frames_(max_frames) {}

void FapRecorder::reset() {
  state_.reset();
  last_ns_ = 0;
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
  time_ns = std::max(time_ns, last_ns_);
  last_ns_ = time_ns;
  if (!sample_before(time_ns)) return false;
  if (event.kind == PFAP_EVENT_COMPLETE) state_.reset();
  for (const Fap& fap : event.faps) state_.apply(fap, time_ns);
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

FapFile FapRecorder::file(const std::string& name, NotWritten* not_written) const {
  FapFile file;
  file.header.version = "2.1";
  file.header.name = name;
  file.header.frame_rate = frame_rate_;
  file.header.frame_count = frames();
  std::array<bool, kFapFileFaps + 1> used{};
  for (const FapAmplitudes& amplitudes : frames_) {
    for (int index = kMinFapIndex; index <= kMaxFapIndex; ++index) {
      if (amplitudes[index] == 0) continue;
      used[index < kFirstExpressionIndex ? index : kExpressionFap] = true;
    }
  }
  NotWritten dropped;
  for (const FapAmplitudes& amplitudes : frames_) {
    FapFrame& frame = file.frames.emplace_back();
    frame.number = static_cast<uint32_t>(file.frames.size() - 1);
    frame.set = used;
    for (int fap = kMinFapIndex; fap <= kFapFileFaps; ++fap) {
      if (used[fap]) frame.value[fap] = amplitudes[fap];
    }
    if (!used[kExpressionFap]) continue;
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
        ++dropped.expressions_dropped;
        continue;
      }
      const int32_t intensity = std::clamp(amplitude, 0, kMaxExpressionIntensity);
      if (intensity != amplitude) ++dropped.intensities_clamped;
      frame.expression[2 * slot] = order[slot] + 1;
      frame.expression[2 * slot + 1] = intensity;
    }
  }
  if (not_written != nullptr) *not_written = dropped;
  return file;
}

}  // namespace pfap
