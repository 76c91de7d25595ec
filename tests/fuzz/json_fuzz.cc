// libFuzzer target: ParseJsonBounded on arbitrary bytes, as network messages, scene files and
// dataset files reach it. It may throw nlohmann::json::exception and nothing else; what it
// returns nests no deeper than the bound, nor deeper than the depth scan's count (shallower when
// a repeated key replaced a deeper value: {"d": {"s": 1}, "d": "x"} scans 2 and parses to 1),
// and dumps to text that parses back to the same value. scripts/run_fuzz.sh runs it with a
// per-input time limit, so a parse that turns superlinear shows up as a timeout.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/json_parse.h"

namespace {

int Depth(const nlohmann::json& j) {
  int deepest = 0;
  if (j.is_structured())
    for (const nlohmann::json& v : j) deepest = std::max(deepest, Depth(v));
  return j.is_structured() ? deepest + 1 : 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  nlohmann::json j;
  try {
    j = partsim::internal::ParseJsonBounded(text);
  } catch (const nlohmann::json::exception&) {
    return 0;  // malformed or too deep: refused the expected way
  }
  const int depth = Depth(j);
  if (depth > partsim::internal::kMaxJsonDepth) __builtin_trap();
  if (depth > partsim::internal::JsonNestingDepth(text, partsim::internal::kMaxJsonDepth))
    __builtin_trap();
  // invalid UTF-8 inside strings is refused by the parser, so the dump cannot throw; compared as
  // text because a number too large for a double parses to infinity and dumps as null
  const std::string once = j.dump();
  if (partsim::internal::ParseJsonBounded(once).dump() != once) __builtin_trap();
  return 0;
}
