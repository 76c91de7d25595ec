// Reading the fields of the vision layer's JSON files (COCO ground truth and results, motion
// labels) with messages that name the file, the entry and the key at fault.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "core/file_read.h"
#include "core/json_parse.h"
#include "partsim/core/error.h"

namespace partsim::vision::internal {

using nlohmann::json;

/// A value as short JSON text for a message: at most 60 characters.
inline std::string Describe(const json& value) {
  std::string text = value.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

/// The document `text`; throws Error "`source`: not valid JSON: ..." when it does not parse.
inline json ParseDocument(const std::string& text, const std::string& source) {
  try {
    return partsim::internal::ParseJsonBounded(text);
  } catch (const json::exception& e) {
    throw Error(source + ": not valid JSON: " + e.what());
  }
}

/// The text of the file at `path` (what: "COCO ground truth", ...), through ReadWholeFile.
inline std::string ReadDocument(const std::string& path, const std::string& what) {
  return partsim::internal::ReadWholeFile(path, what);
}

/// `object[key]`; throws Error "`where`: missing key 'key'" (or "is not an object").
inline const json& Field(const json& object, const char* key, const std::string& where) {
  if (!object.is_object()) throw Error(where + ": expected an object, got " + Describe(object));
  auto it = object.find(key);
  if (it == object.end()) throw Error(where + ": missing key '" + key + "'");
  return *it;
}

/// `object[key]` as an array; throws Error naming `where` and the key.
inline const json& ArrayField(const json& object, const char* key, const std::string& where) {
  const json& value = Field(object, key, where);
  if (!value.is_array())
    throw Error(where + ": '" + key + "' must be an array, got " + Describe(value));
  return value;
}

/// `value` as a whole number (an integer, or a float with a whole value below 2^53); throws
/// Error "`what` must be an integer, got ...".
inline std::int64_t AsInteger(const json& value, const std::string& what) {
  if (value.is_number_unsigned()) {
    if (value.get<std::uint64_t>() <=
        static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      return static_cast<std::int64_t>(value.get<std::uint64_t>());
  } else if (value.is_number_integer()) {
    return value.get<std::int64_t>();
  } else if (value.is_number_float()) {
    const double d = value.get<double>();
    if (std::isfinite(d) && d == std::floor(d) && std::fabs(d) < 9007199254740992.0)
      return static_cast<std::int64_t>(d);
  }
  throw Error(what + " must be an integer, got " + Describe(value));
}

/// `value` as a finite number; throws Error "`what` must be a finite number, got ...".
inline double AsNumber(const json& value, const std::string& what) {
  if (value.is_number()) {
    const double d = value.get<double>();
    if (std::isfinite(d)) return d;
  }
  throw Error(what + " must be a finite number, got " + Describe(value));
}

/// `value` as a string; throws Error "`what` must be a string, got ...".
inline std::string AsString(const json& value, const std::string& what) {
  if (!value.is_string()) throw Error(what + " must be a string, got " + Describe(value));
  return value.get<std::string>();
}

}  // namespace partsim::vision::internal
