// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap::TextReader on arbitrary text, read line by line as pfaptextparse does. Each event read
// must hold valid values, and its canonical line (format_text_line) must read back to the same
// event; an error must point inside the line and keep nothing from it.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.h"
#include "pfap/text.h"

namespace {

void check_event(const pfap::TextEvent& event) {
  FUZZ_CHECK(event.time_ms >= 0);
  FUZZ_CHECK(!event.event.uncertain);
  for (const pfap::Fap& fap : event.event.faps) FUZZ_CHECK(pfap::is_valid(fap));
  if (event.event.kind == PFAP_EVENT_PHONEME) {
    FUZZ_CHECK(pfap::is_valid(event.event.phoneme));
  } else {
    FUZZ_CHECK(event.event.kind == PFAP_EVENT_RECOVERED ||
               event.event.kind == PFAP_EVENT_COMPLETE);
    FUZZ_CHECK(event.event.phoneme == pfap::Phoneme{});
    FUZZ_CHECK(!event.event.sentence_start);
  }

  std::string line;
  pfap::format_text_line(event, line);
  pfap::TextReader fresh;  // sentence starts depend on the lines before: compare without them
  pfap::TextEvent back;
  bool has_event = false;
  FUZZ_CHECK(fresh.read_line(line, back, has_event).ok());
  FUZZ_CHECK(has_event);
  back.event.sentence_start = event.event.sentence_start;
  FUZZ_CHECK(back == event);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  pfap::TextReader reader;
  int64_t last_time_ms = 0;
  while (!text.empty()) {
    const size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);

    pfap::TextEvent untouched;
    untouched.time_ms = -1;
    pfap::TextEvent event = untouched;
    bool has_event = true;
    const pfap::TextResult result = reader.read_line(line, event, has_event);
    if (!result.ok()) {
      FUZZ_CHECK(!has_event && event == untouched);
      FUZZ_CHECK(result.column <= line.size());
      FUZZ_CHECK((result.status == pfap::TextStatus::kBadBookmark) ==
                 (result.bookmark != pfap::BookmarkStatus::kOk));
      continue;
    }
    if (!has_event) {
      FUZZ_CHECK(event == untouched);
      continue;
    }
    FUZZ_CHECK(event.time_ms >= last_time_ms);
    last_time_ms = event.time_ms;
    check_event(event);
  }
  return 0;
}
