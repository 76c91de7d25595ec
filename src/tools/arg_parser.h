// The command line of the partsim sub-commands: one usage-error type, and one parser that every
// command declares its flags to.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace partsim::tools {

/// A bad command line. The message names the command, the flag or argument at fault and the
/// value given ("partsim render: --views expects an integer from 1 to 360, got '0'"); the
/// command exits with code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The value of one flag (or a positional argument, whose flag is ""), with the parsers that
/// turn it into what the command needs. Each throws a UsageError naming the flag and the value.
class FlagValue {
 public:
  FlagValue(std::string command, std::string flag, std::string text)
      : command_(std::move(command)), flag_(std::move(flag)), text_(std::move(text)) {}

  const std::string& Flag() const { return flag_; }
  const std::string& Text() const { return text_; }

  /// The text, refused when empty: "--out needs a `what`" (e.g. "a folder name").
  std::string NonEmpty(const std::string& what) const;
  /// A whole decimal integer from `lo` to `hi`; `note` follows the range in the message
  /// ("(0 picks a free port)").
  long long Integer(long long lo, long long hi, const std::string& note = "") const;
  /// A whole decimal integer >= 0 up to 2^64 - 1 (seeds).
  unsigned long long Unsigned() const;
  /// A finite number.
  double Number() const;
  /// A finite number > `lo` (or >= `lo` when `inclusive`) and at most `hi`.
  double Number(double lo, bool inclusive, double hi) const;
  /// Comma-separated finite numbers, at least one.
  std::vector<double> Numbers() const;
  /// Comma-separated names, none of them empty.
  std::vector<std::string> Names() const;
  /// One of `choices` (or of `hidden`, accepted but not offered: for tests); a typo gets a
  /// suggestion.
  std::string Choice(const std::vector<std::string>& choices,
                     const std::vector<std::string>& hidden = {}) const;
  /// "WxH" with each of W and H from `lo` to `hi`.
  std::pair<int, int> Size(int lo, int hi) const;
  /// "i/N" of --shard, 0 <= i < N: this process's share of a list, the items whose index % N is
  /// i. Returns {i, N}.
  std::pair<int, int> Shard() const;

  /// Throws UsageError("<command>: `message`").
  [[noreturn]] void Fail(const std::string& message) const;

 private:
  std::string command_, flag_, text_;
};

/// The flags and positional arguments of one command, each declared with what to do with it,
/// then read from a command line in order. A flag's value follows it ("--out DIR") or is joined
/// to it ("--out=DIR"); a flag may be given again (its action decides whether the last wins or
/// the values add up). An unknown flag is refused with the closest declared one as suggestion.
class ArgParser {
 public:
  /// `command`: the words that start every message ("partsim render"); `help`: where to read
  /// more, said after an unknown flag ("partsim --help"), or "" to say nothing.
  explicit ArgParser(std::string command, std::string help = "")
      : command_(std::move(command)), help_(std::move(help)) {}

  /// A flag without a value.
  void Switch(const std::string& flag, std::function<void()> action);
  /// A flag with a value.
  void Option(const std::string& flag, std::function<void(const FlagValue&)> action);
  /// What to do with arguments that are not flags ("-" is one); without it they are refused.
  void Positional(std::function<void(const FlagValue&)> action);

  /// Reads `args` (the arguments after the command's own words) front to back, running the
  /// actions; throws UsageError at the first bad argument.
  void Parse(const std::vector<std::string>& args) const;

  /// Throws UsageError("<command>: `message`"): for checks across flags after Parse.
  [[noreturn]] void Fail(const std::string& message) const;

  /// Whether `args` holds -h or --help anywhere.
  static bool AsksForHelp(const std::vector<std::string>& args);

 private:
  struct Flag {
    std::string name;
    bool takes_value = false;
    std::function<void()> on_switch;
    std::function<void(const FlagValue&)> on_value;
  };
  std::string command_, help_;
  std::vector<Flag> flags_;
  std::function<void(const FlagValue&)> positional_;
};

/// Runs a command and turns what it throws into its exit code: 2 after a UsageError (its
/// message on stderr, followed by `usage_tail`), 1 after any other exception ("<command>: what"
/// on stderr), else what `run` returns.
int RunWithExitCode(const std::string& command, const std::string& usage_tail,
                    const std::function<int()>& run);

/// The entry of `candidates` closest to `word` by edit distance (insertions, deletions,
/// substitutions; letters compared case-insensitively) when it is near enough to be a typo of it:
/// at most a third of the longer word's letters differ, and at least one is the same. "" when
/// none is, or when `word` is one of `candidates`.
std::string ClosestMatch(const std::string& word, const std::vector<std::string>& candidates);

/// " (did you mean 'X'?)" with X = ClosestMatch(word, candidates), or "" when there is none: to
/// append to a usage error that names `word`.
std::string DidYouMean(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace partsim::tools
