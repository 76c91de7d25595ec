// Checks and the text of numbers in messages. Bad input from a caller goes through
// PARTSIM_THROW_UNLESS, CheckFinite or CheckPose, which throw partsim::Error naming the argument
// and showing the value; a broken internal invariant goes through PARTSIM_DEMAND, which aborts
// with file:line. Public because bindings and tests use them too; kPi and kInf live in
// partsim/core/constants.h.
#pragma once

#include <Eigen/Core>
#include <string>

#include "partsim/core/error.h"
#include "partsim/core/pose.h"

namespace partsim {

/// Shortest "%g" text that reads back to the same double: 1e-07, 0.1, 3, -0, nan, inf. Never
/// rounds a small number to zero (std::to_string prints 1e-7 as "0.000000").
std::string FormatNumber(double value);

/// "[a, b, c]" with FormatNumber; a matrix prints row by row as "[[a, b], [c, d]]".
template <typename Derived>
std::string FormatVector(const Eigen::MatrixBase<Derived>& v) {
  const bool flat = v.rows() == 1 || v.cols() == 1;
  std::string s = "[";
  for (Eigen::Index r = 0; r < v.rows(); ++r) {
    if (!flat) s += r ? ", [" : "[";
    for (Eigen::Index c = 0; c < v.cols(); ++c) {
      if (flat ? r + c > 0 : c > 0) s += ", ";
      s += FormatNumber(static_cast<double>(v(r, c)));
    }
    if (!flat) s += "]";
  }
  return s + "]";
}

/// Throws Error "`name` must be finite, got [..]" unless every entry of `v` is finite.
template <typename Derived>
void CheckFinite(const std::string& name, const Eigen::MatrixBase<Derived>& v) {
  if (!v.allFinite()) throw Error(name + " must be finite, got " + FormatVector(v));
}

/// Throws Error "`name` must hold finite numbers and a unit quaternion, got Pose(..)" unless
/// `pose.IsValid()`.
void CheckPose(const std::string& name, const Pose& pose);

namespace internal {

/// Throws Error(message + " (failed: " + condition + ")"); the body of PARTSIM_THROW_UNLESS.
[[noreturn]] void ThrowUnless(const std::string& message, const char* condition);

/// Prints "file:line: demand failed: condition" to stderr and aborts; the body of PARTSIM_DEMAND.
[[noreturn]] void DemandFailed(const char* condition, const char* file, int line);

}  // namespace internal
}  // namespace partsim

/// Bad input: throws partsim::Error with `message` (an expression yielding std::string, which
/// should name the argument) and the text of the failed condition. The message is built only when
/// the condition fails.
#define PARTSIM_THROW_UNLESS(condition, message)                               \
  do {                                                                         \
    if (!(condition)) ::partsim::internal::ThrowUnless((message), #condition); \
  } while (0)

/// A broken internal invariant, i.e. a bug in partsim: prints file:line and the condition to
/// stderr and aborts. Checked in every build type.
#define PARTSIM_DEMAND(condition)                                                        \
  do {                                                                                   \
    if (!(condition)) ::partsim::internal::DemandFailed(#condition, __FILE__, __LINE__); \
  } while (0)
