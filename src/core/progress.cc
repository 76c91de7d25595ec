// Progress lines: '\r' on a terminal, bounded plain lines elsewhere.
#include "core/progress.h"

#include <unistd.h>

namespace partsim::internal {

ProgressLine::ProgressLine(std::FILE* out, double min_interval_s)
    : ProgressLine(out, out && ::isatty(::fileno(out)) == 1, min_interval_s) {}

ProgressLine::ProgressLine(std::FILE* out, bool terminal, double min_interval_s)
    : out_(out), terminal_(terminal), min_interval_s_(min_interval_s) {}

void ProgressLine::Update(long done, long total, const std::string& text) {
  if (!out_) return;
  const bool last = done >= total;
  const auto now = std::chrono::steady_clock::now();
  if (terminal_) {
    // rewritten in place at a bounded rate; the trailing blanks cover a longer previous text
    const double since = std::chrono::duration<double>(now - last_print_).count();
    if (!last && printed_ && since < min_interval_s_) return;
    std::fprintf(out_, "\r%s   ", text.c_str());
    open_line_ = !last;
    if (last) std::fputc('\n', out_);
  } else {
    // a line for the first item, for each tenth of the work and for the last item
    const long tenth = total > 0 ? done * 10 / total : 10;
    if (!last && printed_ && tenth <= last_tenth_) return;
    last_tenth_ = tenth;
    std::fprintf(out_, "%s\n", text.c_str());
  }
  printed_ = true;
  last_print_ = now;
  std::fflush(out_);
}

void ProgressLine::Break() {
  if (!out_ || !open_line_) return;
  std::fputc('\n', out_);
  std::fflush(out_);
  open_line_ = false;
}

}  // namespace partsim::internal
