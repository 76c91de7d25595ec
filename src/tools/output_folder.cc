// Output folders shared by the partsim sub-commands.
#include <filesystem>

#include "commands.h"

namespace partsim::tools {

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
