// Parsing JSON from outside (network messages, scene files, dataset files) with a bound on its
// nesting: a deeper document is refused before it is parsed, before a deep tree exists whose
// copy, serialisation or destruction would recurse that deep and overflow the stack. Both steps
// are linear in the size of the text. Also the JSON text helpers every layer shares (DumpJson,
// Base64).
#pragma once

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace partsim::internal {

/// Deepest nesting of arrays and objects accepted: real files and ROS messages nest a handful.
constexpr int kMaxJsonDepth = 64;

/// Deepest nesting of arrays and objects in `text`, stopping early once it passes `stop_above`;
/// brackets inside strings and after a NUL byte (which ends the parser's input) do not count.
/// One pass over the bytes: it does not check that `text` is valid JSON (the parser does that).
inline int JsonNestingDepth(const std::string& text, int stop_above) {
  int depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (const char ch : text) {
    if (ch == '\0') break;  // where nlohmann's parser ends the input too
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (ch == '\\')
        escaped = true;
      else if (ch == '"')
        in_string = false;
    } else if (ch == '"') {
      in_string = true;
    } else if (ch == '[' || ch == '{') {
      if (++depth > deepest && (deepest = depth) > stop_above) break;
    } else if ((ch == ']' || ch == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

/// Parses `text`; throws nlohmann::json::exception when it is malformed or nested deeper than
/// `max_depth` levels ("nested deeper than N levels"). The size is the caller's to bound.
inline nlohmann::json ParseJsonBounded(const std::string& text, int max_depth = kMaxJsonDepth) {
  // the depth first, in one pass; then nlohmann's plain parser, whose callback variant rescans
  // the enclosing container at every closing bracket (quadratic in the number of containers)
  if (JsonNestingDepth(text, max_depth) > max_depth)
    throw nlohmann::json::out_of_range::create(
        406, "nested deeper than " + std::to_string(max_depth) + " levels", nullptr);
  return nlohmann::json::parse(text);
}

/// Text of a JSON value; bytes that are not UTF-8 (a client's string quoted back in an error)
/// become U+FFFD instead of throwing.
inline std::string DumpJson(const nlohmann::json& j) {
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

/// Base64 (RFC 4648, padded) of `n` bytes: how rosbridge sends uint8[] fields and the viewer its
/// pictures as JSON text.
inline std::string Base64(const uint8_t* data, size_t n) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((n + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < n; i += 3) {
    uint32_t v = (uint32_t(data[i]) << 16) | (uint32_t(data[i + 1]) << 8) | data[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  // the last one or two bytes, padded with '='
  if (i < n) {
    uint32_t v = uint32_t(data[i]) << 16;
    if (i + 1 < n) v |= uint32_t(data[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < n ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

}  // namespace partsim::internal
