#include "partsim/assets/mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <tuple>

#include "partsim/assets/convex_decomposition.h"
#include "partsim/core/error.h"
#include "shape_meshes.h"

namespace partsim {
namespace {

const std::string kMeshDir = std::string(PARTSIM_TEST_DATA_DIR) + "/meshes/";

// Axis-aligned bounds of a mesh.
struct Bounds {
  Eigen::Vector3f lo, hi;
};

Bounds BoundsOf(const MeshData& m) {
  Bounds b{Eigen::Vector3f::Constant(1e30f), Eigen::Vector3f::Constant(-1e30f)};
  for (const Eigen::Vector3f& v : m.vertices) {
    b.lo = b.lo.cwiseMin(v);
    b.hi = b.hi.cwiseMax(v);
  }
  return b;
}

void ExpectBounds(const MeshData& m, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
                  float tol = 1e-5f) {
  Bounds b = BoundsOf(m);
  EXPECT_TRUE(b.lo.isApprox(lo, tol) || (b.lo - lo).norm() < tol)
      << "lo " << b.lo.transpose() << " expected " << lo.transpose();
  EXPECT_TRUE(b.hi.isApprox(hi, tol) || (b.hi - hi).norm() < tol)
      << "hi " << b.hi.transpose() << " expected " << hi.transpose();
}

// Signed volume of a closed mesh: positive when triangles wind counter-clockwise from outside.
double SignedVolume(const MeshData& m) {
  double v = 0;
  for (const Eigen::Vector3i& f : m.faces) {
    v += m.vertices[f[0]].cast<double>().dot(
             m.vertices[f[1]].cast<double>().cross(m.vertices[f[2]].cast<double>())) /
         6.0;
  }
  return v;
}

TEST(MeshTest, ObjCubeWithMtlColour) {
  std::vector<LoadedMesh> meshes = LoadMeshFile(kMeshDir + "cube.obj");
  ASSERT_EQ(meshes.size(), 1u);
  const MeshData& m = *meshes[0].mesh;
  EXPECT_EQ(m.faces.size(), 12u);
  // flat normals: each vertex belongs to one face direction, each normal has unit length
  ASSERT_EQ(m.normals.size(), m.vertices.size());
  for (const Eigen::Vector3f& n : m.normals) EXPECT_NEAR(n.norm(), 1.0f, 1e-5);
  ExpectBounds(m, Eigen::Vector3f::Constant(-0.5f), Eigen::Vector3f::Constant(0.5f));
  EXPECT_NEAR(SignedVolume(m), 1.0, 1e-5);
  EXPECT_EQ(m.source, kMeshDir + "cube.obj");
  EXPECT_TRUE(meshes[0].material.base_color.isApprox(Eigen::Vector4f(0.8f, 0.2f, 0.1f, 1.0f)))
      << meshes[0].material.base_color.transpose();
}

TEST(MeshTest, ScaleMultipliesVerticesPerAxis) {
  std::vector<LoadedMesh> meshes = LoadMeshFile(kMeshDir + "cube.obj", Eigen::Vector3d(2, 3, 4));
  ASSERT_EQ(meshes.size(), 1u);
  ExpectBounds(*meshes[0].mesh, Eigen::Vector3f(-1, -1.5f, -2), Eigen::Vector3f(1, 1.5f, 2));
  EXPECT_NEAR(SignedVolume(*meshes[0].mesh), 24.0, 1e-4);
}

TEST(MeshTest, MirroringScaleKeepsOutwardWinding) {
  std::vector<LoadedMesh> meshes = LoadMeshFile(kMeshDir + "cube.obj", Eigen::Vector3d(-1, 1, 1));
  EXPECT_NEAR(SignedVolume(*meshes[0].mesh), 1.0, 1e-5);
}

TEST(MeshTest, AsciiStl) {
  std::shared_ptr<MeshData> m = LoadMergedMesh(kMeshDir + "box.stl");
  EXPECT_EQ(m->faces.size(), 12u);
  ExpectBounds(*m, Eigen::Vector3f::Zero(), Eigen::Vector3f(0.2f, 0.1f, 0.05f));
  EXPECT_NEAR(SignedVolume(*m), 0.2 * 0.1 * 0.05, 1e-7);
}

TEST(MeshTest, ColladaUnitsAndZUp) {
  // 10 x 20 x 30 cm box translated 10 cm along x, written in centimetres with Z_UP
  std::vector<LoadedMesh> meshes = LoadMeshFile(kMeshDir + "box_cm.dae");
  ASSERT_EQ(meshes.size(), 1u);
  ExpectBounds(*meshes[0].mesh, Eigen::Vector3f(0.1f, 0, 0), Eigen::Vector3f(0.2f, 0.2f, 0.3f));
  EXPECT_NEAR(SignedVolume(*meshes[0].mesh), 0.1 * 0.2 * 0.3, 1e-6);
  EXPECT_TRUE(meshes[0].material.base_color.isApprox(Eigen::Vector4f(0.1f, 0.2f, 0.7f, 1.0f)))
      << meshes[0].material.base_color.transpose();
}

TEST(MeshTest, ColladaYUpStandsUpAlongZ) {
  // box 0.1 x 0.2 x 0.3 m with y up: its height (file y) becomes z, file z becomes -y
  std::vector<LoadedMesh> meshes = LoadMeshFile(kMeshDir + "box_yup.dae");
  ASSERT_EQ(meshes.size(), 1u);
  ExpectBounds(*meshes[0].mesh, Eigen::Vector3f(0, -0.3f, 0), Eigen::Vector3f(0.1f, 0, 0.2f));
  EXPECT_NEAR(SignedVolume(*meshes[0].mesh), 0.1 * 0.2 * 0.3, 1e-6);
}

TEST(MeshTest, GltfEmbeddedBufferAndBaseColour) {
  std::vector<LoadedMesh> meshes =
      LoadMeshFile(kMeshDir + "box.gltf", Eigen::Vector3d::Constant(2));
  ASSERT_EQ(meshes.size(), 1u);
  ExpectBounds(*meshes[0].mesh, Eigen::Vector3f(-0.2f, -0.4f, -0.6f),
               Eigen::Vector3f(0.2f, 0.4f, 0.6f));
  EXPECT_TRUE(meshes[0].material.base_color.isApprox(Eigen::Vector4f(0.1f, 0.9f, 0.2f, 1.0f)))
      << meshes[0].material.base_color.transpose();
  EXPECT_NEAR(meshes[0].material.metallic, 0.25f, 1e-6);
  EXPECT_NEAR(meshes[0].material.roughness, 0.5f, 1e-6);
}

TEST(MeshTest, SubMeshesKeepTheirMaterials) {
  std::vector<LoadedMesh> meshes = LoadMeshFile(kMeshDir + "parts.obj");
  ASSERT_EQ(meshes.size(), 2u);
  // order follows the file; find each by colour
  int red = meshes[0].material.base_color.x() > 0.5f ? 0 : 1;
  EXPECT_TRUE(meshes[red].material.base_color.head<3>().isApprox(Eigen::Vector3f(1, 0, 0)));
  EXPECT_TRUE(meshes[1 - red].material.base_color.head<3>().isApprox(Eigen::Vector3f(0, 0, 1)));
  ExpectBounds(*meshes[red].mesh, Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 1, 1));
  ExpectBounds(*meshes[1 - red].mesh, Eigen::Vector3f(2, 0, 0), Eigen::Vector3f(3, 2, 1));

