// Quality checks of articulated objects in PartNet-Mobility folders, and dataset statistics.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "partsim/physics/scene.h"

namespace partsim {

/// Options of the checks.
struct QualityOptions {
  double rest_seconds = 1.0;     ///< simulated time at rest, undriven
  double rest_tolerance = 2e-3;  ///< largest joint motion allowed at rest (rad or m)
  double range_seconds = 1.0;    ///< simulated time to drive a part to each limit
  double range_fraction = 0.95;  ///< a part must cover this fraction of its range each way
  bool check_visibility = true;  ///< render segmentation from several viewpoints
  std::string render_backend = "rasterizer";
  int image_size = 96;  ///< pixels per side of the visibility views
  /// The renderer behind the visibility check: the names of the object's moving links that no
  /// view shows (it may throw partsim::Error, which fails the check). The assets layer does not
  /// render; set it to HiddenMovingLinksFinder(render_backend, image_size) of
  /// partsim/render/visibility.h (the command line and Python do). Needed when
  /// check_visibility is set: CheckPartNetObject throws partsim::Error without it.
  std::function<std::vector<std::string>(Scene&, const Articulation&)> hidden_parts;
};

/// The outcome of one check.
struct QualityCheck {
  std::string name;  ///< "load", "labels", "rest", "range", "visible"
  bool passed = false;
  std::string detail;
};

/// The checks of one object.
struct ObjectQualityReport {
  std::string folder;
  std::string category;
  std::string model_id;
  int movable_parts = 0;  ///< links with a hinge or slider motion
  std::vector<QualityCheck> checks;
  bool Passed() const;
  /// One line per check.
  std::string ToString() const;
};

/// Runs every check on a folder: it loads (files present and consistent: URDF, mobility_v2.json
/// and semantics.txt agree on labels and joint types); undriven with a fixed base, nothing moves
/// more than rest_tolerance or blows up; each movable part, driven alone, reaches both ends of
/// its range (continuous hinges: +-pi) without jamming; each movable part shows in the
/// segmentation of at least one of ten views around the object (five from above, four
/// from below, one from the top). Never throws for a bad object:
/// the failure is in the report.
ObjectQualityReport CheckPartNetObject(const std::string& folder,
                                       const QualityOptions& options = QualityOptions());

/// Models and movable parts per category.
struct DatasetStatistics {
  std::map<std::string, std::pair<int, int>> per_category;  ///< category -> (models, parts)
  int models = 0;
  int parts = 0;
  void Add(const std::string& category, int movable_parts);
  /// A table in the layout of the SAPIEN paper's statistics table (categories as columns,
  /// rows #M and #P), beside the paper's figures when `with_paper` is set.
  std::string ToTable(bool with_paper = true) const;
};

/// The SAPIEN paper's PartNet-Mobility figures: category -> (models, movable parts).
const std::map<std::string, std::pair<int, int>>& PaperStatistics();

}  // namespace partsim
