// Mesh files: OBJ (with its MTL libraries) through partsim's own reader, the other formats (STL,
// DAE, glTF, PLY, ...) through assimp.
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

/// Sub-meshes already loaded (LoadMeshFile of `path`) merged into one mesh named after `path`;
/// the parts are not changed.
std::shared_ptr<MeshData> MergeMeshes(const std::vector<LoadedMesh>& parts,
                                      const std::string& path);

/// Splits a mesh into its connected components (triangles sharing vertices, with positions
/// welded within 1e-7 m).
std::vector<std::shared_ptr<MeshData>> SplitConnectedComponents(const MeshData& mesh);

/// Collision pieces for a file: one per sub-mesh, and each sub-mesh further split into its
/// connected components.
std::vector<std::shared_ptr<MeshData>> LoadConvexPieces(
    const std::string& path, const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

/// LoadConvexPieces of sub-meshes already loaded; the parts are not changed.
std::vector<std::shared_ptr<MeshData>> ConnectedPieces(const std::vector<LoadedMesh>& parts);

/// Most vertices a convex collision piece keeps (CheckConvexPiece). qhull, partsim's and then
/// MuJoCo's when it compiles the piece, merges coplanar facets at a cost of about n^2.5 in the
/// vertices on one plane (a flat 10,000-corner face took 65 s); a hull of at most this many
/// vertices takes under a second in either.
constexpr int kMaxConvexPieceVertices = 2000;

/// What CheckConvexPiece found about a mesh meant to collide as one convex piece (MuJoCo collides
/// the convex hull of its vertices, and refuses vertices that span no volume).
struct ConvexPieceCheck {
  /// The piece to collide with: the input itself when it has at most kMaxConvexPieceVertices
  /// distinct points, else its convex hull; for a flat or line-like input, the convex hull of its
  /// points pushed out by `thickness` along its thin directions; nullptr when the input is
  /// dropped (smaller than 0.1 mm across, or no points). A hull keeps at most
  /// kMaxConvexPieceVertices vertices (see `simplified`).
  std::shared_ptr<const MeshData> piece;
  /// What was wrong and what was done, "" when the input is kept as it is (e.g. "flat: 4 points
  /// on one plane, 0.5 m across; given a convex hull 0.001 m thick").
  std::string repair;
  double thickness = 0.0;  ///< m, of the thin hull when one was made
  /// "" unless the hull had more than kMaxConvexPieceVertices vertices and `piece` is the hull of
  /// a subset of them (the farthest points first), inside the full hull; then what was kept and
  /// how far the dropped points lie outside it (e.g. "has a convex hull of over 2000 vertices
  /// (10000 distinct points): collides as the hull of 2000 of them, which leaves points up to
  /// 1.2e-05 m outside"). Not a defect of the file: loaders warn, also when strict.
  std::string simplified;
  /// The input clearly differs from its convex hull (see ConvexityOf); false for repaired pieces.
  bool non_convex = false;
  /// Volume of the input over its hull's (closed, consistently wound inputs, a few cracks
  /// allowed), else NaN.
  double volume_ratio = 0.0;
  /// Fraction of the input's surface area deeper inside the hull than 5% of its size.
  double deep_area_fraction = 0.0;
};

/// Checks a mesh as one convex collision piece (m): fewer than 4 distinct points, all points on
/// one plane or line (or within 1e-6 of its size of one), or a hull under 1e-13 m^3 make it
/// degenerate; such a piece gets a thin hull (thickness 3% of its size, between 0.02 mm and 5 mm)
/// unless it is under 0.1 mm across, when it is dropped. A sound piece is measured for convexity:
/// a closed, consistently wound surface (a few cracks allowed) is non-convex when it encloses
/// under 80% of its hull's volume; an open one when over 10% of its area lies deeper inside the
/// hull than 5% of its size. Boxes, cylinders and other convex shapes never are. The work is
/// bounded: qhull sees the distinct points and keeps at most kMaxConvexPieceVertices hull
/// vertices, and convexity is measured on a sample of at most 20000 triangles.
ConvexPieceCheck CheckConvexPiece(const std::shared_ptr<const MeshData>& mesh);

}  // namespace partsim