  std::shared_ptr<MeshData> merged = LoadMergedMesh(kMeshDir + "parts.obj");
  EXPECT_EQ(merged->faces.size(), 24u);
  ExpectBounds(*merged, Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(3, 2, 1));
  EXPECT_NEAR(SignedVolume(*merged), 1.0 + 2.0, 1e-5);
}

TEST(MeshTest, SplitTwoBoxesIntoTwoComponents) {
  std::shared_ptr<MeshData> m = LoadMergedMesh(kMeshDir + "two_boxes.obj");
  std::vector<std::shared_ptr<MeshData>> pieces = SplitConnectedComponents(*m);
  ASSERT_EQ(pieces.size(), 2u);
  for (const auto& p : pieces) {
    EXPECT_EQ(p->faces.size(), 12u);
    // flat-shaded corners are welded for the split but stay apart in the piece
    EXPECT_GE(p->vertices.size(), 8u);
    EXPECT_NEAR(SignedVolume(*p), 1.0, 1e-5);
  }
  Bounds a = BoundsOf(*pieces[0]), b = BoundsOf(*pieces[1]);
  EXPECT_NEAR(std::min(a.lo.x(), b.lo.x()), 0.0f, 1e-6);
  EXPECT_NEAR(std::max(a.lo.x(), b.lo.x()), 3.0f, 1e-6);
}

TEST(MeshTest, SplitWeldsDuplicatedVertices) {
  // two triangles of a square that share an edge only through duplicated vertices
  MeshData m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.faces = {{0, 1, 2}, {3, 4, 5}};
  EXPECT_EQ(SplitConnectedComponents(m).size(), 1u);
  // moving the second triangle away disconnects it
  for (int i = 3; i < 6; ++i) m.vertices[i].z() += 1.0f;
  EXPECT_EQ(SplitConnectedComponents(m).size(), 2u);
}

TEST(MeshTest, ConvexPiecesPerSubMeshAndComponent) {
  EXPECT_EQ(LoadConvexPieces(kMeshDir + "two_boxes.obj").size(), 2u);
  EXPECT_EQ(LoadConvexPieces(kMeshDir + "parts.obj").size(), 2u);
  EXPECT_EQ(LoadConvexPieces(kMeshDir + "cube.obj").size(), 1u);
}

TEST(MeshTest, MissingFileNamesTheFile) {
  try {
    LoadMeshFile(kMeshDir + "no_such_mesh.obj");
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_mesh.obj"), std::string::npos) << e.what();
  }
}

TEST(MeshTest, BrokenFileNamesTheFile) {
  std::filesystem::path p = std::filesystem::temp_directory_path() / "partsim_broken_mesh.stl";
  {
    std::ofstream f(p);
    f << "this is not a mesh at all\n";
  }
  try {
    LoadMeshFile(p.string());
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("partsim_broken_mesh.stl"), std::string::npos) << e.what();
  }
  std::filesystem::remove(p);
}

