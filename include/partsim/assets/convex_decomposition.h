// Convex decomposition of whole meshes (an OBJ from another dataset, a robot part): MuJoCo collides
// a mesh as its convex hull, so a non-convex mesh is split into convex pieces with HACD
// (hierarchical approximate convex decomposition, K. Mamou), each piece the convex hull of one
// cluster of the input's triangles. The result states how well the pieces fit the input.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "partsim/physics/description.h"

namespace partsim {

/// Settings of DecomposeConvex. Lengths in metres; a value <= 0 picks the stated default, which
/// scales with the diagonal of the input's bounding box.
struct ConvexDecompositionOptions {
  /// HACD's largest allowed concavity of one piece (m); <= 0: 1% of the bounding-box diagonal.
  /// HACD measures concavity on its own normalised copy of the mesh, along surface normals, so
  /// the bound is approximate: read max_surface_distance and excess in the result.
  double concavity = 0.0;
  /// Upper bound on the piece count (>= 1): when HACD stops with more clusters, it is run again
  /// merging the cheapest clusters until this many remain (concavity then exceeds the bound).
  /// Disconnected parts of the input that HACD does not join can still make more pieces.
  int max_pieces = 32;
  /// HACD stops merging at this many clusters (>= 1).
  int min_pieces = 1;
  /// Vertex limit of each piece (HACD simplifies larger hulls, which may then no longer cover
  /// their cluster); 0: the full hull of the cluster, which covers it exactly.
  int max_hull_vertices = 0;
  /// HACD's concavity estimate: add points inside faces, and extra points cast along normals.
  bool add_faces_points = true;
  bool add_extra_dist_points = true;
  bool add_neighbours_dist_points = false;
  /// HACD's cost weights: compactness (perimeter^2 / area) and volume of a merged cluster.
  double compacity_weight = 1e-4;
  double volume_weight = 0.0;
  /// Disconnected parts closer than this are joined in HACD's graph (m); <= 0: 1.5% of the
  /// bounding-box diagonal.
  double connect_distance = 0.0;

  /// Coverage tolerance (m): a surface sample counts as covered when it is inside a piece or
  /// within this distance of one; <= 0: 0.2% of the bounding-box diagonal.
  double coverage_tolerance = 0.0;
  /// Sample counts of the quality estimates: points on the input surface, and points in its
  /// bounding box for the volumes.
  int surface_samples = 20000;
  int volume_samples = 200000;
  uint32_t seed = 1;  ///< random samples are reproducible for a given seed
};

/// Convex pieces of a mesh and measures of how well they fit it.
struct ConvexDecompositionResult {
  /// Each the convex hull of one cluster: closed, triangles counter-clockwise seen from outside,
  /// in the input's frame (m).
  std::vector<std::shared_ptr<MeshData>> pieces;
  double mesh_volume = 0.0;                 ///< of the input (m^3), from its closed surface
  double hull_union_volume_estimate = 0.0;  ///< of the union of the pieces (m^3), sampled
  /// Largest distance from a sample of the input surface to the nearest piece (m); 0 when every
  /// sample lies inside some piece.
  double max_surface_distance = 0.0;
  /// Fraction of input surface samples inside or within `coverage_tolerance` of some piece.
  double coverage = 0.0;
  /// Volume of the pieces' union outside the input, as a fraction of the input's volume (sampled).
  double excess = 0.0;
  double concavity = 0.0;           ///< the concavity bound used (m)
  double coverage_tolerance = 0.0;  ///< the tolerance used for `coverage` (m)
  double diagonal = 0.0;            ///< bounding-box diagonal of the input (m)
};

/// Splits `mesh` (a closed triangle surface, m) into convex pieces. Vertices closer than 1e-6 of
/// the bounding-box diagonal are welded first. Throws partsim::Error naming the mesh (its
/// `source` file, else "mesh") when it has no triangles, a face index out of range, a non-finite
/// vertex, or no volume; and naming the option when an option is out of range.
ConvexDecompositionResult DecomposeConvex(
    const MeshData& mesh, const ConvexDecompositionOptions& options = ConvexDecompositionOptions());

/// Loads a mesh file (all sub-meshes merged, see LoadMergedMesh) and decomposes it.
ConvexDecompositionResult DecomposeConvexFile(
    const std::string& path,
    const ConvexDecompositionOptions& options = ConvexDecompositionOptions(),
    const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

/// Writes dir/basename_K.obj for K = 0 .. pieces-1 and dir/basename_collision.urdf.xml, a URDF
/// snippet with one <collision> per piece (mesh paths relative to `dir`) to paste into a <link>.
/// Creates `dir` if missing. Returns the paths written (OBJ files first). Throws partsim::Error
/// naming the path when a file cannot be written.
std::vector<std::string> WriteConvexPieces(const ConvexDecompositionResult& result,
                                           const std::string& dir, const std::string& basename);

/// Convex hull of points (m): closed, triangulated, counter-clockwise seen from outside. Throws
/// partsim::Error when the points span no volume (fewer than 4, or all on one plane).
/// `max_vertices` (0: no limit, else at least 4) bounds the hull's vertices: qhull stops once it
/// has that many, each added point being the farthest outside a facet of the hull so far, and the
/// result is the hull of that subset, inside the full hull. qhull merges coplanar facets at a cost
/// that grows about as n^2.5 in the vertices on one plane (a 4,000-corner prism: 6 s), so callers
/// that take untrusted points give a limit.
std::shared_ptr<MeshData> ConvexHull(const std::vector<Eigen::Vector3d>& points,
                                     int max_vertices = 0);

/// Signed volume enclosed by a closed triangle mesh (m^3): positive when its triangles are
/// counter-clockwise seen from outside.
double MeshVolume(const MeshData& mesh);

}  // namespace partsim
