// SPDX-License-Identifier: LGPL-2.1-or-later
// MPEG-4 FAP files (docs/fap-files.md).
//
// Line by line: the header, then for each frame a mask line and a value line. Each line is
// checked field by field, left to right, and only a whole good line changes the reader.
#include "pfap/fap_file.h"

#include <charconv>
#include <cstdio>

#include "number.h"
#include "pfap/model.h"

namespace pfap {
namespace {

bool is_field_space(char c) { return c == ' ' || c == '\t'; }

// Splits a line into its white-space separated fields, with their numbers from 1.
class Fields {
 public:
  explicit Fields(std::string_view line) : line_(line) {}
  // The next field, empty at the end of the line.
  std::string_view next() {
    while (pos_ < line_.size() && is_field_space(line_[pos_])) ++pos_;
    const size_t begin = pos_;
    while (pos_ < line_.size() && !is_field_space(line_[pos_])) ++pos_;
    if (pos_ > begin) ++number_;
    return line_.substr(begin, pos_ - begin);
  }
  // The number of the field last returned (from 1), or the next one once the line is over.
  uint32_t number() const { return number_; }
  size_t position() const { return pos_; }

 private:
  std::string_view line_;
  size_t pos_ = 0;
  uint32_t number_ = 0;
};

bool is_blank_or_comment(std::string_view line) {
  size_t i = 0;
  while (i < line.size() && is_field_space(line[i])) ++i;
  return i == line.size() || line[i] == '#';
}

// A decimal number: optional sign, digits, optionally '.' and more digits. Rounded to the
// nearest integer, halves away from zero; `rounded` says whether it had a non-zero fraction.
// Saturates far above every limit, so a range check refuses long digit strings.
bool parse_value(std::string_view text, int64_t& value, bool& rounded) {
  const size_t dot = text.find('.');
  const std::string_view whole = text.substr(0, dot);
  const std::string_view fraction =
      dot == std::string_view::npos ? std::string_view{} : text.substr(dot + 1);
  int64_t integer = 0;
  if (whole == "-" || whole == "+" || whole.empty()) {
    // "-.5" and ".5": digits after the dot only.
    if (fraction.empty()) return false;
  } else if (!parse_decimal(whole, integer)) {
    return false;
  }
  if (dot != std::string_view::npos && fraction.empty()) return false;  // "5."
  bool nonzero = false, half_or_more = false;
  for (size_t i = 0; i < fraction.size(); ++i) {
    if (fraction[i] < '0' || fraction[i] > '9') return false;
    if (fraction[i] != '0') nonzero = true;
    if (i == 0 && fraction[i] >= '5') half_or_more = true;
  }
  const bool negative = !text.empty() && text[0] == '-';
  if (half_or_more) integer += negative ? -1 : 1;
  value = integer;
  rounded = nonzero;
  return true;
}

// The frame rate: a decimal number, as Xface and Greta write it ("25", "25.0", "29.97").
bool parse_rate(std::string_view text, double& rate) {
  for (char c : text) {
    if ((c < '0' || c > '9') && c != '.') return false;  // no sign, exponent, inf or nan
  }
  double parsed = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), parsed);
  if (error != std::errc{} || end != text.data() + text.size()) return false;
  if (!(parsed >= kMinFapFileFrameRate && parsed <= kMaxFapFileFrameRate)) return false;
  rate = parsed;
  return true;
}

// The MPEG-4 range of each field of FAP 1 and FAP 2 (ISO/IEC 14496-2, viseme and expression
// FAPs): select, blend and intensity fields, and the one-bit flags.
constexpr std::array<int32_t, kVisemeFields> kVisemeMax = {14, 14, 63, 1};
constexpr std::array<int32_t, kExpressionFields> kExpressionMax = {6, 63, 6, 63, 1, 1};

FapFileResult error(FapFileStatus status, uint64_t line, uint32_t field, int fap = 0) {
  return {status, line, field, static_cast<uint8_t>(fap)};
}

}  // namespace

