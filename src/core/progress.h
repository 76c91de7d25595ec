// Progress reports of long commands (`partsim assets generate`, `partsim assets check`) on a
// stream such as stderr: rewritten in place on a terminal, plain lines in a log file or a pipe.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace partsim::internal {

/// One progress report, `done` of `total` items. On a terminal the line is rewritten in place
/// ('\r'), at most every `min_interval_s` seconds and always for the last item. Elsewhere (a log
/// file, a pipe) it writes plain lines, never '\r': one when the first item is done, one each
/// time another tenth of the work is done, and one for the last item, so that a log holds at most
/// a dozen progress lines whatever the number of items. The caller serialises the calls.
class ProgressLine {
 public:
  /// Reports on `out`, a terminal when isatty says so.
  explicit ProgressLine(std::FILE* out, double min_interval_s = 0.5);
  /// Reports on `out`, a terminal when `terminal` (for tests).
  ProgressLine(std::FILE* out, bool terminal, double min_interval_s);

  /// Reports that `done` of `total` items are done; `text` (one line, no newline) says so.
  void Update(long done, long total, const std::string& text);
  /// Ends a line left open on a terminal, so that what the caller prints next starts a line of
  /// its own; nothing elsewhere, or when no line is open.
  void Break();

  bool IsTerminal() const { return terminal_; }

 private:
  std::FILE* out_;
  bool terminal_;
  double min_interval_s_;
  std::chrono::steady_clock::time_point last_print_;
  bool printed_ = false;    // some line was printed
  bool open_line_ = false;  // a '\r' line waits for its end (terminal)
  long last_tenth_ = -1;    // tenths of the work done at the last plain line
};

}  // namespace partsim::internal
