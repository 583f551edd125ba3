// SPDX-License-Identifier: LGPL-2.1-or-later
#include "json.h"

#include <cstring>

#include "pfap/utf8.h"

namespace pfap::json {
namespace {

class Parser {
 public:
  explicit Parser(std::string_view text) : text_(text) {}

  bool document(Value& out, Error& error) {
    skip_space();
    if (!value(out, 0)) {
      error = error_;
      return false;
    }
    skip_space();
    if (pos_ != text_.size()) {
      error = {pos_, "text after the JSON value"};
      return false;
    }
    return true;
  }

 private:
  bool fail(const char* what) {
    error_ = {pos_, what};
    return false;
  }

  void skip_space() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t' ||
                                   text_[pos_] == '\n' || text_[pos_] == '\r')) {
      ++pos_;
    }
  }

  bool literal(std::string_view word) {
    if (text_.substr(pos_, word.size()) != word) return fail("not a JSON value");
    pos_ += word.size();
    return true;
  }

  bool value(Value& out, int depth) {
    if (depth > kMaxDepth) return fail("nested deeper than 16");
    if (++values_ > kMaxValues) return fail("more than 400000 values");
    out.offset = pos_;
    if (pos_ >= text_.size()) return fail("the text ends where a value should be");
    switch (text_[pos_]) {
      case '{':
        out.type = Value::Type::kObject;
        return object(out, depth);
      case '[':
        out.type = Value::Type::kArray;
        return array(out, depth);
      case '"':
        out.type = Value::Type::kString;
        return string(out.text);
      case 't':
        out.type = Value::Type::kBool;
        out.boolean = true;
        return literal("true");
      case 'f':
        out.type = Value::Type::kBool;
        return literal("false");
      case 'n':
        out.type = Value::Type::kNull;
        return literal("null");
      default:
        out.type = Value::Type::kNumber;
        return number(out.text);
    }
  }

  bool object(Value& out, int depth) {
    ++pos_;
    skip_space();
    if (pos_ < text_.size() && text_[pos_] == '}') {
      ++pos_;
      return true;
    }
    for (;;) {
      skip_space();
      if (pos_ >= text_.size() || text_[pos_] != '"') return fail("expected a member name");
      Member member;
      if (!string(member.name)) return false;
      skip_space();
      if (pos_ >= text_.size() || text_[pos_] != ':') return fail("expected ':'");
      ++pos_;
      skip_space();
      if (!value(member.value, depth + 1)) return false;
      out.members.push_back(std::move(member));
      skip_space();
      if (pos_ < text_.size() && text_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (pos_ < text_.size() && text_[pos_] == '}') {
        ++pos_;
        return true;
      }
      return fail("expected ',' or '}'");
    }
  }

  bool array(Value& out, int depth) {
    ++pos_;
    skip_space();
    if (pos_ < text_.size() && text_[pos_] == ']') {
      ++pos_;
      return true;
    }
    for (;;) {
      skip_space();
      out.items.emplace_back();
      if (!value(out.items.back(), depth + 1)) return false;
      skip_space();
      if (pos_ < text_.size() && text_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (pos_ < text_.size() && text_[pos_] == ']') {
        ++pos_;
        return true;
      }
      return fail("expected ',' or ']'");
    }
  }

  bool digits() {
    const size_t start = pos_;
    while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') ++pos_;
    return pos_ > start;
  }

  bool number(std::string& out) {
    const size_t start = pos_;
    if (pos_ < text_.size() && text_[pos_] == '-') ++pos_;
    if (pos_ < text_.size() && text_[pos_] == '0') {
      ++pos_;
    } else if (!digits()) {
      return fail("not a JSON value");
    }
    if (pos_ < text_.size() && text_[pos_] == '.') {
      ++pos_;
      if (!digits()) return fail("a number's fraction has no digits");
    }
    if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
      ++pos_;
      if (pos_ < text_.size() && (text_[pos_] == '+' || text_[pos_] == '-')) ++pos_;
      if (!digits()) return fail("a number's exponent has no digits");
    }
    out.assign(text_.substr(start, pos_ - start));
    return true;
  }

  bool hex4(uint32_t& out) {
    if (text_.size() - pos_ < 4) return fail("a \\u escape needs 4 hex digits");
    out = 0;
    for (int i = 0; i < 4; ++i) {
      const char c = text_[pos_++];
      out <<= 4;
      if (c >= '0' && c <= '9') {
        out |= c - '0';
      } else if (c >= 'a' && c <= 'f') {
        out |= c - 'a' + 10;
      } else if (c >= 'A' && c <= 'F') {
        out |= c - 'A' + 10;
      } else {
        --pos_;
        return fail("a \\u escape needs 4 hex digits");
      }
    }
    return true;
  }

  // One UTF-8 sequence at pos_, checked (no overlongs, surrogates or code points past
  // U+10FFFF), copied to `out`.
  bool utf8(std::string& out) {
    const auto byte = [this](size_t i) { return static_cast<unsigned char>(text_[pos_ + i]); };
    const unsigned char lead = byte(0);
    size_t length = 0;
    uint32_t c = 0;
    if (lead >= 0xC2 && lead <= 0xDF) {
      length = 2, c = lead & 0x1F;
    } else if (lead >= 0xE0 && lead <= 0xEF) {
      length = 3, c = lead & 0x0F;
    } else if (lead >= 0xF0 && lead <= 0xF4) {
      length = 4, c = lead & 0x07;
    } else {
      return fail("invalid UTF-8");
    }
    if (text_.size() - pos_ < length) return fail("invalid UTF-8");
    for (size_t i = 1; i < length; ++i) {
      if ((byte(i) & 0xC0) != 0x80) return fail("invalid UTF-8");
      c = (c << 6) | (byte(i) & 0x3F);
    }
    const uint32_t min = length == 2 ? 0x80 : length == 3 ? 0x800 : 0x10000;
    if (c < min || c > 0x10FFFF || (c >= 0xD800 && c <= 0xDFFF)) return fail("invalid UTF-8");
    out.append(text_.substr(pos_, length));
    pos_ += length;
    return true;
  }

  bool string(std::string& out) {
    ++pos_;  // the opening quote
    for (;;) {
      if (pos_ >= text_.size()) return fail("a string is not closed");
      const unsigned char c = static_cast<unsigned char>(text_[pos_]);
      if (c == '"') {
        ++pos_;
        return true;
      }
      if (c < 0x20) return fail("a control character in a string");
      if (c >= 0x80) {
        if (!utf8(out)) return false;
        continue;
      }
      if (c != '\\') {
        out += static_cast<char>(c);
        ++pos_;
        continue;
      }
      if (++pos_ >= text_.size()) return fail("a string is not closed");
      const char escape = text_[pos_++];
      switch (escape) {
        case '"':
        case '\\':
        case '/':
          out += escape;
          break;
        case 'b':
          out += '\b';
          break;
        case 'f':
          out += '\f';
          break;
        case 'n':
          out += '\n';
          break;
        case 'r':
          out += '\r';
          break;
        case 't':
          out += '\t';
          break;
        case 'u': {
          uint32_t code = 0;
          if (!hex4(code)) return false;
          if (code >= 0xD800 && code <= 0xDBFF) {
            uint32_t low = 0;
            if (text_.substr(pos_, 2) != "\\u") return fail("a lone surrogate in \\u escapes");
            pos_ += 2;
            if (!hex4(low)) return false;
            if (low < 0xDC00 || low > 0xDFFF) return fail("a lone surrogate in \\u escapes");
            code = 0x10000 + ((code - 0xD800) << 10) + (low - 0xDC00);
          } else if (code >= 0xDC00 && code <= 0xDFFF) {
            return fail("a lone surrogate in \\u escapes");
          }
          encode_utf8(code, out);
          break;
        }
        default:
          --pos_;
          return fail("an unknown escape in a string");
      }
    }
  }

  std::string_view text_;
  size_t pos_ = 0;
  size_t values_ = 0;
  Error error_;
};

}  // namespace

