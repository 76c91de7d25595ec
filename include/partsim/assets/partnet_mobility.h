// PartNet-Mobility objects: a folder with mobility.urdf, mobility_v2.json, semantics.txt,
// meta.json, bounding_box.json and textured_objs/ (docs/partnet_mobility_format.md).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "partsim/assets/urdf.h"
#include "partsim/physics/description.h"
#include "partsim/physics/scene.h"

namespace partsim {

/// One annotated part piece of a link (a visual named "<name>-<id>").
struct PartNetPart {
  int id = -1;
  std::string name;  ///< e.g. "handle"
};

/// One entry of mobility_v2.json: a link's motion, axis, limits and parts.
struct PartNetLink {
  int id = -1;                 ///< N of link_N
  int parent = -1;             ///< id of the parent link, -1 for base
  std::string joint;           ///< hinge | slider | free | heavy | static
  std::string semantic_label;  ///< e.g. "drawer", "rotation_door"
  std::vector<PartNetPart> parts;
  bool has_axis = false;
  Eigen::Vector3d axis_origin = Eigen::Vector3d::Zero();      ///< file frame (y-up), m
  Eigen::Vector3d axis_direction = Eigen::Vector3d::UnitX();  ///< file frame, unit
  double limit_a = 0.0;  ///< degrees (hinge) or metres (slider), as in the file
  double limit_b = 0.0;
  bool no_limit = false;
  bool rotates = false;  ///< a slider that also turns about its axis
  bool no_rotation_limit = false;
  double rotation_limit = 0.0;  ///< degrees
};

/// A parsed object: its articulation (z-up, root "base") and its annotations.
struct PartNetMobilityObject {
  std::string folder;
  std::string category;  ///< meta.json model_cat
  std::string model_id;
  ArticulationDesc articulation;
  std::vector<PartNetLink> links;                      ///< mobility_v2.json entries, by id order
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();  ///< bounding_box.json (file frame)
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();

  /// The entry of link_N; throws if there is none.
  const PartNetLink& Link(int id) const;
  /// Index of link "link_N" in the articulation; throws if there is none.
  int LinkIndex(int id) const;
  /// Indices (in the link's visuals) of the visuals of part `part_name` on link_N, e.g. the
  /// handle of the drawer on link_1: PartVisuals(1, "handle").
  std::vector<int> PartVisuals(int id, const std::string& part_name) const;
  /// The partsim joint type a mobility_v2.json motion maps to.
  static JointType MotionJointType(const PartNetLink& link);
};

/// Reads PartNet-Mobility folders (SAPIEN's loader of the dataset). The URDF options
/// (load_multiple_collisions_from_file, scale, density, material) apply to mobility.urdf; the
/// root "base" is fixed unless fix_root_link is false.
class PartNetMobilityLoader {
 public:
  explicit PartNetMobilityLoader(Scene* scene = nullptr) : scene_(scene) {}

  UrdfLoader urdf;  ///< options for mobility.urdf

  /// Reads and cross-checks a folder; throws partsim::Error naming the file and entry at fault.
  PartNetMobilityObject Parse(const std::string& folder) const;
  /// Parses and adds the articulation to the scene (named "<category>_<model_id>").
  Articulation Load(const std::string& folder);

 private:
  Scene* scene_;
};

/// Result of reading one folder of a batch.
struct PartNetBatchEntry {
  std::string folder;
  bool ok = false;
  std::string error;  ///< when !ok
  PartNetMobilityObject object;
};

/// Parses every object folder under `root` (a folder holding mobility_v2.json, at any depth),
/// sorted by path; a bad folder is reported in its entry and the rest are still read.
std::vector<PartNetBatchEntry> ParsePartNetMobilityBatch(const std::string& root,
                                                         const PartNetMobilityLoader& loader);

}  // namespace partsim
