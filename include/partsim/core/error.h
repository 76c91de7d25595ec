// Errors. Bad input from a caller throws partsim::Error, whose message names the argument, file or
// element at fault; the scene stays usable afterwards.
#pragma once

#include <stdexcept>
#include <string>

namespace partsim {

/// Raised for bad input: the message says what is wrong and where.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// Raised when an index or id is out of range (maps to Python's IndexError).
class IndexError : public Error {
 public:
  explicit IndexError(const std::string& what) : Error(what) {}
};

}  // namespace partsim