const char* to_string(FapFileStatus status) {
  switch (status) {
    case FapFileStatus::kOk:
      return "ok";
    case FapFileStatus::kBadVersion:
      return "unsupported version (2.0 and 2.1 are read)";
    case FapFileStatus::kMissingField:
      return "header without frame rate and frame count";
    case FapFileStatus::kBadName:
      return "name too long";
    case FapFileStatus::kBadFrameRate:
      return "frame rate not a number from 1 to 1000";
    case FapFileStatus::kBadFrameCount:
      return "frame count not an integer from 1 to 360000";
    case FapFileStatus::kBadMaskFlag:
      return "mask flag not 0 or 1";
    case FapFileStatus::kWrongMaskLength:
      return "mask without 68 flags";
    case FapFileStatus::kBadFrameNumber:
      return "frame number not the next frame's";
    case FapFileStatus::kBadValue:
      return "value not a decimal number";
    case FapFileStatus::kValueOutOfRange:
      return "value out of range";
    case FapFileStatus::kMissingValues:
      return "fewer values than the mask sets";
    case FapFileStatus::kExtraValues:
      return "more values than the mask sets";
    case FapFileStatus::kTooManyFrames:
      return "more frames than the header's count";
    case FapFileStatus::kTruncated:
      return "the file ends before the header's count of frames";
    case FapFileStatus::kLineTooLong:
      return "line longer than 65536 bytes";
  }
  return "unknown";
}

std::string describe(const FapFileResult& result) {
  std::string out = "line " + std::to_string(result.line);
  if (result.field != 0) out += ", field " + std::to_string(result.field);
  if (result.fap != 0) out += " (FAP " + std::to_string(result.fap) + ")";
  return out + ": " + to_string(result.status);
}

void FapFileReader::reset() { *this = FapFileReader{}; }

FapFileResult FapFileReader::read_line(std::string_view line, FapFrame& out, bool& has_frame) {
  has_frame = false;
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  const uint64_t number = line_ + 1;
  if (line.size() > kMaxFapFileLineBytes) return error(FapFileStatus::kLineTooLong, number, 0);
  FapFileResult result;
  if (is_blank_or_comment(line)) {
    // Nothing to read.
  } else if (!has_header_) {
    result = read_header(line);
  } else if (!have_mask_) {
    result = read_mask(line);
  } else {
    result = read_values(line, out);
    has_frame = result.ok();
  }
  if (result.ok()) line_ = number;
  return result;
}

FapFileResult FapFileReader::finish() const {
  if (!has_header_) return error(FapFileStatus::kTruncated, line_ + 1, 0);
  if (frames_ < header_.frame_count) return error(FapFileStatus::kTruncated, line_ + 1, 0);
  return {};
}

FapFileResult FapFileReader::read_header(std::string_view line) {
  const uint64_t number = line_ + 1;
  Fields fields(line);
  const std::string_view version = fields.next();
  // 2.1 in every file we know of (Xface, Greta, visage); 2.0 has the same syntax.
  if (version != "2.1" && version != "2.0") {
    return error(FapFileStatus::kBadVersion, number, fields.number());
  }
  // The name is the text between version and the last two fields: Xface's writer puts one
  // word there, its exporters a Windows path, which could hold spaces.
  struct Span {
    size_t begin, end;
  };
  std::vector<Span> rest;
  for (std::string_view f = fields.next(); !f.empty(); f = fields.next()) {
    rest.push_back({fields.position() - f.size(), fields.position()});
  }
  const uint32_t count_field = fields.number();
  if (rest.size() < 3) return error(FapFileStatus::kMissingField, number, count_field + 1);
  auto text_of = [line](Span s) { return line.substr(s.begin, s.end - s.begin); };
  const std::string_view rate_text = text_of(rest[rest.size() - 2]);
  const std::string_view count_text = text_of(rest.back());
  const std::string_view name = text_of({rest.front().begin, rest[rest.size() - 3].end});
  if (name.size() > kMaxFapFileNameBytes) return error(FapFileStatus::kBadName, number, 2);
  FapFileHeader header;
  header.version = version;
  header.name = name;
  if (!parse_rate(rate_text, header.frame_rate)) {
    return error(FapFileStatus::kBadFrameRate, number, count_field - 1);
  }
  int64_t count = 0;
  if (!parse_decimal(count_text, count) || count < 1 || count > kMaxFapFileFrames) {
    return error(FapFileStatus::kBadFrameCount, number, count_field);
  }
  header.frame_count = static_cast<uint32_t>(count);
  header_ = std::move(header);
  has_header_ = true;
  return {};
}

FapFileResult FapFileReader::read_mask(std::string_view line) {
  const uint64_t number = line_ + 1;
  if (frames_ == header_.frame_count) return error(FapFileStatus::kTooManyFrames, number, 1);
  std::array<bool, kFapFileFaps + 1> mask{};
  Fields fields(line);
  int fap = 0;
  for (std::string_view f = fields.next(); !f.empty(); f = fields.next()) {
    if (++fap > kFapFileFaps)
      return error(FapFileStatus::kWrongMaskLength, number, fields.number());
    if (f != "0" && f != "1")
      return error(FapFileStatus::kBadMaskFlag, number, fields.number(), fap);
    mask[fap] = f == "1";
  }
  if (fap != kFapFileFaps)
    return error(FapFileStatus::kWrongMaskLength, number, fields.number() + 1);
  mask_ = mask;
  have_mask_ = true;
  return {};
}

