// Builder steps that read mesh files or check convex pieces (assimp, qhull), for an ActorBuilder
// or a LinkBuilder: the assets layer's additions to the physics builders, as free functions so
// that physics builds and links without them. Each returns the builder it was given, so that
// the builder's own calls chain on: AddVisualFromFile(builder, "mug.obj").BuildStatic().
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>

#include "partsim/core/pose.h"
#include "partsim/physics/description.h"
#include "partsim/physics/scene.h"

namespace partsim {

/// Adds the convex hull of a mesh file's vertices (multiplied by `scale`) at `pose` in the body,
/// with `material` (default: the scene's) and `density` (kg/m^3). Pieces MuJoCo cannot collide
/// with (flat, line-like, under 0.1 mm: CheckConvexPiece) get a thin hull or are dropped, and a
/// non-convex file is warned about once (partsim::LogWarning); the same holds for the adders
/// below. `Builder` is ActorBuilder or LinkBuilder (both instantiated in the assets library).
template <typename Builder>
Builder& AddConvexCollisionFromFile(Builder& builder, const std::string& filename,
                                    const Pose& pose = Pose(),
                                    const Eigen::Vector3d& scale = Eigen::Vector3d::Ones(),
                                    const std::optional<PhysicalMaterial>& material = {},
                                    double density = 1000.0);
/// One convex piece per sub-mesh (and connected component) of a mesh file.
template <typename Builder>
Builder& AddMultipleConvexCollisionsFromFile(Builder& builder, const std::string& filename,
                                             const Pose& pose = Pose(),
                                             const Eigen::Vector3d& scale = Eigen::Vector3d::Ones(),
                                             const std::optional<PhysicalMaterial>& material = {},
                                             double density = 1000.0);
/// The convex hull of a mesh's vertices (m, in the shape's frame); throws partsim::Error when
/// `mesh` is null.
template <typename Builder>
Builder& AddConvexCollisionFromMesh(Builder& builder, std::shared_ptr<const MeshData> mesh,
                                    const Pose& pose = Pose(),
                                    const std::optional<PhysicalMaterial>& material = {},
                                    double density = 1000.0);
/// Every sub-mesh of a file (multiplied by `scale`) as a visual at `pose` in the body, with the
/// file's materials and an optional name (e.g. a part name).
template <typename Builder>
Builder& AddVisualFromFile(Builder& builder, const std::string& filename, const Pose& pose = Pose(),
                           const Eigen::Vector3d& scale = Eigen::Vector3d::Ones(),
                           const std::string& name = "");

}  // namespace partsim
