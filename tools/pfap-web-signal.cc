// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap-web-signal.h"

#include <json-glib/json-glib.h>

#include <algorithm>
#include <cstring>

namespace pfap_web {

namespace {

// The deepest nesting of arrays and objects in `text`, outside strings; stops counting past
// `limit`. json-glib checks the rest of the syntax.
int nesting_depth(std::string_view text, int limit) {
  int depth = 0;
  int deepest = 0;
  bool in_string = false;
  bool escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) break;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

enum class Member { kAbsent, kNull, kString, kInteger, kOther };

Member member_type(JsonObject* object, const char* name) {
  JsonNode* node = json_object_get_member(object, name);
  if (node == nullptr) return Member::kAbsent;
  if (JSON_NODE_HOLDS_NULL(node)) return Member::kNull;
  if (!JSON_NODE_HOLDS_VALUE(node)) return Member::kOther;
  const GType type = json_node_get_value_type(node);
  if (type == G_TYPE_STRING) return Member::kString;
  if (type == G_TYPE_INT64) return Member::kInteger;
  return Member::kOther;
}

// A string member: its text in `out`, or false with `error` set.
bool string_member(JsonObject* object, const char* name, size_t max_bytes, std::string& out,
                   std::string& error) {
  if (member_type(object, name) != Member::kString) {
    error = std::string("\"") + name + "\" must be a string";
    return false;
  }
  const char* value = json_object_get_string_member(object, name);
  const size_t size = std::strlen(value);
  if (size > max_bytes) {
    error = std::string("\"") + name + "\" is longer than " + std::to_string(max_bytes) + " bytes";
    return false;
  }
  if (!g_utf8_validate(value, static_cast<gssize>(size), nullptr)) {
    error = std::string("\"") + name + "\" is not UTF-8";
    return false;
  }
  out.assign(value, size);
  return true;
}

bool read_object(JsonObject* m, Signal& signal, std::string& error) {
  std::string type;
  if (!string_member(m, "type", 32, type, error)) return false;
  if (type == "answer") {
    signal.kind = SignalKind::kAnswer;
    if (!string_member(m, "sdp", kMaxSignalBytes, signal.sdp, error)) return false;
    if (signal.sdp.empty()) {
      error = "\"sdp\" is empty";
      return false;
    }
  } else if (type == "ice") {
    signal.kind = SignalKind::kIce;
    if (!string_member(m, "candidate", kMaxCandidateBytes, signal.candidate, error)) {
      return false;
    }
    switch (member_type(m, "sdpMLineIndex")) {
      case Member::kAbsent:
      case Member::kNull:
        signal.mline = 0;
        break;
      case Member::kInteger: {
        const int64_t mline = json_object_get_int_member(m, "sdpMLineIndex");
        if (mline < 0 || mline > kMaxMLineIndex) {
          error = "\"sdpMLineIndex\" must be 0 to " + std::to_string(kMaxMLineIndex);
          return false;
        }
        signal.mline = static_cast<unsigned>(mline);
        break;
      }
      default:
        error = "\"sdpMLineIndex\" must be an integer";
        return false;
    }
  } else if (type == "say") {
    signal.kind = SignalKind::kSay;
    if (!string_member(m, "text", kMaxSayBytes, signal.text, error)) return false;
  } else if (type == "playing") {
    signal.kind = SignalKind::kPlaying;
  } else if (type == "complete") {
    signal.kind = SignalKind::kComplete;
  } else {
    error = "\"type\" must be answer, ice, say, playing or complete";
    return false;
  }
  return true;
}

}  // namespace

bool parse_signal(std::string_view message, Signal& signal, std::string& error) {
  signal = Signal{};
  if (message.size() > kMaxSignalBytes) {
    error = "a message longer than " + std::to_string(kMaxSignalBytes) + " bytes";
    return false;
  }
  if (nesting_depth(message, kMaxSignalDepth) > kMaxSignalDepth) {
    error = "a message nested deeper than " + std::to_string(kMaxSignalDepth);
    return false;
  }
  JsonParser* parser = json_parser_new_immutable();
  bool ok = false;
  if (!json_parser_load_from_data(parser, message.data(), static_cast<gssize>(message.size()),
                                  nullptr)) {
    error = "not JSON";
  } else if (JsonNode* root = json_parser_get_root(parser);
             root == nullptr || !JSON_NODE_HOLDS_OBJECT(root)) {
    error = "not a JSON object";
  } else {
    ok = read_object(json_node_get_object(root), signal, error);
  }
  g_object_unref(parser);
  if (!ok) signal = Signal{};
  return ok;
}

}  // namespace pfap_web
