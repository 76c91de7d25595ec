// Triangle meshes of primitive visual shapes: box, sphere, capsule, cylinder and plane, in the
// shape's frame, counter-clockwise seen from outside, with per-vertex normals (flat on box faces,
// caps and the plane; smooth on curved surfaces).
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/number_text.h"
#include "partsim/core/constants.h"
#include "partsim/core/error.h"
#include "partsim/render/backend.h"

namespace partsim {
namespace {

constexpr int kSegments = 32;  // around the axis
constexpr int kRings = 16;     // from pole to pole of a sphere

// appends a vertex and returns its index
int AddVertex(MeshData* m, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  m->vertices.push_back(p.cast<float>());
  m->normals.push_back(n.normalized().cast<float>());
  return static_cast<int>(m->vertices.size()) - 1;
}

// a quad a-b-c-d (counter-clockwise seen from outside) as two triangles
void AddQuad(MeshData* m, int a, int b, int c, int d) {
  m->faces.emplace_back(a, b, c);
  m->faces.emplace_back(a, c, d);
}

std::shared_ptr<MeshData> Box(const Eigen::Vector3d& h) {
  auto m = std::make_shared<MeshData>();
  // one face per axis and sign, with its own four vertices for flat normals
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {1, -1}) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = sign;
      // u, v span the face so that u x v = n
      Eigen::Vector3d u = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
      u[(axis + 1) % 3] = 1;
      v[(axis + 2) % 3] = sign;
      Eigen::Vector3d c = n.cwiseProduct(h);
      Eigen::Vector3d du = u.cwiseProduct(h), dv = v.cwiseProduct(h);
      int a = AddVertex(m.get(), c - du - dv, n);
      int b = AddVertex(m.get(), c + du - dv, n);
      int cc = AddVertex(m.get(), c + du + dv, n);
      int d = AddVertex(m.get(), c - du + dv, n);
      AddQuad(m.get(), a, b, cc, d);
    }
  }
  return m;
}

// A surface of revolution about x: a grid of (kSegments + 1) x rows vertices, where row r has
// its point at axial position x[r] and radius rad[r] with outward normal (nx[r], nr[r]).
void AddRevolution(MeshData* m, const std::vector<double>& x, const std::vector<double>& rad,
                   const std::vector<double>& nx, const std::vector<double>& nr) {
  int base = static_cast<int>(m->vertices.size());
  int rows = static_cast<int>(x.size());
  for (int r = 0; r < rows; ++r) {
    for (int s = 0; s <= kSegments; ++s) {
      double phi = 2 * kPi * s / kSegments;
      Eigen::Vector3d radial(0, std::cos(phi), std::sin(phi));
      Eigen::Vector3d p = Eigen::Vector3d(x[r], 0, 0) + rad[r] * radial;
      Eigen::Vector3d n = Eigen::Vector3d(nx[r], 0, 0) + nr[r] * radial;
      AddVertex(m, p, n);
    }
  }
  // rows run from -x to +x; with phi turning about +x this winding faces outward
  for (int r = 0; r + 1 < rows; ++r) {
    for (int s = 0; s < kSegments; ++s) {
      int a = base + r * (kSegments + 1) + s;
      int b = a + 1;
      int c = b + (kSegments + 1);
      int d = a + (kSegments + 1);
      // skip the degenerate triangle at a pole
      if (rad[r] > 0) m->faces.emplace_back(a, b, c);
      if (rad[r + 1] > 0) m->faces.emplace_back(a, c, d);
    }
  }
}

// rows of a hemisphere cap or a whole sphere: polar angle theta from -x (0) to +x (pi)
void SphereRows(double radius, double x_offset, int theta_lo, int theta_hi, std::vector<double>* x,
                std::vector<double>* rad, std::vector<double>* nx, std::vector<double>* nr) {
  for (int i = theta_lo; i <= theta_hi; ++i) {
    double theta = kPi * i / kRings;
    double c = -std::cos(theta), s = std::sin(theta);
    x->push_back(x_offset + radius * c);
    rad->push_back(i == 0 || i == kRings ? 0.0 : radius * s);
    nx->push_back(c);
    nr->push_back(s);
  }
}

