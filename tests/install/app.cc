// SPDX-License-Identifier: LGPL-2.1-or-later
// An application of libpfap built against an installed pfap.pc (scripts/check-install):
// g++ -std=c++20 app.cc $(pkg-config --cflags --libs pfap). Parses MPEG-4 bookmarks and
// prints them back in the transformed form; exit status 0 when they read back the same.
#include <pfap/bookmark.h>

#include <cstdio>
#include <string>
#include <vector>

int main() {
  const std::string text = "<FAP 3 300 500 1><FAP 2 1 40 0 0 500 1>";
  std::vector<pfap::Fap> faps;
  const pfap::BookmarkResult result = pfap::parse_bookmarks(text, faps);
  if (!result.ok()) {
    std::printf("parse_bookmarks: %s at %zu\n", pfap::to_string(result.status), result.position);
    return 1;
  }
  std::string formatted;
  pfap::format_bookmarks(faps, formatted);
  std::vector<pfap::Fap> again;
  if (!pfap::parse_bookmarks(formatted, again).ok() || again != faps) {
    std::printf("read back differently: %s\n", formatted.c_str());
    return 1;
  }
  std::printf("%zu FAPs: %s\n", faps.size(), formatted.c_str());
  return 0;
}
