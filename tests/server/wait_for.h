// Polling helper of the server tests.
#pragma once

#include <chrono>
#include <thread>

namespace partsim::testing {

/// Calls `pred` every 10 ms until it holds, for up to 30 s (what a loaded 2-core machine needs
/// is far less); returns its last value.
template <class F>
bool WaitFor(F pred) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < deadline) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return pred();
}

}  // namespace partsim::testing
