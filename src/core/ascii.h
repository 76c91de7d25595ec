// ASCII case folding for names that formats compare without case (file extensions, keywords,
// HTTP header names): bytes outside A-Z are left as they are, whatever the locale.
#pragma once

#include <string>
#include <string_view>

namespace partsim::internal {

/// `s` with A-Z turned into a-z.
inline std::string AsciiLower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

}  // namespace partsim::internal