TEST(MeshTest, DirectoryIsNotAMesh) { EXPECT_THROW(LoadMeshFile(kMeshDir), Error); }

// ---------------------------------------------------------------------------------------------
// convex collision pieces

std::shared_ptr<const MeshData> Shared(MeshData m) {
  return std::make_shared<const MeshData>(std::move(m));
}

// A mesh of points with a fan of triangles over them.
MeshData Points(const std::vector<Eigen::Vector3f>& points) {
  MeshData m;
  m.vertices = points;
  for (int i = 1; i + 1 < static_cast<int>(points.size()); ++i) m.faces.emplace_back(0, i, i + 1);
  if (points.size() < 3) m.faces.emplace_back(0, 0, static_cast<int>(points.size()) - 1);
  return m;
}

// Extent of a mesh's vertices along a unit direction (m).
double ExtentAlong(const MeshData& m, const Eigen::Vector3d& d) {
  double lo = 1e30, hi = -1e30;
  for (const Eigen::Vector3f& v : m.vertices) {
    lo = std::min(lo, v.cast<double>().dot(d));
    hi = std::max(hi, v.cast<double>().dot(d));
  }
  return hi - lo;
}

TEST(ConvexPieceTest, FlatQuadGetsAThinHullAlongItsNormal) {
  // a 0.4 m square in a tilted plane: 4 points, no volume
  const Eigen::Vector3d n = Eigen::Vector3d(1, 2, 3).normalized();
  const Eigen::Vector3d u = n.unitOrthogonal(), w = n.cross(u);
  std::vector<Eigen::Vector3f> quad;
  const int corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const auto& c : corners)
    quad.push_back((0.4 * (c[0] * u + c[1] * w) + Eigen::Vector3d(1, 1, 1)).cast<float>());
  ConvexPieceCheck c = CheckConvexPiece(Shared(Points(quad)));
  ASSERT_TRUE(c.piece);
  EXPECT_NE(c.repair.find("flat"), std::string::npos) << c.repair;
  EXPECT_FALSE(c.non_convex);
  // 3% of its size, at most 5 mm, along the normal; the square itself is unchanged
  EXPECT_DOUBLE_EQ(c.thickness, 0.005);
  EXPECT_NEAR(ExtentAlong(*c.piece, n), 0.005, 1e-5);
  EXPECT_NEAR(ExtentAlong(*c.piece, u), 0.4, 1e-5);
  EXPECT_NEAR(ExtentAlong(*c.piece, w), 0.4, 1e-5);
  // a closed hull that MuJoCo accepts
  EXPECT_GT(MeshVolume(*c.piece), 0.4 * 0.4 * 0.005 * 0.99);
}

