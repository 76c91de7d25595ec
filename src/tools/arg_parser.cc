// The command-line parser of the partsim sub-commands, and the typo suggestions of its messages.
#include "arg_parser.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>

#include "partsim/core/check.h"

namespace partsim::tools {

namespace {

// "A, B or C".
std::string Alternatives(const std::vector<std::string>& words) {
  std::string out;
  for (size_t i = 0; i < words.size(); ++i)
    out += (i == 0 ? "" : i + 1 == words.size() ? " or " : ", ") + words[i];
  return out;
}

// Reads a whole decimal integer; false if `text` is not one or overflows.
bool ReadInteger(const std::string& text, long long* out) {
  char* end = nullptr;
  errno = 0;
  const long long n = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE) return false;
  *out = n;
  return true;
}

// Reads a finite number; false if `text` is not one.
bool ReadNumber(const std::string& text, double* out) {
  const char* s = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s, &end);
  if (text.empty() || end == s || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    return false;
  *out = v;
  return true;
}

// Splits at commas, keeping empty pieces ("a,,b" has three, "a," two).
std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> pieces(1);
  for (char c : text) {
    if (c == ',')
      pieces.emplace_back();
    else
      pieces.back() += c;
  }
  return pieces;
}

// Levenshtein distance between `a` and `b`, letters compared case-insensitively; one row of the
// dynamic programme at a time.
size_t EditDistance(const std::string& a, const std::string& b) {
  auto same = [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) ==
           std::tolower(static_cast<unsigned char>(y));
  };
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] =
          std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same(a[i - 1], b[j - 1]) ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// FlagValue

void FlagValue::Fail(const std::string& message) const {
  throw UsageError(command_ + ": " + message);
}

std::string FlagValue::NonEmpty(const std::string& what) const {
  if (text_.empty()) Fail(flag_ + " needs " + what);
  return text_;
}

long long FlagValue::Integer(long long lo, long long hi, const std::string& note) const {
  long long n = 0;
  if (!ReadInteger(text_, &n) || n < lo || n > hi) {
    const std::string range = hi == std::numeric_limits<long long>::max()
                                  ? ">= " + std::to_string(lo)
                                  : "from " + std::to_string(lo) + " to " + std::to_string(hi);
    Fail(flag_ + " expects an integer " + range + (note.empty() ? "" : " " + note) + ", got '" +
         text_ + "'");
  }
  return n;
}

unsigned long long FlagValue::Unsigned() const {
  char* end = nullptr;
  errno = 0;
  const unsigned long long n = std::strtoull(text_.c_str(), &end, 10);
  // strtoull would wrap "-1" around to 2^64 - 1
  if (text_.empty() || !std::isdigit(static_cast<unsigned char>(text_[0])) || *end != '\0' ||
      errno == ERANGE)
    Fail(flag_ + " expects an unsigned integer, got '" + text_ + "'");
  return n;
}

double FlagValue::Number() const {
  double v = 0;
  if (!ReadNumber(text_, &v)) Fail(flag_ + " expects a number, got '" + text_ + "'");
  return v;
}

double FlagValue::Number(double lo, bool inclusive, double hi) const {
  double v = 0;
  if (!ReadNumber(text_, &v) || (inclusive ? v < lo : v <= lo) || v > hi) {
    const std::string range = std::string(inclusive ? ">= " : "> ") + FormatNumber(lo) +
                              (std::isinf(hi) ? "" : " and <= " + FormatNumber(hi));
    Fail(flag_ + " expects a number " + range + ", got '" + text_ + "'");
  }
  return v;
}

std::vector<double> FlagValue::Numbers() const {
  std::vector<double> values;
  for (const std::string& piece : SplitCommas(text_)) {
    double v = 0;
    if (!ReadNumber(piece, &v))
      Fail(flag_ + " expects comma-separated numbers, got '" + text_ + "'");
    values.push_back(v);
  }
  return values;
}

std::vector<std::string> FlagValue::Names() const {
  std::vector<std::string> names = SplitCommas(text_);
  for (const std::string& name : names)
    if (name.empty()) Fail(flag_ + " has an empty name in '" + text_ + "'");
  return names;
}

std::string FlagValue::Choice(const std::vector<std::string>& choices,
                              const std::vector<std::string>& hidden) const {
  for (const std::vector<std::string>* list : {&choices, &hidden})
    if (std::find(list->begin(), list->end(), text_) != list->end()) return text_;
  Fail(flag_ + " expects " + Alternatives(choices) + ", got '" + text_ + "'" +
       DidYouMean(text_, choices));
}