std::shared_ptr<MeshData> Sphere(double radius) {
  auto m = std::make_shared<MeshData>();
  std::vector<double> x, rad, nx, nr;
  SphereRows(radius, 0, 0, kRings, &x, &rad, &nx, &nr);
  AddRevolution(m.get(), x, rad, nx, nr);
  return m;
}

std::shared_ptr<MeshData> Capsule(double radius, double half_length) {
  auto m = std::make_shared<MeshData>();
  std::vector<double> x, rad, nx, nr;
  // the -x cap up to its equator, then the +x cap from its equator: the equator rows join the
  // two caps with the cylinder between them (same normals, so shading is smooth)
  SphereRows(radius, -half_length, 0, kRings / 2, &x, &rad, &nx, &nr);
  SphereRows(radius, half_length, kRings / 2, kRings, &x, &rad, &nx, &nr);
  AddRevolution(m.get(), x, rad, nx, nr);
  return m;
}

// flat disc at axial position x facing +x (sign 1) or -x (sign -1)
void AddDisc(MeshData* m, double x, double radius, int sign) {
  Eigen::Vector3d n(sign, 0, 0);
  int centre = AddVertex(m, Eigen::Vector3d(x, 0, 0), n);
  int first = static_cast<int>(m->vertices.size());
  for (int s = 0; s < kSegments; ++s) {
    double phi = 2 * kPi * s / kSegments;
    AddVertex(m, Eigen::Vector3d(x, radius * std::cos(phi), radius * std::sin(phi)), n);
  }
  for (int s = 0; s < kSegments; ++s) {
    int a = first + s, b = first + (s + 1) % kSegments;
    // phi turns counter-clockwise about +x
    if (sign > 0)
      m->faces.emplace_back(centre, a, b);
    else
      m->faces.emplace_back(centre, b, a);
  }
}

std::shared_ptr<MeshData> Cylinder(double radius, double half_length) {
  auto m = std::make_shared<MeshData>();
  AddRevolution(m.get(), {-half_length, half_length}, {radius, radius}, {0, 0}, {1, 1});
  AddDisc(m.get(), half_length, radius, 1);
  AddDisc(m.get(), -half_length, radius, -1);
  return m;
}

std::shared_ptr<MeshData> Plane(double hx, double hy) {
  auto m = std::make_shared<MeshData>();
  Eigen::Vector3d n(0, 0, 1);
  int a = AddVertex(m.get(), Eigen::Vector3d(-hx, -hy, 0), n);
  int b = AddVertex(m.get(), Eigen::Vector3d(hx, -hy, 0), n);
  int c = AddVertex(m.get(), Eigen::Vector3d(hx, hy, 0), n);
  int d = AddVertex(m.get(), Eigen::Vector3d(-hx, hy, 0), n);
  AddQuad(m.get(), a, b, c, d);
  // texture coordinates one per metre, so a tiled texture keeps its scale
  for (const Eigen::Vector3f& v : m->vertices) m->uvs.emplace_back(v.x(), v.y());
  return m;
}

}  // namespace

std::shared_ptr<MeshData> MakePrimitiveMesh(const VisualShape& shape) {
  std::shared_ptr<MeshData> m;
  switch (shape.type) {
    case ShapeType::kBox:
      m = Box(shape.half_size);
      break;
    case ShapeType::kSphere:
      m = Sphere(shape.radius);
      break;
    case ShapeType::kCapsule:
      m = Capsule(shape.radius, shape.half_length);
      break;
    case ShapeType::kCylinder:
      m = Cylinder(shape.radius, shape.half_length);
      break;
    case ShapeType::kPlane:
      m = Plane(shape.half_size.x(), shape.half_size.y());
      break;
    case ShapeType::kConvexMesh:
      throw Error("MakePrimitiveMesh: a mesh visual is not a primitive (use its mesh)");
  }
  m->name = ShapeTypeName(shape.type);
  return m;
}

namespace internal {

std::string PrimitiveKey(const VisualShape& shape) {
  // "%.17g" reads back bit-exact: equal text, equal sizes
  return std::to_string(static_cast<int>(shape.type)) + " " + Num(shape.half_size.x()) + " " +
         Num(shape.half_size.y()) + " " + Num(shape.half_size.z()) + " " + Num(shape.radius) + " " +
         Num(shape.half_length);
}

}  // namespace internal

}  // namespace partsim
