// Closed, outward-facing, convex triangle meshes for the object generator: boxes, prisms of a
// convex profile (cylinders, rounded boxes, extruded profiles), lofts of homothetic rings
// (frustums, domes, spheres, rounded caps) and rods between two points. All are convex, so each
// mesh is its own exact collision shape.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <vector>

namespace partsim::internal::gen {

using V2 = Eigen::Vector2d;
using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

/// A triangle mesh (metres); triangles counter-clockwise seen from outside.
struct Mesh {
  std::vector<V3> v;
  std::vector<std::array<int, 3>> f;

  /// Applies x -> a x + t to every vertex (a with positive determinant keeps the orientation).
  Mesh& Transform(const M3& a, const V3& t);
  Mesh& Translate(const V3& t) { return Transform(M3::Identity(), t); }
};

/// Mass properties of a closed mesh of unit density: volume (m^3), centroid, and the second
/// moment integral of x x^T over the volume (about the origin).
struct VolumeProps {
  double volume = 0.0;
  V3 first = V3::Zero();   ///< integral of x dV
  M3 second = M3::Zero();  ///< integral of x x^T dV
};
VolumeProps ComputeVolumeProps(const Mesh& mesh);

/// A rigid frame: origin and rotation whose columns are the local x, y, z axes.
struct Frame {
  V3 o = V3::Zero();
  M3 r = M3::Identity();
  V3 operator*(const V3& p) const { return o + r * p; }
};
/// Frame at `o` whose local z axis is `z` (normalised); x is chosen deterministically, or
/// along `x_hint` projected off z when given.
Frame FrameZ(const V3& o, const V3& z, const V3& x_hint = V3::Zero());

// Convex polygons in the plane, counter-clockwise.
std::vector<V2> Circle(double r, int n, double phase = 0.0);
std::vector<V2> Rect(double w, double h);
/// Rectangle w x h with corners rounded by radius r (r <= min(w, h) / 2), `seg` per corner.
std::vector<V2> RoundRect(double w, double h, double r, int seg = 4);
/// Ellipse with half axes a, b.
std::vector<V2> Ellipse(double a, double b, int n);

/// Box with full sizes `size` centred at `c` (axes of the file frame).
Mesh Box(const V3& c, const V3& size);
/// Box between corners lo and hi.
Mesh BoxLoHi(const V3& lo, const V3& hi);
/// Box in frame f: centred at f.o, full sizes along f's axes.
Mesh Box(const Frame& f, const V3& size);
/// Prism: `poly` (local xy) extruded over local z in [z0, z1] of frame f.
Mesh Prism(const std::vector<V2>& poly, const Frame& f, double z0, double z1);
/// One ring of a loft: the polygon scaled by `s` (>= 0; 0 is an apex) and moved to local
/// (cx, cy, z).
struct Ring {
  double z;
  double s;
  double cx = 0.0;
  double cy = 0.0;
};
/// Loft of homothetic copies of a convex polygon over rings with increasing z, closed with flat
/// caps (or apices). Convex when the ring profile is concave.
Mesh Loft(const std::vector<V2>& poly, const std::vector<Ring>& rings, const Frame& f);
/// Cylinder of radius r between points a and b, n sides.
Mesh Rod(const V3& a, const V3& b, double r, int n = 16);
/// Box-section bar of width w (across, along `side`) and thickness t between points a and b.
Mesh Bar(const V3& a, const V3& b, double w, double t, const V3& side);
/// Cylinder along local z of frame f, z in [z0, z1].
Mesh Cylinder(const Frame& f, double r, double z0, double z1, int n = 32);
/// Frustum along local z of frame f: radius r0 at z0, r1 at z1.
Mesh Frustum(const Frame& f, double r0, double r1, double z0, double z1, int n = 32);
/// Ellipsoid with half axes `half` (along f's axes) centred at f.o.
Mesh Ellipsoid(const Frame& f, const V3& half, int rings = 12, int n = 24);
/// Sphere of radius r at c.
Mesh Sphere(const V3& c, double r, int rings = 12, int n = 24);
/// Spherical cap along local z of frame f: the part of the sphere of radius r centred at f.o
/// with local z in [z0, r] (z0 in (-r, r)).
Mesh Dome(const Frame& f, double r, double z0, int rings = 8, int n = 32);
/// Rounded slab: rounded rectangle w x d (local x, y) of height h (local z from 0), whose top
/// edges are bevelled by `bevel` (a chamfer of two steps).
Mesh RoundedSlab(const Frame& f, double w, double d, double h, double corner, double bevel,
                 int seg = 4);

}  // namespace partsim::internal::gen
