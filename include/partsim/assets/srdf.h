// SRDF reading (MoveIt's Semantic Robot Description Format): the pairs of links that never
// collide. Only <disable_collisions> is read; groups, end effectors and the rest are skipped.
#pragma once

#include <string>
#include <vector>

#include "partsim/assets/load_report.h"

namespace partsim {

/// One <disable_collisions link1="" link2="" reason=""/> entry.
struct SrdfDisabledCollision {
  std::string link1;
  std::string link2;
  std::string reason;  ///< e.g. "Adjacent", "Never"; "" if absent
  int line = 0;        ///< line in the file
};

/// What partsim uses of an SRDF.
struct SrdfDesc {
  std::string robot_name;  ///< <robot name="">
  std::vector<SrdfDisabledCollision> disabled_collisions;
};

/// Parses SRDF text; `source` names it in messages. Malformed XML or a root other than <robot>
/// throws partsim::Error naming the source and line; an entry without link1 or link2 is skipped
/// with a warning in `report` (as MoveIt does).
SrdfDesc ParseSrdf(const std::string& text, const std::string& source, LoadReport* report);
/// Reads and parses an SRDF file.
SrdfDesc ReadSrdfFile(const std::string& path, LoadReport* report);

}  // namespace partsim
