#include "partsim/assets/load_report.h"

#include "partsim/core/log.h"

namespace partsim {

std::string LoadWarning::ToString() const { return file + ": " + message; }

void LoadReport::Warn(const std::string& file, const std::string& message) {
  warnings.push_back({file, message});
  LogWarning(warnings.back().ToString());
}

void LoadReport::Append(const LoadReport& other) {
  warnings.insert(warnings.end(), other.warnings.begin(), other.warnings.end());
}

std::string LoadReport::ToString() const {
  std::string out;
  for (const LoadWarning& w : warnings) out += w.ToString() + "\n";
  return out;
}

}  // namespace partsim