std::pair<int, int> FlagValue::Size(int lo, int hi) const {
  const size_t x = text_.find('x');
  long long w = 0, h = 0;
  if (x == std::string::npos || !ReadInteger(text_.substr(0, x), &w) ||
      !ReadInteger(text_.substr(x + 1), &h) || w < lo || h < lo || w > hi || h > hi)
    Fail(flag_ + " expects WxH with each in " + std::to_string(lo) + ".." + std::to_string(hi) +
         " (e.g. 640x480), got '" + text_ + "'");
  return {static_cast<int>(w), static_cast<int>(h)};
}

std::pair<int, int> FlagValue::Shard() const {
  const size_t slash = text_.find('/');
  long long i = -1, n = -1;
  if (slash == std::string::npos || !ReadInteger(text_.substr(0, slash), &i) ||
      !ReadInteger(text_.substr(slash + 1), &n) || n < 1 || n > std::numeric_limits<int>::max() ||
      i < 0 || i >= n)
    Fail(flag_ + " wants i/N with 0 <= i < N (e.g. 0/4), got '" + text_ + "'");
  return {static_cast<int>(i), static_cast<int>(n)};
}

// ---------------------------------------------------------------------------------------------
// ArgParser

void ArgParser::Switch(const std::string& flag, std::function<void()> action) {
  flags_.push_back({flag, false, std::move(action), nullptr});
}

void ArgParser::Option(const std::string& flag, std::function<void(const FlagValue&)> action) {
  flags_.push_back({flag, true, nullptr, std::move(action)});
}

void ArgParser::Positional(std::function<void(const FlagValue&)> action) {
  positional_ = std::move(action);
}

void ArgParser::Fail(const std::string& message) const {
  throw UsageError(command_ + ": " + message);
}

void ArgParser::Parse(const std::vector<std::string>& args) const {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    // positional: anything that is not a flag
    if (arg.empty() || arg[0] != '-' || arg == "-") {
      if (!positional_) Fail("unexpected argument '" + arg + "'");
      positional_(FlagValue(command_, "", arg));
      continue;
    }
    // a flag, as "--flag value" or "--flag=value"
    std::string name = arg;
    const size_t eq = arg.rfind("--", 0) == 0 ? arg.find('=') : std::string::npos;
    if (eq != std::string::npos) name = arg.substr(0, eq);
    auto flag =
        std::find_if(flags_.begin(), flags_.end(), [&](const Flag& f) { return f.name == name; });
    if (flag == flags_.end()) {
      std::vector<std::string> names;
      for (const Flag& f : flags_) names.push_back(f.name);
      Fail("unknown option '" + arg + "'" + DidYouMean(name, names) +
           (help_.empty() ? "" : " (see " + help_ + ")"));
    }
    if (!flag->takes_value) {
      if (eq != std::string::npos) Fail(name + " takes no value");
      flag->on_switch();
      continue;
    }
    std::string value;
    if (eq != std::string::npos) {
      value = arg.substr(eq + 1);
    } else {
      if (i + 1 >= args.size()) Fail(name + " needs a value");
      value = args[++i];
    }
    flag->on_value(FlagValue(command_, name, value));
  }
}

bool ArgParser::AsksForHelp(const std::vector<std::string>& args) {
  return std::any_of(args.begin(), args.end(),
                     [](const std::string& a) { return a == "--help" || a == "-h"; });
}

int RunWithExitCode(const std::string& command, const std::string& usage_tail,
                    const std::function<int()>& run) {
  try {
    return run();
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s\n%s", e.what(), usage_tail.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", command.c_str(), e.what());
    return 1;
  }
}

// ---------------------------------------------------------------------------------------------
// suggestions

std::string ClosestMatch(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_distance = 0;
  for (const std::string& c : candidates) {
    if (c == word) return "";
    const size_t d = EditDistance(word, c);
    const size_t longer = std::max(word.size(), c.size());
    // a typo changes a few letters of a word, not most of them
    if (d * 3 > longer || d >= longer) continue;
    if (best.empty() || d < best_distance) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

std::string DidYouMean(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string match = ClosestMatch(word, candidates);
  return match.empty() ? "" : " (did you mean '" + match + "'?)";
}

}  // namespace partsim::tools
