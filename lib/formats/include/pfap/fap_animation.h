// SPDX-License-Identifier: LGPL-2.1-or-later
// MPEG-4 FAP files as PFAP events and back (docs/fap-files.md).
//
// File to events: frame k becomes a silence phoneme starting at frame_time_ms(k), lasting
// until the next frame, with a bookmark <FAP n a 0 1> (linear, T = 0) for each FAP whose
// value differs from the frame before (0 before the first frame). T = 0 holds each frame's
// values from its time to the next frame's, as MPEG-4 players show a FAP file, so a receiver's
// FapState sampled at frame_time_ms(k) is the file's frame k exactly. More than
// kMaxBookmarksPerPhoneme changes go on extra 0 ms silence phonemes at the same time.
//
// FAPs 3..68 keep their number. FAP 2 (expression select1 intensity1 select2 intensity2) is
// the bookmark rule's: FAPs 68 + select with the intensity as amplitude, the other expressions
// 0. FAP 1 (viseme) and FAP 2's init_face and expression_def have no place in the draft:
// they are counted in NotCarried, for the caller to report.
//
// Events to file: FapRecorder applies events to a FapState and samples it at frame times,
// rounding each amplitude to the nearest whole unit.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "pfap/fap_file.h"
#include "pfap/fap_state.h"
#include "pfap/markup_event.h"
#include "pfap/text.h"

namespace pfap {

// The amplitude of each PFAP FAP index 3..74 in one frame; [0..2] unused.
using FapAmplitudes = std::array<int32_t, kFapCount>;

// The silence symbol of x-pfap-arpabet (phoneme_table.h), which pfapfapparse announces.
inline constexpr uint8_t kSilenceSymbol = 0;

// The start of frame `frame` in whole ms: frame / rate seconds, rounded to the nearest ms
// (phoneme durations on the wire are whole ms). Both directions use it.
int64_t frame_time_ms(uint64_t frame, double frame_rate);

// What a FAP file holds that the draft cannot carry, counted in frames.
struct NotCarried {
  uint64_t visemes = 0;           // frames setting FAP 1
  uint64_t expression_flags = 0;  // frames setting FAP 2 with init_face or expression_def
  uint64_t rounded_values = 0;    // values with a fraction, rounded to whole units

  bool any() const { return visemes != 0 || expression_flags != 0 || rounded_values != 0; }
};

// A frame's amplitudes: a FAP the mask leaves out is 0 in that frame (Xface's reading; see
// docs/fap-files.md), expressions as above.
FapAmplitudes amplitudes_of(const FapFrame& frame, NotCarried& not_carried);

// Turns the frames of a file, in order, into phoneme events.
class FapFileMarkup {
 public:
  explicit FapFileMarkup(const FapFileHeader& header);
  // Appends frame `frame`'s events (1 or more phonemes). Frames come in order from 0.
  void add(const FapFrame& frame, std::vector<TextEvent>& out);
  const NotCarried& not_carried() const { return not_carried_; }

 private:
  FapFileHeader header_;
  FapAmplitudes previous_{};
  NotCarried not_carried_;
};

// The events of a whole file.
std::vector<TextEvent> markup_of(const FapFile& file, NotCarried* not_carried = nullptr);

// A file's events (markup_of) merged with a speech stream's events, both timed from 0 ms and
// in time order, speech phonemes one after the other. Each frame's bookmarks go on the speech
// phoneme that starts at the frame's time; a speech phoneme that spans a frame with changes is
// split there into pieces of the same symbol and f0 (the first keeps stress, word begin,
// sentence start and the speech's own FAPs, the last end of text). Where no speech phoneme
// spans a frame with changes, a silence phoneme carries them, lasting until the next such
// frame or speech phoneme. The file's bookmarks come after the speech's at the same time, so
// the file's value wins there; a FAP the speech sets between frames holds until the file's
// next change of it. More than kMaxBookmarksPerPhoneme FAPs on one phoneme go on 0 ms silence
// phonemes before it. The last phoneme ends the text.
std::vector<TextEvent> merge_with_speech(const std::vector<TextEvent>& speech,
                                         const std::vector<TextEvent>& file_events,
                                         uint8_t silence_symbol = kSilenceSymbol);

// What a FAP file can hold of the amplitudes that it cannot write as they are.
struct NotWritten {
  uint64_t expressions_dropped = 0;  // a third (or more) expression at once: FAP 2 has two
  uint64_t intensities_clamped = 0;  // an expression amplitude outside MPEG-4's 0..63
};

// Samples a receiver's FAP state at the frames of a rate.
class FapRecorder {
 public:
  explicit FapRecorder(double frame_rate, uint32_t max_frames = kMaxFapFileFrames);
  // Applies an event at `time_ns` from frame 0's time, 0 or later and never earlier than the
  // event before (EventTimeline places events so: timeline.h). The frames before it are
  // sampled first. False once max_frames are sampled: later events are not recorded.
  bool apply(const MarkupEvent& event, int64_t time_ns);
  // Samples the frames that start before `end_ns` (at least frame 0), then more while a
  // transition is still running at the last one. False if max_frames cut the end off.
  bool finish(int64_t end_ns);
  uint32_t frames() const { return static_cast<uint32_t>(frames_.size()); }
  const std::vector<FapAmplitudes>& amplitudes() const { return frames_; }
  // The FAP file: every FAP that is ever non-zero is set in every frame, so that readers that
  // hold a FAP the mask leaves out and readers that take it for 0 read the same values.
  FapFile file(const std::string& name, NotWritten* not_written = nullptr) const;
  // The same file a frame at a time, for a writer that keeps no more than the amplitudes:
  // its header, the mask of every frame, and frame `number` (< frames()) with that mask.
  using Mask = std::array<bool, kFapFileFaps + 1>;
  FapFileHeader header(const std::string& name) const;
  Mask mask() const;
  FapFrame frame(uint32_t number, const Mask& mask, NotWritten& not_written) const;
  void reset();

 private:
  bool sample_before(int64_t time_ns);

  double frame_rate_;
  uint32_t max_frames_;
  FapState state_;
  std::vector<FapAmplitudes> frames_;
};

}  // namespace pfap
