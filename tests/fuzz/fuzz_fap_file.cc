// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap::read_fap_file on arbitrary bytes (what pfapfapparse reads). An error must name a line of
// the input and keep nothing; a file read must respect the limits, write back as a file that
// reads the same, and its PFAP events (fap_animation.h) must be valid and give back every
// frame's values when applied to a FapState and sampled at the frame times.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.h"
#include "pfap/fap_animation.h"
#include "pfap/fap_file.h"
#include "pfap/fap_state.h"

namespace {

// Applies `events` to a FapState and checks every frame's values at its time.
void check_values(const pfap::FapFile& file, const std::vector<pfap::TextEvent>& events) {
  pfap::FapState state;
  size_t next = 0;
  for (const pfap::FapFrame& frame : file.frames) {
    const int64_t at = pfap::frame_time_ms(frame.number, file.header.frame_rate) * pfap::kNsPerMs;
    for (; next < events.size() && events[next].time_ms * pfap::kNsPerMs <= at; ++next) {
      for (const pfap::Fap& f : events[next].event.faps) {
        state.apply(f, events[next].time_ms * pfap::kNsPerMs);
      }
    }
    pfap::NotCarried ignored;
    const pfap::FapAmplitudes want = pfap::amplitudes_of(frame, ignored);
    for (int i = pfap::kMinFapIndex; i <= pfap::kMaxFapIndex; ++i) {
      FUZZ_CHECK(state.amplitude(i, at) == want[i]);
    }
  }
}

void check_valid(const std::vector<pfap::TextEvent>& events) {
  if (events.empty()) return;  // a merge of no speech with a file that never changes
  int64_t last_ms = 0;
  for (const pfap::TextEvent& e : events) {
    FUZZ_CHECK(e.time_ms >= last_ms);
    last_ms = e.time_ms;
    FUZZ_CHECK(pfap::is_valid(e.event.phoneme));
    FUZZ_CHECK(e.event.faps.size() <= size_t{pfap::kMaxBookmarksPerPhoneme});
    for (const pfap::Fap& f : e.event.faps) FUZZ_CHECK(pfap::is_valid(f));
  }
  FUZZ_CHECK(events.back().event.phoneme.end_of_text);
}

void check_events(const pfap::FapFile& file) {
  const std::vector<pfap::TextEvent> events = pfap::markup_of(file);
  FUZZ_CHECK(events.size() >= file.frames.size() && !events.empty());
  int64_t end_ms = 0;
  for (const pfap::TextEvent& e : events) {
    FUZZ_CHECK(e.time_ms == end_ms);  // phonemes tile the file's time
    end_ms += e.event.phoneme.duration_ms;
  }
  check_valid(events);
  check_values(file, events);

  // Merged with speech over the first half of the file, 70 ms phonemes with a gap after
  // the third: the file's values stay.
  std::vector<pfap::TextEvent> speech;
  for (int64_t at = 0; at < end_ms / 2; at += 70) {
    pfap::TextEvent s;
    s.time_ms = speech.size() == 3 ? at + 30 : at;
    s.event.kind = PFAP_EVENT_PHONEME;
    s.event.phoneme.symbol = 7;
    s.event.phoneme.duration_ms = 70;
    speech.push_back(s);
    if (speech.size() == 4) at += 30;
  }
  const std::vector<pfap::TextEvent> merged = pfap::merge_with_speech(speech, events);
  check_valid(merged);
  check_values(file, merged);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  pfap::FapFile file;
  file.header.name = "untouched";
  const pfap::FapFileResult result = pfap::read_fap_file(text, file);
  if (!result.ok()) {
    FUZZ_CHECK(file.header.name == "untouched" && file.frames.empty());
    size_t lines = 1;
    for (char c : text) lines += c == '\n';
    FUZZ_CHECK(result.line >= 1 && result.line <= lines + 1);
    FUZZ_CHECK(!pfap::describe(result).empty());
    return 0;
  }
  FUZZ_CHECK(file.frames.size() == file.header.frame_count);
  FUZZ_CHECK(file.header.frame_count <= pfap::kMaxFapFileFrames);
  FUZZ_CHECK(file.header.frame_rate >= pfap::kMinFapFileFrameRate &&
             file.header.frame_rate <= pfap::kMaxFapFileFrameRate);

  // Written and read again: the same frames, but values are whole now.
  pfap::FapFile back;
  const pfap::FapFileResult again = pfap::read_fap_file(pfap::write_fap_file(file), back);
  FUZZ_CHECK(again.ok());
  FUZZ_CHECK(back.frames.size() == file.frames.size());
  for (size_t k = 0; k < file.frames.size(); ++k) {
    pfap::FapFrame frame = file.frames[k];
    frame.rounded = 0;
    FUZZ_CHECK(back.frames[k] == frame);
  }
  check_events(file);
  return 0;
}