const Value* Value::get(std::string_view key) const {
  for (const Member& member : members) {
    if (member.name == key) return &member.value;
  }
  return nullptr;
}

bool parse(std::string_view text, Value& out, Error& error) {
  out = Value{};
  return Parser(text).document(out, error);
}

std::optional<int64_t> to_fixed(std::string_view number, int decimals, int64_t limit) {
  size_t i = 0;
  const bool negative = !number.empty() && number[0] == '-';
  if (negative) ++i;
  // The digits, and where the decimal point falls among them.
  std::string digits;
  int point = -1;
  for (; i < number.size() && number[i] != 'e' && number[i] != 'E'; ++i) {
    if (number[i] == '.') {
      if (point >= 0) return std::nullopt;
      point = static_cast<int>(digits.size());
    } else if (number[i] >= '0' && number[i] <= '9') {
      if (digits.size() > 64) return std::nullopt;  // far past any limit
      digits += number[i];
    } else {
      return std::nullopt;
    }
  }
  if (digits.empty()) return std::nullopt;
  if (point < 0) point = static_cast<int>(digits.size());
  int exponent = 0;
  if (i < number.size()) {
    ++i;
    const bool exp_negative = i < number.size() && number[i] == '-';
    if (i < number.size() && (number[i] == '-' || number[i] == '+')) ++i;
    if (i == number.size()) return std::nullopt;
    for (; i < number.size(); ++i) {
      if (number[i] < '0' || number[i] > '9') return std::nullopt;
      exponent = std::min(exponent * 10 + (number[i] - '0'), 1000);
    }
    if (exp_negative) exponent = -exponent;
  }
  // The integer part of value × 10^decimals is digits[0 .. point + exponent + decimals).
  const int whole = point + exponent + decimals;
  int64_t result = 0;
  for (int d = 0; d < whole; ++d) {
    const int digit = d < static_cast<int>(digits.size()) ? digits[d] - '0' : 0;
    if (result > (limit - digit) / 10) return std::nullopt;
    result = result * 10 + digit;
  }
  if (whole >= 0 && whole < static_cast<int>(digits.size()) && digits[whole] >= '5') {
    if (result >= limit) return std::nullopt;
    ++result;
  }
  return negative ? -result : result;
}

void append_string(std::string_view s, std::string& out) {
  static constexpr char kHex[] = "0123456789abcdef";
  out += '"';
  for (const char c : s) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20) {
      out += "\\u00";
      out += kHex[u >> 4];
      out += kHex[u & 0xF];
    } else {
      out += c;
    }
  }
  out += '"';
}

}  // namespace pfap::json
