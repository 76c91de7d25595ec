// Text of numbers for the files partsim writes (MJCF, URDF): shortest text that reads back to the
// same double.
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

}  // namespace partsim::internal
