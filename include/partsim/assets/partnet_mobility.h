// PartNet-Mobility objects: a folder with mobility.urdf, mobility_v2.json, semantics.txt,
// meta.json, textured_objs/ and optionally bounding_box.json, result.json and images/
// (docs/partnet_mobility_format.md).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "partsim/assets/load_report.h"
#include "partsim/assets/urdf.h"
#include "partsim/physics/description.h"
#include "partsim/physics/scene.h"

namespace partsim {

/// One annotated part piece of a link (visuals named "<name>-<id>").
struct PartNetPart {
  int id = -1;
  std::string name;          ///< PartNet part name, e.g. "handle"
  std::vector<int> visuals;  ///< indices in the link's visuals named "*-<id>"
};

/// One link_N: its entry of mobility_v2.json (motion, axis, limits, parts) and its line of
/// semantics.txt.
struct PartNetLink {
  int id = -1;        ///< N of link_N
  int parent = -1;    ///< id of the parent link, -1 for base
  std::string joint;  ///< mobility_v2.json motion: hinge | slider | free | heavy | static
  /// semantics.txt label, the movable-part vocabulary ("drawer", "rotation_door",
  /// "rotation_lid", "furniture_body", ...); the PartNet name when semantics.txt has no line.
  std::string semantic_label;
  /// semantics.txt joint kind: hinge | slider | slider+ | free | heavy | static ("" if no line)
  std::string semantic_joint;
  std::string partnet_name;  ///< mobility_v2.json "name", the PartNet vocabulary ("cabinet_door")
  std::vector<PartNetPart> parts;
  bool has_axis = false;
  Eigen::Vector3d axis_origin = Eigen::Vector3d::Zero();      ///< file frame F (y-up), m
  Eigen::Vector3d axis_direction = Eigen::Vector3d::UnitX();  ///< file frame F, unit
  double limit_a = 0.0;  ///< degrees (hinge) or metres (slider), as in the file
  double limit_b = 0.0;
  bool no_limit = false;
  bool rotates = false;  ///< a slider that also turns about its axis
  bool no_rotation_limit = false;
  double rotation_limit = 0.0;  ///< degrees
};

/// A parsed object: its articulation (mobility.urdf as it is: z-up, root "base") and its
/// annotations. The annotation files use the raw mesh frame F (y-up), which mobility.urdf turns
/// z-up at the joint from "base" to the object's body: X_BF is that joint's rotation.
struct PartNetMobilityObject {
  std::string folder;
  std::string category;  ///< meta.json model_cat ("" when meta.json is missing)
  std::string model_id;
  ArticulationDesc articulation;
  std::vector<PartNetLink> links;  ///< mobility_v2.json entries, by id order
  Pose X_BF;                       ///< the annotation frame F in the root link "base"
  /// Bounds at rest in F (bounding_box.json, else computed from the visual meshes), m.
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();
  LoadReport report;  ///< what the reader repaired or ignored

  /// The entry of link_N; throws if there is none.
  const PartNetLink& Link(int id) const;
  /// Index of link "link_N" in the articulation; throws if there is none.
  int LinkIndex(int id) const;
  /// Indices (in the link's visuals) of the visuals of part `part_name` on link_N, e.g. the
  /// handle of the drawer on link_1: PartVisuals(1, "handle").
  std::vector<int> PartVisuals(int id, const std::string& part_name) const;
  /// The partsim joint type a mobility_v2.json motion maps to.
  static JointType MotionJointType(const PartNetLink& link);
  /// link_N ids whose semantics label is `label` (e.g. "drawer"), in id order.
  std::vector<int> LinksWithLabel(const std::string& label) const;
};

/// Reads PartNet-Mobility folders (SAPIEN's loader of the dataset). mobility.urdf is the
/// physical truth: the other files give labels and parts, and a disagreement between them that
/// does not change the physics (labels, names, axes or limits that differ, an optional file
/// missing) is a warning in LastReport(); with `strict` it is an error. The URDF options
/// (load_multiple_collisions_from_file, scale, density, material) apply to mobility.urdf; the
/// root "base" is fixed unless fix_root_link is false.
class PartNetMobilityLoader {
 public:
  explicit PartNetMobilityLoader(Scene* scene = nullptr) : scene_(scene) {}

  UrdfLoader urdf;      ///< options for mobility.urdf
  bool strict = false;  ///< cross-file disagreements and missing files become errors (dataset QA)

  /// Reads and cross-checks a folder; throws partsim::Error naming the file and entry at fault
  /// for what cannot be read (malformed JSON, missing mobility.urdf, a broken URDF).
  PartNetMobilityObject Parse(const std::string& folder) const;
  /// Parses and adds the articulation to the scene (named "<category>_<model_id>").
  Articulation Load(const std::string& folder);
  /// Warnings of the last Parse or Load.
  const LoadReport& LastReport() const { return last_report_; }

 private:
  Scene* scene_;
  mutable LoadReport last_report_;
};

/// The pose of an articulation's root that makes its geometry stand on the plane z = `altitude`
/// at the current joint positions: the root's orientation and x, y stay; z moves so that the
/// lowest point of its collision shapes (visuals when it has none) is 10 micrometres above the
/// plane: clear of it, so that a part that cannot move down (a drawer of a fixed cabinet) is not
/// in a contact it cannot push out of, whose friction would hold it.
Pose StandingRootPose(const Articulation& articulation, double altitude = 0.0);
/// Moves the articulation's root to StandingRootPose.
void PlaceOnGround(Articulation& articulation, double altitude = 0.0);

/// A folder that a dataset search could not list, and why.
struct UnreadableFolder {
  std::string folder;  ///< the path as reached from the root (through links, not resolved)
  std::string reason;  ///< e.g. "cannot read the folder: Permission denied"
};

/// The folders under `root` (`root` itself included) that `is_object` accepts, sorted by path,
/// searched at any depth without looking inside an accepted folder. Symbolic links to folders
/// are followed (a folder of links is the usual way to pick a subset of a dataset), and the
/// paths returned go through them, as reached from `root`. What cannot be searched is added to
/// `unreadable` with the reason when it is given, else throws partsim::Error naming it: a
/// folder that cannot be listed, a link whose target is missing, and a link loop (a link to a
/// folder that holds it, or links that lead to one another), named by the link, which is not
/// followed. Throws when `root` is not a folder.
std::vector<std::string> FindDatasetFolders(
    const std::string& root, const std::function<bool(const std::string& folder)>& is_object,
    std::vector<UnreadableFolder>* unreadable = nullptr);

/// FindDatasetFolders of PartNet-Mobility objects: the folders that hold mobility.urdf.
std::vector<std::string> FindPartNetMobilityFolders(
    const std::string& root, std::vector<UnreadableFolder>* unreadable = nullptr);

/// Result of reading one folder of a batch.
struct PartNetBatchEntry {
  std::string folder;
  bool ok = false;
  std::string error;  ///< when !ok
  PartNetMobilityObject object;
};

/// Parses every object folder under `root` (FindPartNetMobilityFolders: a folder holding
/// mobility.urdf, at any depth, through links), sorted by path; a bad folder is reported in its
/// entry and the rest are still read.
std::vector<PartNetBatchEntry> ParsePartNetMobilityBatch(const std::string& root,
                                                         const PartNetMobilityLoader& loader);

}  // namespace partsim
