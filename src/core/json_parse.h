// Parsing JSON from outside (network messages, scene files, dataset files) with a bound on its
// nesting: a deeper document is refused while it is parsed, before a deep tree exists whose
// copy, serialisation or destruction would recurse that deep and overflow the stack.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace partsim::internal {

/// Deepest nesting of arrays and objects accepted: real files and ROS messages nest a handful.
constexpr int kMaxJsonDepth = 64;

/// Parses `text`; throws nlohmann::json::exception when it is malformed or nested deeper than
/// `max_depth` levels ("nested deeper than N levels").
inline nlohmann::json ParseJsonBounded(const std::string& text, int max_depth = kMaxJsonDepth) {
  nlohmann::json::parser_callback_t depth_guard =
      [max_depth](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
        if (depth > max_depth)
          throw nlohmann::json::out_of_range::create(
              406, "nested deeper than " + std::to_string(max_depth) + " levels", nullptr);
        return true;
      };
  return nlohmann::json::parse(text, depth_guard);
}

}  // namespace partsim::internal
