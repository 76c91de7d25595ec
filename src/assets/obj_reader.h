// partsim's reader of Wavefront OBJ files and their MTL material libraries: the mesh format of
// PartNet-Mobility and of partsim's generator. It gives the sub-meshes that LoadMeshFile made of
// an OBJ file through assimp (same splits, materials, vertex order and merged corners) without
// assimp's fixed 48 MB of buffers per file.
#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

#include "partsim/assets/mesh.h"
#include "partsim/physics/description.h"

namespace partsim::internal {

/// A sub-mesh as its file states it, in the file's frame and units. Corners whose position,
/// normal and uv agree are one vertex, numbered in order of first use.
struct FileSubMesh {
  std::string name;
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;  ///< one per position, or none
  std::vector<Eigen::Vector2f> uvs;      ///< one per position, or none
  std::vector<Eigen::Vector3i> triangles;
  RenderMaterial material;  ///< texture paths absolute
};

/// The sub-meshes of an OBJ file with at least one triangle, in the order the file makes them.
///
/// A new sub-mesh starts at `o` and `g` (named after them) and at `usemtl` with another material
/// (named after it), once the current one has faces. Faces before any `usemtl` take the last
/// material the libraries define (none: grey 0.6). Polygons are fanned when convex and cut into
/// ears when not; `l` and `p`, and faces of fewer than 3 corners, are no surfaces and are
/// skipped. Faces without `vn` get their triangle's normal; corners without `vt` get (0, 0) when
/// other faces of the sub-mesh have uvs. Indices may be negative (relative). MTL: `newmtl`,
/// `Kd`, `d`, `Tr` (1 - opacity), `Pr` (roughness), `Pm` (metallic) and `map_Kd` with its
/// options; other statements are ignored, and a library that cannot be read leaves its
/// materials grey. Throws partsim::Error naming the file and line of a statement it cannot
/// read (a number that is not one, an index 0 or past the data).
std::vector<FileSubMesh> ReadObjFile(const std::string& path);

/// ReadObjFile of OBJ text: `folder` resolves material libraries and textures, `path` names the
/// text in errors.
std::vector<FileSubMesh> ParseObj(std::string_view text, const std::string& folder,
                                  const std::string& path);

/// LoadMeshFile through assimp, for any format it reads, OBJ included: the formats other than
/// OBJ take this path, and the tests hold ReadObjFile to it.
std::vector<LoadedMesh> LoadMeshFileWithAssimp(const std::string& path,
                                               const Eigen::Vector3d& scale);

}  // namespace partsim::internal
