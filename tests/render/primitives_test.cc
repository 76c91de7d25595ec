// Meshes of primitive visuals: closed, outward, with the right size and unit normals.
#include <gtest/gtest.h>

#include <cmath>

#include "partsim/core/error.h"
#include "partsim/render/backend.h"

namespace partsim {
namespace {

// volume enclosed by a closed, outward mesh (divergence theorem)
double Volume(const MeshData& m) {
  double v = 0;
  for (const Eigen::Vector3i& f : m.faces) {
    Eigen::Vector3d a = m.vertices[f[0]].cast<double>(), b = m.vertices[f[1]].cast<double>(),
                    c = m.vertices[f[2]].cast<double>();
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

// every face of a convex shape centred at the origin points away from it and agrees with its
// vertex normals
void ExpectOutward(const MeshData& m, const std::string& what) {
  ASSERT_EQ(m.normals.size(), m.vertices.size()) << what;
  for (const Eigen::Vector3f& n : m.normals) EXPECT_NEAR(n.norm(), 1.0f, 1e-5f) << what;
  for (const Eigen::Vector3i& f : m.faces) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_GE(f[k], 0);
      ASSERT_LT(f[k], static_cast<int>(m.vertices.size()));
    }
    Eigen::Vector3f a = m.vertices[f[0]], b = m.vertices[f[1]], c = m.vertices[f[2]];
    Eigen::Vector3f n = (b - a).cross(c - a);
    ASSERT_GT(n.norm(), 0) << what << ": degenerate triangle";
    EXPECT_GT(n.dot((a + b + c) / 3), 0) << what;
    for (int k = 0; k < 3; ++k) EXPECT_GT(n.dot(m.normals[f[k]]), 0) << what;
  }
}

VisualShape Shape(ShapeType type) {
  VisualShape v;
  v.type = type;
  v.half_size = Eigen::Vector3d(0.1, 0.2, 0.3);
  v.radius = 0.15;
  v.half_length = 0.25;
  return v;
}

TEST(PrimitivesTest, BoxIsClosedOutwardAndFlat) {
  auto m = MakePrimitiveMesh(Shape(ShapeType::kBox));
  EXPECT_EQ(m->faces.size(), 12u);
  ExpectOutward(*m, "box");
  EXPECT_NEAR(Volume(*m), 0.2 * 0.4 * 0.6, 1e-6);
  // flat: each vertex normal is an axis
  for (const Eigen::Vector3f& n : m->normals) EXPECT_NEAR(n.cwiseAbs().maxCoeff(), 1.0f, 1e-6f);
}

TEST(PrimitivesTest, CurvedShapesAreClosedOutwardAndNearTheirVolume) {
  const double r = 0.15, h = 0.25, pi = M_PI;
  auto sphere = MakePrimitiveMesh(Shape(ShapeType::kSphere));
  ExpectOutward(*sphere, "sphere");
  EXPECT_NEAR(Volume(*sphere), 4.0 / 3 * pi * r * r * r, 0.03 * 4.0 / 3 * pi * r * r * r);
  // smooth: the normal of a sphere vertex is its direction from the centre
  for (size_t i = 0; i < sphere->vertices.size(); ++i) {
    EXPECT_NEAR(sphere->vertices[i].norm(), r, 1e-6);
    EXPECT_GT(sphere->normals[i].dot(sphere->vertices[i].normalized()), 0.9999f);
  }
  auto capsule = MakePrimitiveMesh(Shape(ShapeType::kCapsule));
  ExpectOutward(*capsule, "capsule");
  double vc = pi * r * r * 2 * h + 4.0 / 3 * pi * r * r * r;
  EXPECT_NEAR(Volume(*capsule), vc, 0.03 * vc);
  auto cylinder = MakePrimitiveMesh(Shape(ShapeType::kCylinder));
  ExpectOutward(*cylinder, "cylinder");
  double vy = pi * r * r * 2 * h;
  EXPECT_NEAR(Volume(*cylinder), vy, 0.03 * vy);
  // along x: the extent in x is the length
  float xmax = 0, ymax = 0;
  for (const Eigen::Vector3f& v : cylinder->vertices) {
    xmax = std::max(xmax, std::abs(v.x()));
    ymax = std::max(ymax, std::abs(v.y()));
  }
  EXPECT_NEAR(xmax, h, 1e-6);
  EXPECT_NEAR(ymax, r, 1e-6);
}

TEST(PrimitivesTest, PlaneFacesUp) {
  VisualShape v = Shape(ShapeType::kPlane);
  v.half_size = Eigen::Vector3d(10, 5, 0);
  auto m = MakePrimitiveMesh(v);
  ASSERT_EQ(m->faces.size(), 2u);
  for (const Eigen::Vector3i& f : m->faces) {
    Eigen::Vector3f n =
        (m->vertices[f[1]] - m->vertices[f[0]]).cross(m->vertices[f[2]] - m->vertices[f[0]]);
    EXPECT_GT(n.z(), 0);
  }
  for (const Eigen::Vector3f& n : m->normals) EXPECT_EQ(n, Eigen::Vector3f(0, 0, 1));
  EXPECT_FLOAT_EQ(m->vertices[2].x(), 10.0f);
  EXPECT_FLOAT_EQ(m->vertices[2].y(), 5.0f);
}

TEST(PrimitivesTest, MeshVisualIsNotAPrimitive) {
  EXPECT_THROW(MakePrimitiveMesh(Shape(ShapeType::kConvexMesh)), Error);
}

}  // namespace
}  // namespace partsim
