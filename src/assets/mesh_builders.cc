// The builder steps that need the assets layer: mesh files (assimp) and the convex-piece check
// (qhull), for actor and link builders (partsim/assets/mesh_builders.h); and CreateUrdfLoader
// (partsim/assets/urdf.h). Physics builds without them.
#include "partsim/assets/mesh_builders.h"

#include <mutex>
#include <set>

#include "partsim/assets/mesh.h"
#include "partsim/assets/urdf.h"
#include "partsim/core/log.h"
#include "partsim/physics/scene.h"

namespace partsim {

namespace {

void AddConvexMesh(BodyDesc& b, std::shared_ptr<const MeshData> mesh, const Pose& pose,
                   const std::optional<PhysicalMaterial>& material, double density) {
  CollisionShape s;
  s.type = ShapeType::kConvexMesh;
  s.pose = pose;
  s.material = material;
  s.density = density;
  s.mesh = std::move(mesh);
  b.collisions.push_back(s);
}

// A piece MuJoCo can collide with (CheckConvexPiece): a flat or line-like piece gets a thin hull,
// a tiny one is dropped (nullptr), each with a warning naming the mesh. A non-convex mesh loaded
// as one piece (`whole_file`) is warned about once per file and process.
std::shared_ptr<const MeshData> CollidablePiece(std::shared_ptr<const MeshData> mesh,
                                                bool whole_file) {
  ConvexPieceCheck check = CheckConvexPiece(mesh);
  const std::string name =
      mesh->source.empty() ? "a collision mesh" : "mesh '" + mesh->source + "'";
  if (!check.repair.empty()) LogWarning(name + ": collision piece " + check.repair);
  if (!check.simplified.empty()) LogWarning(name + ": collision piece " + check.simplified);
  if (check.non_convex && whole_file) {
    static std::mutex mutex;
    static std::set<std::string> warned;
    std::lock_guard<std::mutex> lock(mutex);
    if (warned.insert(mesh->source).second) {
      LogWarning(name +
                 " is not convex, and collides as one convex hull; use "
                 "add_multiple_convex_collisions_from_file to make each connected part its own "
                 "piece, or split it into convex pieces with `partsim assets decompose " +
                 mesh->source + " --out DIR`");
    }
  }
  return check.piece;
}

void CheckScale(const Eigen::Vector3d& scale, const std::string& filename) {
  if (!scale.allFinite() || (scale.array() == 0).any())
    throw Error("mesh '" + filename + "': scale must be finite and non-zero");
}

void AddVisualFile(BodyDesc& b, const std::string& filename, const Pose& pose,
                   const Eigen::Vector3d& scale, const std::string& name) {
  CheckScale(scale, filename);
  for (const LoadedMesh& lm : LoadMeshFile(filename, scale)) {
    VisualShape v;
    v.type = ShapeType::kConvexMesh;
    v.pose = pose;
    v.mesh = lm.mesh;
    v.material = lm.material;
    v.name = name;
    b.visuals.push_back(v);
  }
}

}  // namespace

template <typename Builder>
Builder& AddConvexCollisionFromFile(Builder& builder, const std::string& filename, const Pose& pose,
                                    const Eigen::Vector3d& scale,
                                    const std::optional<PhysicalMaterial>& material,
                                    double density) {
  CheckScale(scale, filename);
  if (auto piece = CollidablePiece(LoadMergedMesh(filename, scale), true))
    AddConvexMesh(builder.Body(), piece, pose, material, density);
  return builder;
}

template <typename Builder>
Builder& AddMultipleConvexCollisionsFromFile(Builder& builder, const std::string& filename,
                                             const Pose& pose, const Eigen::Vector3d& scale,
                                             const std::optional<PhysicalMaterial>& material,
                                             double density) {
  CheckScale(scale, filename);
  for (auto& loaded : LoadConvexPieces(filename, scale))
    if (auto piece = CollidablePiece(loaded, false))
      AddConvexMesh(builder.Body(), piece, pose, material, density);
  return builder;
}

template <typename Builder>
Builder& AddConvexCollisionFromMesh(Builder& builder, std::shared_ptr<const MeshData> mesh,
                                    const Pose& pose,
                                    const std::optional<PhysicalMaterial>& material,
                                    double density) {
  if (!mesh) throw Error("add_convex_collision_from_mesh: the mesh is null");
  if (auto piece = CollidablePiece(std::move(mesh), false))
    AddConvexMesh(builder.Body(), piece, pose, material, density);
  return builder;
}

template <typename Builder>
Builder& AddVisualFromFile(Builder& builder, const std::string& filename, const Pose& pose,
                           const Eigen::Vector3d& scale, const std::string& name) {
  AddVisualFile(builder.Body(), filename, pose, scale, name);
  return builder;
}

// the builders these are for
#define PARTSIM_INSTANTIATE(Builder)                                                            \
  template Builder& AddConvexCollisionFromFile(Builder&, const std::string&, const Pose&,       \
                                               const Eigen::Vector3d&,                          \
                                               const std::optional<PhysicalMaterial>&, double); \
  template Builder& AddMultipleConvexCollisionsFromFile(                                        \
      Builder&, const std::string&, const Pose&, const Eigen::Vector3d&,                        \
      const std::optional<PhysicalMaterial>&, double);                                          \
  template Builder& AddConvexCollisionFromMesh(Builder&, std::shared_ptr<const MeshData>,       \
                                               const Pose&,                                     \
                                               const std::optional<PhysicalMaterial>&, double); \
  template Builder& AddVisualFromFile(Builder&, const std::string&, const Pose&,                \
                                      const Eigen::Vector3d&, const std::string&);
PARTSIM_INSTANTIATE(ActorBuilder)
PARTSIM_INSTANTIATE(LinkBuilder)
#undef PARTSIM_INSTANTIATE

UrdfLoader CreateUrdfLoader(Scene& scene) { return UrdfLoader(&scene); }

}  // namespace partsim