TEST(ConvexPieceTest, TriangleLineAndTinyPieces) {
  // three points: a flat triangle, thickened
  ConvexPieceCheck tri =
      CheckConvexPiece(Shared(Points({{0, 0, 0}, {0.03f, 0, 0}, {0, 0.03f, 0}})));
  ASSERT_TRUE(tri.piece);
  EXPECT_NE(tri.repair.find("fewer than 4"), std::string::npos) << tri.repair;
  // 3% of its largest extent, 0.03 * sqrt(2) m, along its normal
  EXPECT_NEAR(tri.thickness, 0.03 * 0.03 * std::sqrt(2.0), 1e-7);
  EXPECT_NEAR(ExtentAlong(*tri.piece, Eigen::Vector3d::UnitZ()), tri.thickness, 1e-6);
  // points on a line: thickened across both of its thin directions
  ConvexPieceCheck line =
      CheckConvexPiece(Shared(Points({{0, 0, 0}, {0.5f, 0, 0}, {1, 0, 0}, {0.2f, 0, 0}})));
  ASSERT_TRUE(line.piece);
  EXPECT_NE(line.repair.find("line"), std::string::npos) << line.repair;
  EXPECT_NEAR(ExtentAlong(*line.piece, Eigen::Vector3d::UnitY()), 0.005, 1e-6);
  EXPECT_NEAR(ExtentAlong(*line.piece, Eigen::Vector3d::UnitZ()), 0.005, 1e-6);
  // a tetrahedron 10 micrometres across: dropped
  ConvexPieceCheck tiny =
      CheckConvexPiece(Shared(Points({{0, 0, 0}, {1e-5f, 0, 0}, {0, 1e-5f, 0}, {0, 0, 1e-5f}})));
  EXPECT_FALSE(tiny.piece);
  EXPECT_NE(tiny.repair.find("dropped"), std::string::npos) << tiny.repair;
  // no vertices at all
  EXPECT_FALSE(CheckConvexPiece(Shared(MeshData())).piece);
}

TEST(ConvexPieceTest, ConvexShapesPassAndNonConvexOnesAreFlagged) {
  for (const MeshData& convex :
       {testing::Box(), Points({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}})}) {
    ConvexPieceCheck c = CheckConvexPiece(Shared(convex));
    EXPECT_TRUE(c.piece);
    EXPECT_TRUE(c.repair.empty()) << c.repair;
    EXPECT_FALSE(c.non_convex);
    EXPECT_EQ(c.deep_area_fraction, 0.0);
  }
  // the box is closed: its volume is its hull's
  EXPECT_NEAR(CheckConvexPiece(Shared(testing::Box())).volume_ratio, 1.0, 1e-6);
  // an L fills 0.3 x 0.05 + 0.25 x 0.05 of its hull's triangle-topped 0.3 x 0.3 profile
  ConvexPieceCheck l = CheckConvexPiece(Shared(testing::LShape()));
  EXPECT_TRUE(l.non_convex);
  const double profile = 0.3 * 0.3 - 0.5 * 0.25 * 0.25;
  EXPECT_NEAR(l.volume_ratio, (0.3 * 0.05 + 0.25 * 0.05) / profile, 1e-6);
  // the same L as an open surface (half its triangles): depth alone decides
  MeshData open = testing::LShape();
  open.faces.resize(open.faces.size() / 2);
  ConvexPieceCheck lo = CheckConvexPiece(Shared(open));
  EXPECT_TRUE(std::isnan(lo.volume_ratio));
  EXPECT_GT(lo.deep_area_fraction, 0.1);
  EXPECT_TRUE(lo.non_convex);
  // a torus is closed and clearly not convex; a thin-walled cup too
  EXPECT_TRUE(CheckConvexPiece(Shared(testing::Torus(0.2, 0.05))).non_convex);
  EXPECT_TRUE(CheckConvexPiece(Shared(testing::Cup(0.05, 0.1, 0.004, 32))).non_convex);
}

// How far a point lies outside a closed convex mesh (m): its largest signed distance to the planes
// of the triangles, 0 or less inside.
double OutsideConvex(const MeshData& hull, const Eigen::Vector3d& p) {
  double d = -1e30;
  for (const Eigen::Vector3i& f : hull.faces) {
    const Eigen::Vector3d a = hull.vertices[f[0]].cast<double>();
    const Eigen::Vector3d n =
        (hull.vertices[f[1]].cast<double>() - a).cross(hull.vertices[f[2]].cast<double>() - a);
    if (n.norm() > 1e-12) d = std::max(d, n.normalized().dot(p - a));
  }
  return d;
}

// A regular polygon of `corners` corners and radius 0.5 m in the plane z = `z`.
std::vector<Eigen::Vector3f> Polygon(int corners, float z = 0.0f) {
  std::vector<Eigen::Vector3f> out;
  for (int i = 0; i < corners; ++i) {
    const double a = 2 * M_PI * i / corners;
    out.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), z);
  }
  return out;
}

