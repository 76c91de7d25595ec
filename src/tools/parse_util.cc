// Command-line parsing shared by the partsim sub-commands.
#include <cerrno>
#include <cstdlib>

#include "commands.h"

namespace partsim::tools {

bool ParseInteger(const std::string& text, long long lo, long long* out) {
  char* end = nullptr;
  errno = 0;
  long long n = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || n < lo) return false;
  *out = n;
  return true;
}

}  // namespace partsim::tools
