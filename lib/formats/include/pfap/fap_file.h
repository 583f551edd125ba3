// SPDX-License-Identifier: LGPL-2.1-or-later
// MPEG-4 FAP files (.fap, the FBA text format of Xface, Greta and other MPEG-4 face players):
// reading, writing, and the limits that keep hostile files small. docs/fap-files.md.
//
//   2.1 name 25 108                      version, name, frame rate, frame count
//   0 0 1 1 0 ... (68 flags)             mask: which of FAPs 1..68 the next line sets
//   0 10 -4 ...                          frame number, then the values the mask sets
//   ...                                  a mask line and a value line per frame
//
// FAP 1 (viseme) takes 4 values: select1 select2 blend def; FAP 2 (expression) takes 6:
// select1 intensity1 select2 intensity2 init_face def; every other FAP one. Lines whose first
// non-blank byte is '#' are comments; blank lines are skipped; fields are separated by spaces
// or tabs; a line ends at "\n" or "\r\n".
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pfap {

inline constexpr int kFapFileFaps = 68;  // mask flags per frame: FAPs 1..68
inline constexpr int kVisemeFap = 1;
inline constexpr int kExpressionFap = 2;
inline constexpr int kVisemeFields = 4;
inline constexpr int kExpressionFields = 6;

// Hard limits against hostile files. A real frame's lines are under 1 KiB; 360000 frames are
// 4 hours at 25 frames/s, 1 hour at 100.
inline constexpr size_t kMaxFapFileLineBytes = 64 * 1024;
inline constexpr uint32_t kMaxFapFileFrames = 360'000;
// One frame per ms at most (the draft's times are whole ms); at least one a second.
inline constexpr double kMinFapFileFrameRate = 1.0;
inline constexpr double kMaxFapFileFrameRate = 1000.0;
inline constexpr size_t kMaxFapFileNameBytes = 1024;

enum class FapFileStatus : uint8_t {
  kOk = 0,
  kBadVersion,       // not a version this reader accepts (2.0 or 2.1)
  kMissingField,     // the header line ends before frame rate and frame count
  kBadName,          // the name is longer than kMaxFapFileNameBytes
  kBadFrameRate,     // not a number in kMinFapFileFrameRate..kMaxFapFileFrameRate
  kBadFrameCount,    // not an integer in 1..kMaxFapFileFrames
  kBadMaskFlag,      // a mask field that is not 0 or 1
  kWrongMaskLength,  // a mask line without exactly 68 flags
  kBadFrameNumber,   // not the number of this frame (consecutive from 0)
  kBadValue,         // a value that is not a decimal number
  kValueOutOfRange,  // |value| over the draft's 2529600, or a viseme or expression
                     // field outside its MPEG-4 range
  kMissingValues,    // fewer values than the mask sets
  kExtraValues,      // more values than the mask sets
  kTooManyFrames,    // a frame after the header's count
  kTruncated,        // the file ends before the header's count of frames
  kLineTooLong,      // a line over kMaxFapFileLineBytes
};

const char* to_string(FapFileStatus status);

struct FapFileResult {
  FapFileStatus status = FapFileStatus::kOk;
  uint64_t line = 0;   // from 1
  uint32_t field = 0;  // from 1, white-space separated; 0 for the whole line
  uint8_t fap = 0;     // the FAP whose flag or value is at fault, 0 when none

  bool ok() const { return status == FapFileStatus::kOk; }
};

// "line 5, field 12 (FAP 13): value out of range", for error messages.
std::string describe(const FapFileResult& result);

struct FapFileHeader {
  std::string version;  // as written: "2.1"
  std::string name;     // the text between version and frame rate
  double frame_rate = 25.0;
  uint32_t frame_count = 0;

  bool operator==(const FapFileHeader&) const = default;
};

struct FapFrame {
  uint32_t number = 0;
  std::array<bool, kFapFileFaps + 1> set{};             // indexed by FAP 1..68; [0] unused
  std::array<int32_t, kFapFileFaps + 1> value{};        // the value of each set FAP 3..68
  std::array<int32_t, kVisemeFields> viseme{};          // when FAP 1 is set
  std::array<int32_t, kExpressionFields> expression{};  // when FAP 2 is set
  uint32_t rounded = 0;  // values written with a fraction, rounded to whole units

  bool operator==(const FapFrame&) const = default;
};

struct FapFile {
  FapFileHeader header;
  std::vector<FapFrame> frames;
};

// Reads a FAP file line by line, keeping what spans lines (the header, mask, frame number).
class FapFileReader {
 public:
  // Reads one line, without its "\n" (a final '\r' is dropped). `has_frame` says whether the
  // line finished a frame, now in `out`. On error the reader stays where it was.
  FapFileResult read_line(std::string_view line, FapFrame& out, bool& has_frame);
  // At the end of the input: an error if frames are missing.
  FapFileResult finish() const;
  // The header, once its line is read.
  const FapFileHeader& header() const { return header_; }
  bool has_header() const { return has_header_; }
  uint64_t line() const { return line_; }
  void reset();

 private:
  FapFileResult read_header(std::string_view line);
  FapFileResult read_mask(std::string_view line);
  FapFileResult read_values(std::string_view line, FapFrame& out);

  FapFileHeader header_;
  bool has_header_ = false;
  bool have_mask_ = false;
  std::array<bool, kFapFileFaps + 1> mask_{};
  uint32_t frames_ = 0;  // frames read
  uint64_t line_ = 0;    // lines read
};

// A whole file in memory. Lines over kMaxFapFileLineBytes are refused before they are read.
FapFileResult read_fap_file(std::string_view text, FapFile& out);

// The header line and each frame's two lines, each ending in "\n". Values are integers; the
// name is written with its white space as '_', since readers take it as one field.
void format_fap_header(const FapFileHeader& header, std::string& out);
void format_fap_frame(const FapFrame& frame, std::string& out);
std::string write_fap_file(const FapFile& file);

}  // namespace pfap
