// What a loader repaired or ignored in the files it read: warnings a user can read after a load
// (UrdfLoader::LastReport, PartNetMobilityLoader::LastReport). Errors are exceptions; a warning is
// a disagreement or defect that partsim worked around without changing what the file means.
#pragma once

#include <string>
#include <vector>

namespace partsim {

/// One repaired or ignored defect: the file at fault and a message naming the element in the
/// file's own terms (URDF link and joint names, JSON entries), never a generated name.
struct LoadWarning {
  std::string file;     ///< path or name of the file, as given to the loader
  std::string message;  ///< e.g. "link 'FR_HIP' <inertial>: ... corrected to ..."
  /// "<file>: <message>".
  std::string ToString() const;
};

/// The warnings of one load, in the order they were found.
struct LoadReport {
  std::vector<LoadWarning> warnings;

  /// Records a warning and writes it to the log (partsim::LogWarning).
  void Warn(const std::string& file, const std::string& message);
  /// Appends another report's warnings (without logging them again).
  void Append(const LoadReport& other);
  bool Empty() const { return warnings.empty(); }
  /// One warning per line.
  std::string ToString() const;
};

}  // namespace partsim