TEST(ConvexPieceTest, FlatFaceOfManyCornersGetsAThinHullOfBoundedSize) {
  // a flat 10,000-corner face: its thin hull has 20,000 corners, and qhull's merging of the
  // coplanar facets (partsim's hull, then MuJoCo's when it compiles the piece) grows about as
  // n^2.5 in them; the piece keeps at most kMaxConvexPieceVertices
  const std::vector<Eigen::Vector3f> face = Polygon(10000);
  ConvexPieceCheck c = CheckConvexPiece(Shared(Points(face)));
  ASSERT_TRUE(c.piece);
  EXPECT_NE(c.repair.find("flat"), std::string::npos) << c.repair;
  EXPECT_DOUBLE_EQ(c.thickness, 0.005);
  EXPECT_LE(c.piece->vertices.size(), static_cast<size_t>(kMaxConvexPieceVertices));
  EXPECT_NE(c.simplified.find("collides as the hull of"), std::string::npos) << c.simplified;
  // still the face, 5 mm thick: every corner at most 1 mm (0.1% of its size) outside the piece
  EXPECT_NEAR(ExtentAlong(*c.piece, Eigen::Vector3d::UnitZ()), 0.005, 1e-6);
  EXPECT_NEAR(ExtentAlong(*c.piece, Eigen::Vector3d::UnitX()), 1.0, 1e-3);
  EXPECT_NEAR(ExtentAlong(*c.piece, Eigen::Vector3d::UnitY()), 1.0, 1e-3);
  double outside = 0;
  for (const Eigen::Vector3f& v : face)
    outside = std::max(outside, OutsideConvex(*c.piece, v.cast<double>()));
  EXPECT_LT(outside, 1e-3);
  EXPECT_GT(MeshVolume(*c.piece), M_PI * 0.25 * 0.005 * 0.99);
}

TEST(ConvexPieceTest, SolidOfManyPointsCollidesAsABoundedHull) {
  // the side of a cylinder of 5,000 segments: 10,000 points on two planes, convex
  MeshData side;
  for (float z : {0.0f, 0.3f}) {
    const std::vector<Eigen::Vector3f> rim = Polygon(5000, z);
    side.vertices.insert(side.vertices.end(), rim.begin(), rim.end());
  }
  for (int i = 0; i < 5000; ++i) {
    const int j = (i + 1) % 5000;
    side.faces.emplace_back(i, j, 5000 + j);
    side.faces.emplace_back(i, 5000 + j, 5000 + i);
  }
  ConvexPieceCheck c = CheckConvexPiece(Shared(side));
  ASSERT_TRUE(c.piece);
  EXPECT_TRUE(c.repair.empty()) << c.repair;
  EXPECT_FALSE(c.non_convex);
  // MuJoCo gets a hull of at most kMaxConvexPieceVertices, not the 10,000 points
  EXPECT_LE(c.piece->vertices.size(), static_cast<size_t>(kMaxConvexPieceVertices));
  EXPECT_FALSE(c.simplified.empty());
  double outside = 0;
  for (const Eigen::Vector3f& v : side.vertices)
    outside = std::max(outside, OutsideConvex(*c.piece, v.cast<double>()));
  EXPECT_LT(outside, 1e-3);
  // a box of 8 points is kept as it is, and says nothing
  auto box = Shared(testing::Box());
  ConvexPieceCheck b = CheckConvexPiece(box);
  EXPECT_EQ(b.piece, box);
  EXPECT_TRUE(b.simplified.empty()) << b.simplified;
}

TEST(ConvexPieceTest, ConvexHullKeepsAtMostMaxVertices) {
  std::vector<Eigen::Vector3d> prism;
  for (const Eigen::Vector3f& v : Polygon(3000)) {
    prism.push_back(v.cast<double>());
    prism.push_back(v.cast<double>() + Eigen::Vector3d(0, 0, 0.01));
  }
  std::shared_ptr<MeshData> capped = ConvexHull(prism, 100);
  EXPECT_LE(capped->vertices.size(), 100u);
  EXPECT_GT(MeshVolume(*capped), 0.0);
  // the limit counts the 4 points of qhull's first simplex
  EXPECT_THROW(ConvexHull(prism, 3), Error);
  // no limit: every corner of a 20-sided prism
  std::vector<Eigen::Vector3d> small;
  for (const Eigen::Vector3f& v : Polygon(20)) {
    small.push_back(v.cast<double>());
    small.push_back(v.cast<double>() + Eigen::Vector3d(0, 0, 0.01));
  }
  EXPECT_EQ(ConvexHull(small)->vertices.size(), 40u);
}

}  // namespace
}  // namespace partsim