FapFileResult FapFileReader::read_values(std::string_view line, FapFrame& out) {
  const uint64_t number = line_ + 1;
  Fields fields(line);
  FapFrame frame;
  int64_t frame_number = 0;
  if (!parse_decimal(fields.next(), frame_number) || frame_number != frames_) {
    return error(FapFileStatus::kBadFrameNumber, number, 1);
  }
  frame.number = frames_;
  frame.set = mask_;
  // Reads the next value into `value`, within -max..max (or 0..max when `unsigned_only`).
  auto next_value = [&](int fap, int64_t min, int64_t max, int32_t& value) -> FapFileResult {
    const std::string_view text = fields.next();
    if (text.empty()) return error(FapFileStatus::kMissingValues, number, fields.number() + 1, fap);
    int64_t parsed = 0;
    bool rounded = false;
    if (!parse_value(text, parsed, rounded)) {
      return error(FapFileStatus::kBadValue, number, fields.number(), fap);
    }
    if (parsed < min || parsed > max) {
      return error(FapFileStatus::kValueOutOfRange, number, fields.number(), fap);
    }
    value = static_cast<int32_t>(parsed);
    if (rounded) ++frame.rounded;
    return {};
  };
  for (int fap = 1; fap <= kFapFileFaps; ++fap) {
    if (!mask_[fap]) continue;
    FapFileResult result;
    if (fap == kVisemeFap) {
      for (int i = 0; i < kVisemeFields && result.ok(); ++i) {
        result = next_value(fap, 0, kVisemeMax[i], frame.viseme[i]);
      }
    } else if (fap == kExpressionFap) {
      for (int i = 0; i < kExpressionFields && result.ok(); ++i) {
        result = next_value(fap, 0, kExpressionMax[i], frame.expression[i]);
      }
    } else {
      result = next_value(fap, -kMaxAmplitude, kMaxAmplitude, frame.value[fap]);
    }
    if (!result.ok()) return result;
  }
  if (!fields.next().empty()) return error(FapFileStatus::kExtraValues, number, fields.number());
  have_mask_ = false;
  ++frames_;
  out = frame;
  return {};
}

FapFileResult read_fap_file(std::string_view text, FapFile& out) {
  FapFileReader reader;
  FapFile file;
  FapFrame frame;
  while (!text.empty()) {
    const size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    if (line.size() > kMaxFapFileLineBytes + 1) {  // + 1: a '\r' the reader drops
      return error(FapFileStatus::kLineTooLong, reader.line() + 1, 0);
    }
    bool has_frame = false;
    const FapFileResult result = reader.read_line(line, frame, has_frame);
    if (!result.ok()) return result;
    if (has_frame) file.frames.push_back(frame);
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  const FapFileResult result = reader.finish();
  if (!result.ok()) return result;
  file.header = reader.header();
  out = std::move(file);
  return {};
}

void format_fap_header(const FapFileHeader& header, std::string& out) {
  std::string name = header.name.empty() ? "pfap" : header.name;
  for (char& c : name) {
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') c = '_';
  }
  // Enough digits for any rate a double holds that is not a whole number (29.97).
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.10g", header.frame_rate);
  out += header.version.empty() ? "2.1" : header.version;
  out += ' ';
  out += name;
  out += ' ';
  out += rate;
  out += ' ';
  out += std::to_string(header.frame_count);
  out += '\n';
}

void format_fap_frame(const FapFrame& frame, std::string& out) {
  for (int fap = 1; fap <= kFapFileFaps; ++fap) {
    out += frame.set[fap] ? '1' : '0';
    out += fap == kFapFileFaps ? '\n' : ' ';
  }
  out += std::to_string(frame.number);
  auto append = [&out](int32_t value) {
    out += ' ';
    out += std::to_string(value);
  };
  for (int fap = 1; fap <= kFapFileFaps; ++fap) {
    if (!frame.set[fap]) continue;
    if (fap == kVisemeFap) {
      for (int32_t v : frame.viseme) append(v);
    } else if (fap == kExpressionFap) {
      for (int32_t v : frame.expression) append(v);
    } else {
      append(frame.value[fap]);
    }
  }
  out += '\n';
}

std::string write_fap_file(const FapFile& file) {
  std::string out;
  format_fap_header(file.header, out);
  for (const FapFrame& frame : file.frames) format_fap_frame(frame, out);
  return out;
}

}  // namespace pfap
