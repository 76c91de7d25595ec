// Mesh files (OBJ, STL, DAE, glTF, PLY, ...) read through assimp.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "partsim/physics/description.h"

namespace partsim {

/// One sub-mesh of a file with its render material.
struct LoadedMesh {
  std::shared_ptr<MeshData> mesh;
  RenderMaterial material;
};

/// Loads every sub-mesh of a file, with node transforms applied and vertices multiplied by
/// `scale`, in metres (Collada <unit> honoured) and z-up as the file states. Throws
/// partsim::Error naming the file when it is missing, unreadable or holds no triangles.
std::vector<LoadedMesh> LoadMeshFile(const std::string& path,
                                     const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

/// All sub-meshes of a file merged into one mesh.
std::shared_ptr<MeshData> LoadMergedMesh(const std::string& path,
                                         const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

/// Splits a mesh into its connected components (triangles sharing vertices, with positions
/// welded within 1e-7 m).
std::vector<std::shared_ptr<MeshData>> SplitConnectedComponents(const MeshData& mesh);

/// Collision pieces for a file: one per sub-mesh, and each sub-mesh further split into its
/// connected components.
std::vector<std::shared_ptr<MeshData>> LoadConvexPieces(
    const std::string& path, const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

}  // namespace partsim
