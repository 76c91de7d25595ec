// The builder members that need the assets layer: mesh files (assimp) and the convex-piece check
// (qhull), and Scene::CreateUrdfLoader. Physics declares them (partsim/physics/scene.h) and builds
// without them; they are defined and instantiated here, one layer up.
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

template <typename D>
D& BodyBuilder<D>::AddConvexCollisionFromFile(const std::string& filename, const Pose& pose,
                                              const Eigen::Vector3d& scale,
                                              const std::optional<PhysicalMaterial>& material,
                                              double density) {
  CheckScale(scale, filename);
  if (auto piece = CollidablePiece(LoadMergedMesh(filename, scale), true))
    AddConvexMesh(body(), piece, pose, material, density);
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddMultipleConvexCollisionsFromFile(
    const std::string& filename, const Pose& pose, const Eigen::Vector3d& scale,
    const std::optional<PhysicalMaterial>& material, double density) {
  CheckScale(scale, filename);
  for (auto& loaded : LoadConvexPieces(filename, scale))
    if (auto piece = CollidablePiece(loaded, false))
      AddConvexMesh(body(), piece, pose, material, density);
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddConvexCollisionFromMesh(std::shared_ptr<const MeshData> mesh,
                                              const Pose& pose,
                                              const std::optional<PhysicalMaterial>& material,
                                              double density) {
  if (!mesh) throw Error("add_convex_collision_from_mesh: the mesh is null");
  if (auto piece = CollidablePiece(std::move(mesh), false))
    AddConvexMesh(body(), piece, pose, material, density);
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddVisualFromFile(const std::string& filename, const Pose& pose,
                                     const Eigen::Vector3d& scale, const std::string& name) {
  AddVisualFile(body(), filename, pose, scale, name);
  return self();
}

template ActorBuilder& BodyBuilder<ActorBuilder>::AddConvexCollisionFromFile(
    const std::string&, const Pose&, const Eigen::Vector3d&, const std::optional<PhysicalMaterial>&,
    double);
template ActorBuilder& BodyBuilder<ActorBuilder>::AddMultipleConvexCollisionsFromFile(
    const std::string&, const Pose&, const Eigen::Vector3d&, const std::optional<PhysicalMaterial>&,
    double);
template ActorBuilder& BodyBuilder<ActorBuilder>::AddConvexCollisionFromMesh(
    std::shared_ptr<const MeshData>, const Pose&, const std::optional<PhysicalMaterial>&, double);
template ActorBuilder& BodyBuilder<ActorBuilder>::AddVisualFromFile(const std::string&, const Pose&,
                                                                    const Eigen::Vector3d&,
                                                                    const std::string&);
template LinkBuilder& BodyBuilder<LinkBuilder>::AddConvexCollisionFromFile(
    const std::string&, const Pose&, const Eigen::Vector3d&, const std::optional<PhysicalMaterial>&,
    double);
template LinkBuilder& BodyBuilder<LinkBuilder>::AddMultipleConvexCollisionsFromFile(
    const std::string&, const Pose&, const Eigen::Vector3d&, const std::optional<PhysicalMaterial>&,
    double);
template LinkBuilder& BodyBuilder<LinkBuilder>::AddConvexCollisionFromMesh(
    std::shared_ptr<const MeshData>, const Pose&, const std::optional<PhysicalMaterial>&, double);
template LinkBuilder& BodyBuilder<LinkBuilder>::AddVisualFromFile(const std::string&, const Pose&,
                                                                  const Eigen::Vector3d&,
                                                                  const std::string&);

UrdfLoader Scene::CreateUrdfLoader() { return UrdfLoader(this); }

}  // namespace partsim
