#include "assets/generator/mesh_builder.h"

#include <algorithm>
#include <cmath>

#include "partsim/core/constants.h"

namespace partsim::internal::gen {

Mesh& Mesh::Transform(const M3& a, const V3& t) {
  for (V3& p : v) p = a * p + t;
  return *this;
}

VolumeProps ComputeVolumeProps(const Mesh& mesh) {
  // sum over tetrahedra (origin, a, b, c) of each triangle
  VolumeProps out;
  for (const auto& t : mesh.f) {
    const V3& a = mesh.v[t[0]];
    const V3& b = mesh.v[t[1]];
    const V3& c = mesh.v[t[2]];
    double det = a.dot(b.cross(c));
    V3 s = a + b + c;
    out.volume += det / 6.0;
    out.first += det / 24.0 * s;
    out.second += det / 120.0 *
                  (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  return out;
}

Frame FrameZ(const V3& o, const V3& z, const V3& x_hint) {
  Frame f;
  f.o = o;
  V3 zz = z.normalized();
  V3 x = x_hint - x_hint.dot(zz) * zz;
  if (x.norm() < 1e-9) {
    // a fixed choice: the file axis least aligned with z
    V3 ref = std::abs(zz.x()) < 0.9 ? V3(1, 0, 0) : V3(0, 1, 0);
    x = ref - ref.dot(zz) * zz;
  }
  x.normalize();
  V3 y = zz.cross(x);
  f.r.col(0) = x;
  f.r.col(1) = y;
  f.r.col(2) = zz;
  return f;
}

std::vector<V2> Circle(double r, int n, double phase) {
  std::vector<V2> p;
  for (int i = 0; i < n; ++i) {
    double a = phase + 2 * kPi * i / n;
    p.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return p;
}

std::vector<V2> Ellipse(double a, double b, int n) {
  std::vector<V2> p;
  for (int i = 0; i < n; ++i) {
    double t = 2 * kPi * i / n;
    p.emplace_back(a * std::cos(t), b * std::sin(t));
  }
  return p;
}

std::vector<V2> Rect(double w, double h) {
  return {V2(-w / 2, -h / 2), V2(w / 2, -h / 2), V2(w / 2, h / 2), V2(-w / 2, h / 2)};
}

std::vector<V2> RoundRect(double w, double h, double r, int seg) {
  r = std::min(r, 0.5 * std::min(w, h) * 0.999);
  if (r <= 1e-5) return Rect(w, h);
  std::vector<V2> p;
  const V2 centres[4] = {V2(w / 2 - r, -h / 2 + r), V2(w / 2 - r, h / 2 - r),
                         V2(-w / 2 + r, h / 2 - r), V2(-w / 2 + r, -h / 2 + r)};
  for (int c = 0; c < 4; ++c) {
    double a0 = -kPi / 2 + c * kPi / 2;
    for (int i = 0; i <= seg; ++i) {
      double a = a0 + (kPi / 2) * i / seg;
      p.push_back(centres[c] + r * V2(std::cos(a), std::sin(a)));
    }
  }
  return p;
}

Mesh Loft(const std::vector<V2>& poly, const std::vector<Ring>& rings, const Frame& f) {
  Mesh m;
  const int n = static_cast<int>(poly.size());
  std::vector<int> start;  // first vertex of each ring; an apex ring has one vertex
  for (const Ring& ring : rings) {
    start.push_back(static_cast<int>(m.v.size()));
    if (ring.s <= 0) {
      m.v.push_back(f * V3(ring.cx, ring.cy, ring.z));
    } else {
      for (const V2& q : poly)
        m.v.push_back(f * V3(ring.cx + ring.s * q.x(), ring.cy + ring.s * q.y(), ring.z));
    }
  }
  auto apex = [&](size_t i) { return rings[i].s <= 0; };
  // bottom and top caps
  if (!apex(0)) {
    for (int j = 1; j + 1 < n; ++j) m.f.push_back({start[0], start[0] + j + 1, start[0] + j});
  }
  const size_t last = rings.size() - 1;
  if (!apex(last)) {
    for (int j = 1; j + 1 < n; ++j)
      m.f.push_back({start[last], start[last] + j, start[last] + j + 1});
  }
  // side bands
  for (size_t i = 0; i + 1 < rings.size(); ++i) {
    for (int j = 0; j < n; ++j) {
      int k = (j + 1) % n;
      if (apex(i)) {
        m.f.push_back({start[i], start[i + 1] + k, start[i + 1] + j});
      } else if (apex(i + 1)) {
        m.f.push_back({start[i] + j, start[i] + k, start[i + 1]});
      } else {
        int lo_j = start[i] + j, lo_k = start[i] + k, hi_j = start[i + 1] + j,
            hi_k = start[i + 1] + k;
        m.f.push_back({lo_j, lo_k, hi_k});
        m.f.push_back({lo_j, hi_k, hi_j});
      }
    }
  }
  // a frame with a negative determinant (mirror) would flip the triangles
  if (f.r.determinant() < 0) {
    for (auto& t : m.f) std::swap(t[1], t[2]);
  }
  return m;
}

Mesh Prism(const std::vector<V2>& poly, const Frame& f, double z0, double z1) {
  return Loft(poly, {Ring{z0, 1.0}, Ring{z1, 1.0}}, f);
}

Mesh Box(const Frame& f, const V3& size) {
  return Prism(Rect(size.x(), size.y()), f, -size.z() / 2, size.z() / 2);
}

Mesh Box(const V3& c, const V3& size) {
  Frame f;
  f.o = c;
  return Box(f, size);
}

Mesh BoxLoHi(const V3& lo, const V3& hi) { return Box(0.5 * (lo + hi), hi - lo); }

Mesh Cylinder(const Frame& f, double r, double z0, double z1, int n) {
  return Prism(Circle(r, n), f, z0, z1);
}

Mesh Frustum(const Frame& f, double r0, double r1, double z0, double z1, int n) {
  return Loft(Circle(1.0, n), {Ring{z0, r0}, Ring{z1, r1}}, f);
}

Mesh Rod(const V3& a, const V3& b, double r, int n) {
  V3 d = b - a;
  return Cylinder(FrameZ(a, d), r, 0.0, d.norm(), n);
}

Mesh Bar(const V3& a, const V3& b, double w, double t, const V3& side) {
  V3 d = b - a;
  Frame f = FrameZ(a, d, side);
  return Prism(Rect(w, t), f, 0.0, d.norm());
}

Mesh Dome(const Frame& f, double r, double z0, int rings, int n) {
  std::vector<Ring> rs;
  double a0 = std::acos(std::clamp(z0 / r, -1.0, 1.0));  // polar angle of the cut
  for (int i = 0; i <= rings; ++i) {
    double a = a0 * (1.0 - static_cast<double>(i) / rings);
    rs.push_back(Ring{r * std::cos(a), r * std::sin(a)});
  }
  rs.back().s = 0.0;
  return Loft(Circle(1.0, n), rs, f);
}

Mesh Ellipsoid(const Frame& f, const V3& half, int rings, int n) {
  std::vector<Ring> rs;
  for (int i = 0; i <= rings; ++i) {
    double a = kPi * (1.0 - static_cast<double>(i) / rings);
    rs.push_back(Ring{std::cos(a), std::sin(a)});
  }
  rs.front().s = 0.0;
  rs.back().s = 0.0;
  Mesh m = Loft(Circle(1.0, n), rs, Frame());
  M3 a = f.r * half.asDiagonal();
  return m.Transform(a, f.o);
}

Mesh Sphere(const V3& c, double r, int rings, int n) {
  Frame f;
  f.o = c;
  return Ellipsoid(f, V3::Constant(r), rings, n);
}

Mesh RoundedSlab(const Frame& f, double w, double d, double h, double corner, double bevel,
                 int seg) {
  bevel = std::min({bevel, 0.45 * h, 0.2 * std::min(w, d)});
  std::vector<V2> poly = RoundRect(w, d, corner, seg);
  if (bevel <= 1e-5) return Prism(poly, f, 0.0, h);
  // homothetic rings: scale so that the outline shrinks by about `bevel` at the top
  double m = std::min(w, d);
  double s1 = 1.0 - 2 * (0.3 * bevel) / m, s2 = 1.0 - 2 * bevel / m;
  return Loft(poly, {Ring{0.0, 1.0}, Ring{h - bevel, 1.0}, Ring{h - 0.3 * bevel, s1}, Ring{h, s2}},
              f);
}

}  // namespace partsim::internal::gen
