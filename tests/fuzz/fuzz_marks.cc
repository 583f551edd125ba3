// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap::MarksReader on arbitrary text: the first byte picks the format (Polly, Rhubarb lines,
// Rhubarb JSON document, Azure), the rest is read as pfapmarksparse reads it. Every event must
// be a valid phoneme of the format's alphabet at a time that never goes back, an error must
// point inside its line and keep nothing from it; the events read are then written in every
// format, and the Polly marks written must read back.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_check.h"
#include "pfap/speech_marks.h"

namespace {

void check_events(const std::vector<pfap::TextEvent>& events, const pfap::PhonemeAlphabet& a,
                  int64_t& last_time_ms) {
  for (const pfap::TextEvent& e : events) {
    FUZZ_CHECK(e.event.kind == PFAP_EVENT_PHONEME);
    FUZZ_CHECK(pfap::is_valid(e.event.phoneme));
    FUZZ_CHECK(e.event.faps.empty());
    FUZZ_CHECK(pfap::find_visemes(a, e.event.phoneme.symbol).has_value());
    FUZZ_CHECK(e.time_ms >= last_time_ms);
    last_time_ms = e.time_ms;
  }
}

void write_all(const std::vector<pfap::TextEvent>& events, const pfap::PhonemeAlphabet& a) {
  for (int f = 0; f <= static_cast<int>(pfap::MarksFormat::kArkitCsv); ++f) {
    const auto format = static_cast<pfap::MarksFormat>(f);
    pfap::MarksWriter writer(format, 30);
    writer.set_alphabet(&a);
    std::string out;
    size_t frames_bytes = 0;
    const pfap::MarksWriter::Sink sink = [&](std::string_view text) {
      frames_bytes += text.size();
      // Frames of long pauses would be large: keep what is checked.
      if (format != pfap::MarksFormat::kArkitJson && format != pfap::MarksFormat::kArkitCsv) {
        out += text;
      }
      return frames_bytes < (1u << 16);
    };
    bool ok = true;
    for (const pfap::TextEvent& e : events) {
      ok = ok && writer.add(e.event, e.time_ms * pfap::kNsPerMs, sink);
    }
    if (ok) writer.finish(sink);
    FUZZ_CHECK(writer.unknown_phonemes() == 0);
    if (format != pfap::MarksFormat::kPolly) continue;
    pfap::MarksReader back(pfap::MarksInput::kPolly);
    std::vector<pfap::TextEvent> read;
    std::string_view text = out;
    while (!text.empty()) {
      const size_t end = text.find('\n');
      FUZZ_CHECK(back.read_line(text.substr(0, end), read).ok());
      text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const int mode = data[0] % 4;
  std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  const pfap::MarksInput input = mode == 0   ? pfap::MarksInput::kPolly
                                 : mode == 3 ? pfap::MarksInput::kAzure
                                             : pfap::MarksInput::kRhubarb;
  pfap::MarksReader reader(input);
  const pfap::PhonemeAlphabet& alphabet = *pfap::find_alphabet(reader.alphabet());
  std::vector<pfap::TextEvent> all;
  int64_t last_time_ms = 0;
  if (mode == 2) {
    std::vector<pfap::TextEvent> events;
    const pfap::MarksResult result = reader.read_document(text, events);
    if (!result.ok()) FUZZ_CHECK(result.column <= text.size());
    check_events(events, alphabet, last_time_ms);
    all = events;
  } else {
    while (!text.empty()) {
      const size_t end = text.find('\n');
      const std::string_view line = text.substr(0, end);
      text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
      std::vector<pfap::TextEvent> events;
      const pfap::MarksResult result = reader.read_line(line, events);
      if (!result.ok()) {
        FUZZ_CHECK(events.empty());
        FUZZ_CHECK(result.column <= line.size());
        continue;
      }
      check_events(events, alphabet, last_time_ms);
      all.insert(all.end(), events.begin(), events.end());
    }
    std::vector<pfap::TextEvent> last;
    reader.finish(last);
    check_events(last, alphabet, last_time_ms);
    all.insert(all.end(), last.begin(), last.end());
  }
  write_all(all, alphabet);
  return 0;
}
