// The message of the partsim::Error a call throws, for tests that check what a message says.
#pragma once

#include <string>

#include "partsim/core/error.h"

namespace partsim::testing {

/// The message of the partsim::Error that `f` throws; "" when it throws none.
template <typename F>
std::string ErrorOf(const F& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace partsim::testing
