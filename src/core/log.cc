#include "partsim/core/log.h"

#include <atomic>
#include <cstdio>

#include "partsim/core/error.h"

namespace partsim {
namespace {

std::atomic<LogLevel> g_level{LogLevel::kWarning};

}  // namespace

void SetLogLevel(LogLevel level) { g_level = level; }

LogLevel GetLogLevel() { return g_level; }

LogLevel ParseLogLevel(const std::string& name) {
  if (name == "warn" || name == "warning") return LogLevel::kWarning;
  if (name == "error") return LogLevel::kError;
  if (name == "off") return LogLevel::kOff;
  throw Error("log level '" + name + "' is not one of warning, error, off");
}

void LogWarning(const std::string& message) {
  if (g_level != LogLevel::kWarning) return;
  // one write, so that lines from several threads do not interleave
  std::string line = "partsim: warning: " + message + "\n";
  std::fwrite(line.data(), 1, line.size(), stderr);
}

}  // namespace partsim
