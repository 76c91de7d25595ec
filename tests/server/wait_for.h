// Polling helper of the server tests.
#pragma once

#include <chrono>
#include <thread>

namespace partsim::testing {

/// Calls `pred` every 10 ms until it holds, for up to 10 s; returns its last value.
template <class F>
bool WaitFor(F pred) {
  for (int i = 0; i < 1000; ++i) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return pred();
}

}  // namespace partsim::testing
