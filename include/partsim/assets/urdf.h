// URDF loading: URDF text -> ArticulationDesc (no scene needed) -> Articulation in a Scene.
#pragma once

#include <map>
#include <optional>
#include <string>

#include "partsim/assets/load_report.h"
#include "partsim/physics/description.h"
#include "partsim/physics/scene.h"

namespace partsim {

/// Most links a URDF may have: MuJoCo's compile of a scene grows as the square of its bodies and
/// joints (revolute joints on one root: 2000 load in 0.6 s and 74 MB, 4000 in 2.2 s and 220 MB,
/// 8000 in 7 s and 650 MB; see bench/README.md). A file with more is refused before its links are
/// read.
constexpr int kMaxUrdfLinks = 5000;
/// Most joints between a URDF's root link and any of its links: MuJoCo refuses bodies about 1023
/// below the world ("depth limit exceeded"), and a chain of 1000 takes 5 s to load and 0.12 s a
/// step. A deeper file is refused before its links are read.
constexpr int kMaxUrdfChainDepth = 1000;

/// Per-link overrides of the loader's defaults.
struct UrdfLinkOverride {
  std::optional<double> density;  ///< kg/m^3 for the link's collision shapes
  std::optional<PhysicalMaterial> material;
};

/// Loads URDF files (SAPIEN's URDFLoader). Links become links, joints become joints (revolute,
/// continuous, prismatic, fixed; `floating` joining the root to the world makes a free root;
/// `mimic` joints become couplings; `planar` is rejected). Mesh paths may be relative to the file
/// or use package://NAME/..., resolved through `package_dirs` or by searching the file's parent
/// folders for a folder NAME. What the loader repairs or ignores (a mimic on a fixed joint, an
/// inertia that breaks the triangle inequality, a flat, line-like or tiny collision piece, a
/// <limit> without bounds) is a warning in LastReport(); with `strict` those are errors. A mesh
/// that is not convex, and so collides as its convex hull, is a warning in either case. Every
/// mesh or texture file that is missing or unreadable is listed in one error. A mimic joint
/// keeps a dof of its own (see JointCoupling).
class UrdfLoader {
 public:
  explicit UrdfLoader(Scene* scene = nullptr) : scene_(scene) {}

  bool fix_root_link = true;
  double scale = 1.0;  ///< uniform scale on geometry, origins and prismatic limits
  /// Each mesh file (and each connected component of it) becomes its own convex piece.
  bool load_multiple_collisions_from_file = false;
  /// false skips every <collision> element and reads no collision mesh: for scenes that are only
  /// rendered (datasets), which load faster and hold no contact shapes. Links without <inertial>
  /// then get a small mass.
  bool load_collisions = true;
  double density = 1000.0;                                 ///< kg/m^3 for links without <inertial>
  std::optional<PhysicalMaterial> material;                ///< default material of collision shapes
  std::map<std::string, UrdfLinkOverride> link_overrides;  ///< by link name
  std::map<std::string, std::string> package_dirs;         ///< package name -> folder
  /// Defects that do not change what the file means become errors instead of warnings.
  bool strict = false;
  /// SRDF whose <disable_collisions> pairs apply; "" looks for "<urdf stem>.srdf" beside a URDF
  /// file.
  std::string srdf_file;

  /// Parses a URDF into a description. `source` names the text in error messages;
  /// `base_dir` resolves relative mesh paths.
  ArticulationDesc Parse(const std::string& text, const std::string& base_dir,
                         const std::string& source = "<string>") const;
  ArticulationDesc ParseFile(const std::string& path) const;

  /// Parses and adds to the scene.
  Articulation Load(const std::string& path);
  Articulation LoadFromString(const std::string& text, const std::string& base_dir = ".");

  /// Warnings of the last Parse / ParseFile / Load (empty before the first).
  const LoadReport& LastReport() const { return last_report_; }

 private:
  Scene* scene_;
  mutable LoadReport last_report_;
};

/// A loader whose Load adds to `scene` (SAPIEN's scene.create_urdf_loader()); the scene must
/// outlive it.
UrdfLoader CreateUrdfLoader(Scene& scene);

}  // namespace partsim
