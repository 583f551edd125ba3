// SPDX-License-Identifier: LGPL-2.1-or-later
// A small JSON reader and string writer for the speech-mark formats (pfap/speech_marks.h).
// Internal to libpfap, not installed. Strict RFC 8259, with hard limits on depth and size.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pfap::json {

inline constexpr int kMaxDepth = 16;
// Bounds the memory of a document's tree (about 100 bytes a value): 100,000 Rhubarb cues.
inline constexpr size_t kMaxValues = 400'000;

struct Member;

struct Value {
  enum class Type : uint8_t { kNull, kBool, kNumber, kString, kArray, kObject };
  Type type = Type::kNull;
  bool boolean = false;
  std::string text;      // a string's value (UTF-8), or a number as written
  size_t offset = 0;     // where the value starts in the document, in bytes
  std::vector<Value> items;                           // an array's
  std::vector<Member> members;  // an object's, in document order

  // The member `key` of an object (the first, if repeated); nullptr if none.
  const Value* get(std::string_view key) const;
};

struct Member {
  std::string name;
  Value value;
};

struct Error {
  size_t offset = 0;  // in bytes, where the fault was found
  const char* what = "";
};

// Parses one JSON value filling all of `text` (white space around it allowed). Strings must
// be valid UTF-8; nesting deeper than kMaxDepth, or more than kMaxValues values, is refused.
bool parse(std::string_view text, Value& out, Error& error);

// A JSON number as an integer count of 10^-decimals units: "1.25" with decimals 3 is 1250.
// Digits past `decimals` round half up; exponents are accepted. None when the text is not a
// number or the result is past +-limit.
std::optional<int64_t> to_fixed(std::string_view number, int decimals, int64_t limit);

// Appends `s` as a JSON string, quotes included.
void append_string(std::string_view s, std::string& out);

}  // namespace pfap::json
