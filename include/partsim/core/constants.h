// Numerical constants shared by every layer; the one place they are defined.
#pragma once

#include <limits>

namespace partsim {

/// pi, as a double.
constexpr double kPi = 3.14159265358979323846;

/// Positive infinity: an unbounded limit (a joint range, a force limit).
constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace partsim
