// Command-line parsing and output folders shared by the partsim sub-commands.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <filesystem>

#include "commands.h"

namespace partsim::tools {

bool ParseInteger(const std::string& text, long long lo, long long* out) {
  char* end = nullptr;
  errno = 0;
  long long n = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || n < lo) return false;
  *out = n;
  return true;
}

namespace {

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

int ClearOwnedOutputs(const std::string& dir,
                      const std::vector<std::pair<std::string, std::string>>& names) {
  namespace fs = std::filesystem;
  std::error_code ec;
  int removed = 0;
  for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator();
       it.increment(ec)) {
    if (!it->is_regular_file()) continue;
    const std::string name = it->path().filename().string();
    for (const auto& [prefix, suffix] : names) {
      if (name.size() >= prefix.size() + suffix.size() && name.rfind(prefix, 0) == 0 &&
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
        std::error_code rm;
        removed += fs::remove(it->path(), rm) ? 1 : 0;
        break;
      }
    }
  }
  return removed;
}

}  // namespace partsim::tools
