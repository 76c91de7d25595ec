// Messages partsim writes to the standard error stream outside of errors: warnings about what a
// loader repaired, about numerical trouble, and the like. One process-wide level.
#pragma once

#include <string>

namespace partsim {

/// What reaches standard error: kWarning (default) writes warnings, kError and kOff keep them
/// quiet (they are still recorded in load reports and scene warnings).
enum class LogLevel { kWarning, kError, kOff };

void SetLogLevel(LogLevel level);
LogLevel GetLogLevel();
/// Parses "warn", "warning", "error", "off" (case-sensitive); throws partsim::Error otherwise.
LogLevel ParseLogLevel(const std::string& name);

/// Writes "partsim: warning: <message>" to standard error when the level allows it.
void LogWarning(const std::string& message);

}  // namespace partsim
