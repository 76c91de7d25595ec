// Text of numbers, one family for all of partsim: exact text for the files partsim writes (MJCF,
// URDF, scene files) and rounded text for messages, tables and reports. The shortest text that
// reads back to the same double, for messages that quote a value, is FormatNumber
// (partsim/core/check.h).
#pragma once

#include <Eigen/Core>
#include <cstdio>
#include <string>

namespace partsim::internal {

/// "%.17g": reads back bit-exact.
inline std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

/// "x y z" with Num.
inline std::string Vec(const Eigen::Vector3d& v) {
  return Num(v.x()) + " " + Num(v.y()) + " " + Num(v.z());
}

/// "%.*g": `digits` significant digits (1 to 17), for messages and tables; "inf", "-inf" and
/// "nan" as printf writes them.
inline std::string Significant(double v, int digits) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.*g", digits, v);
  return buf;
}

/// "%.*f": `decimals` digits after the point (0 to 17), for values of a known range.
inline std::string Fixed(double v, int decimals) {
  char buf[352];  // the longest double in full, 309 digits, and the decimals
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

}  // namespace partsim::internal
