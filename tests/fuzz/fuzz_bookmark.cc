// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap::parse_bookmark and pfap::parse_bookmarks on arbitrary text. On success every FAP is
// valid, and the FAPs formatted (format_bookmarks) parse back to the same FAPs; on error
// nothing is appended, the position is unchanged and the error points inside the text.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_check.h"
#include "pfap/bookmark.h"

namespace {

// Something already in `out`, that no parse may touch.
const pfap::Fap kBefore{.index = 3, .amplitude = -1, .transition_ms = 1, .curve = pfap::Curve::kSpline};

// `faps` formatted, then read back one bookmark at a time (the formatted form may hold more
// than the 40 bookmarks parse_bookmarks allows).
void check_round_trip(const std::vector<pfap::Fap>& faps) {
  std::string text;
  pfap::format_bookmarks(faps, text);
  std::vector<pfap::Fap> back;
  size_t pos = 0;
  while (pos < text.size()) {
    const size_t before = back.size();
    FUZZ_CHECK(pfap::parse_bookmark(text, pos, back).ok());
    FUZZ_CHECK(back.size() == before + 1);  // the transformed form: one FAP per bookmark
  }
  FUZZ_CHECK(back == faps);
  if (faps.size() <= pfap::kMaxBookmarksPerPhoneme) {
    back.clear();
    FUZZ_CHECK(pfap::parse_bookmarks(text, back).ok());
    FUZZ_CHECK(back == faps);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);

  std::vector<pfap::Fap> faps{kBefore};
  const pfap::BookmarkResult all = pfap::parse_bookmarks(text, faps);
  FUZZ_CHECK(!faps.empty() && faps.front() == kBefore);
  faps.erase(faps.begin());
  if (all.ok()) {
    for (const pfap::Fap& fap : faps) FUZZ_CHECK(pfap::is_valid(fap));
    FUZZ_CHECK(faps.size() <= 2 * pfap::kMaxBookmarksPerPhoneme);
    check_round_trip(faps);
  } else {
    FUZZ_CHECK(faps.empty());
    FUZZ_CHECK(all.position < size);
  }

  // One bookmark at each '<', as a line reader takes them.
  for (size_t start = text.find('<'); start != std::string_view::npos;
       start = text.find('<', start + 1)) {
    std::vector<pfap::Fap> one{kBefore};
    size_t pos = start;
    const pfap::BookmarkResult result = pfap::parse_bookmark(text, pos, one);
    FUZZ_CHECK(one.front() == kBefore);
    if (result.ok()) {
      FUZZ_CHECK(pos > start && pos <= size && text[pos - 1] == '>');
      FUZZ_CHECK(one.size() <= 3);
      one.erase(one.begin());
      for (const pfap::Fap& fap : one) FUZZ_CHECK(pfap::is_valid(fap));
      check_round_trip(one);
    } else {
      FUZZ_CHECK(pos == start && one.size() == 1);
      FUZZ_CHECK(result.position >= start && result.position < size);
    }
  }
  return 0;
}
