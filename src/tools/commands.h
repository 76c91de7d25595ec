// Sub-commands of the `partsim` program that live in their own files.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace partsim::tools {

/// Reads a whole decimal integer >= `lo` from `text` into `out`; false if `text` is not one (or
/// overflows).
bool ParseInteger(const std::string& text, long long lo, long long* out);

/// The entry of `candidates` closest to `word` by edit distance (insertions, deletions,
/// substitutions; letters compared case-insensitively) when it is near enough to be a typo of it:
/// at most a third of the longer word's letters differ, and at least one is the same. "" when
/// none is, or when `word` is one of `candidates`.
std::string ClosestMatch(const std::string& word, const std::vector<std::string>& candidates);

/// " (did you mean 'X'?)" with X = ClosestMatch(word, candidates), or "" when there is none: to
/// append to a usage error that names `word`.
std::string DidYouMean(const std::string& word, const std::vector<std::string>& candidates);

/// Removes the files of `dir` that an earlier run of the same command wrote: names starting with
/// one of `prefixes` and ending with the matching entry of `suffixes` ("color_" + ".png"), so
/// that a run with fewer views or frames leaves no stale ones beside its own. Other files stay.
/// Returns how many were removed.
int ClearOwnedOutputs(const std::string& dir,
                      const std::vector<std::pair<std::string, std::string>>& names);

/// `partsim assets ...`: generate procedural PartNet-Mobility objects. `argv` holds the
/// arguments after "assets". Returns the exit code (0 success, 1 failure, 2 bad command line).
int RunAssetsCommand(int argc, char** argv);

/// `partsim tasks ...`: the drawer and door tasks with the heuristic solvers (arguments after
/// "tasks"). Returns the exit code (0 success, 1 failure, 2 bad command line).
int RunTasksCommand(int argc, char** argv);

/// `partsim serve ...`: a scene stepped in real time behind a rosbridge v2 WebSocket server
/// (arguments after "serve"). Returns the exit code (0 success, 1 failure, 2 bad command line).
int RunServeCommand(int argc, char** argv);

}  // namespace partsim::tools
