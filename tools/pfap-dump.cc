// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap-dump: decodes PFAP payloads and prints what they carry, one line per descriptor.
//
// Input (a file, or standard input with "-"): one payload per line in hex, white space
// allowed between bytes, '#' starts a comment. A payload that does not decode is reported
// with its error class and byte offset and skipped; the rest still decode. The exit status
// is 0 when every payload decoded, 1 when some did not, 2 on a usage or input error.
#include <cctype>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "command_line.h"
#include "pfap/bookmark.h"
#include "pfap/payload.h"

namespace {

std::optional<std::vector<uint8_t>> parse_hex(const std::string& line) {
  std::vector<uint8_t> bytes;
  int high = -1;
  for (char c : line) {
    if (c == '#') break;
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    if (!std::isxdigit(static_cast<unsigned char>(c))) return std::nullopt;
    const int nibble =
        std::isdigit(static_cast<unsigned char>(c)) ? c - '0' : (std::tolower(c) - 'a' + 10);
    if (high < 0) {
      high = nibble;
    } else {
      bytes.push_back(static_cast<uint8_t>(high << 4 | nibble));
      high = -1;
    }
  }
  if (high >= 0) return std::nullopt;
  return bytes;
}

const char* kind_name(const pfap::Packet& packet) {
  switch (packet.recovery_kind) {
    case pfap::RecoveryKind::kNone:
      return "no recovery";
    case pfap::RecoveryKind::kDynamic:
      return "dynamic recovery";
    case pfap::RecoveryKind::kComplete:
      return "complete recovery";
  }
  return "";
}

void print(const pfap::Packet& packet) {
  std::string line;
  std::printf("  %s", kind_name(packet));
  if (packet.recovery_kind == pfap::RecoveryKind::kDynamic) {
    std::printf(" covering %u previous packet%s", packet.covered_packets,
                packet.covered_packets == 1 ? "" : "s");
  }
  if (!packet.recovery.empty()) {
    line.clear();
    pfap::format_bookmarks(packet.recovery, line);
    std::printf(": %s", line.c_str());
  }
  std::printf("\n");
  for (size_t i = 0; i < packet.phonemes.size(); ++i) {
    const pfap::Phoneme& p = packet.phonemes[i].phoneme;
    line.clear();
    pfap::format_bookmarks(packet.faps_of(i), line);
    std::printf("  phoneme %3u %4u ms %3u Hz %c%c%c %s\n", p.symbol, p.duration_ms, p.f0_hz(),
                p.stress ? 'S' : '-', p.word_begin ? 'W' : '-', p.end_of_text ? 'E' : '-',
                line.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  // No options of its own; it runs no GStreamer, so it takes none of GStreamer's.
  const GOptionEntry entries[] = {{}};
  if (const int status = parse_command_line(
          &argc, &argv, "FILE|-",
          "Decodes PFAP payloads, one per line in hex ('#' starts a comment), from FILE or\n"
          "standard input (-), and prints every descriptor. Exit status: 0 when every payload\n"
          "decoded, 1 when some did not, 2 on a usage or input error.",
          entries, nullptr);
      status != 0) {
    return status;
  }
  if (argc != 2) return usage_error("wants one FILE, or - for standard input");
  const std::string path = argv[1];
  std::ifstream file;
  if (path != "-") {
    file.open(path);
    if (!file) {
      std::fprintf(stderr, "pfap-dump: cannot open %s\n", path.c_str());
      return 2;
    }
  }
  std::istream& in = path == "-" ? std::cin : file;

  pfap::Packet packet;
  unsigned decoded = 0, malformed = 0;
  std::string line;
  for (unsigned line_number = 1; std::getline(in, line); ++line_number) {
    const std::optional<std::vector<uint8_t>> bytes = parse_hex(line);
    if (!bytes) {
      std::fprintf(stderr, "pfap-dump: line %u: not hex bytes\n", line_number);
      return 2;
    }
    if (bytes->empty()) continue;
    const pfap::DecodeResult result = pfap::decode_payload(*bytes, packet);
    if (!result.ok()) {
      ++malformed;
      std::printf("line %u: %zu bytes: dropped: %s at byte %u\n", line_number, bytes->size(),
                  pfap::to_string(result.status), result.offset);
      continue;
    }
    ++decoded;
    std::printf("line %u: %zu bytes\n", line_number, bytes->size());
    print(packet);
  }
  std::printf("%u payloads decoded, %u dropped as malformed\n", decoded, malformed);
  return malformed == 0 ? 0 : 1;
}
