#include "partsim/core/check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace partsim {

std::string FormatNumber(double value) {
  // the fewest significant digits that read back to the same double; 17 always do
  char buf[32];
  int digits = 1;
  for (; digits < 17; ++digits) {
    std::snprintf(buf, sizeof(buf), "%.*g", digits, value);
    if (std::strtod(buf, nullptr) == value) break;
  }
  // whole numbers up to 17 digits print in full (100, not 1e+02): more digits still read back
  if (std::isfinite(value) && std::abs(value) >= 1) {
    const int whole_digits = static_cast<int>(std::floor(std::log10(std::abs(value)))) + 1;
    if (whole_digits <= 17) digits = std::max(digits, whole_digits);
  }
  std::snprintf(buf, sizeof(buf), "%.*g", digits, value);
  return buf;
}

void CheckPose(const std::string& name, const Pose& pose) {
  if (!pose.IsValid())
    throw Error(name + " must hold finite numbers and a unit quaternion, got " + pose.ToString());
}

namespace internal {

void ThrowUnless(const std::string& message, const char* condition) {
  throw Error(message + " (failed: " + condition + ")");
}

void DemandFailed(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: demand failed: %s\n", file, line, condition);
  std::fflush(stderr);
  std::abort();
}

}  // namespace internal
}  // namespace partsim
