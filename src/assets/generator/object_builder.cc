#include "assets/generator/object_builder.h"

#include <algorithm>
#include <cmath>

#include "partsim/core/constants.h"
#include "partsim/core/error.h"

namespace partsim::internal::gen {
namespace {

constexpr double kGravity = 9.81;
// joint dynamics limits (accelerations in m/s^2 or rad/s^2): dry friction below
// kMaxFrictionAccel; damping such that an effort of kDriveAccel sweeps the range kMinSweeps
// times a second (kMinSweepsLoaded for parts whose damping holds them against gravity)
constexpr double kMaxFrictionAccel = 3.0;
constexpr double kDriveAccel = 30.0;
constexpr double kDriveStiffness = 225.0;  // 1/s^2 (per unit inertia)
constexpr double kMaxDampingRate = 10.0;   // 1/s (per unit inertia)
// wheels, knobs and rotors: some bearing friction (m/s^2 or rad/s^2) and damping (1/s)
constexpr double kFreeTurnFriction = 1.0;
constexpr double kFreeTurnDamping = 2.0;
constexpr double kMinSweeps = 4.0;
constexpr double kMinSweepsLoaded = 1.5;
// gravity creep: allowed acceleration load of a part not resting on a limit, and damping
// (per unit inertia and load acceleration) that keeps the creep below ~1 mm/s
constexpr double kCreepAccel = 0.5;
constexpr double kCreepDampingPerAccel = 500.0;

std::uint64_t SplitMix(std::uint64_t* x) {
  std::uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

std::uint64_t Rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

Material Make(const std::string& name, const V3& kd, double density) {
  Material m;
  m.name = name;
  m.kd = kd;
  m.density = density;
  return m;
}

// picks one colour and jitters it a little
V3 Jitter(Rng& rng, const V3& c, double amount) {
  V3 out;
  double k = rng.U(-amount, amount);
  for (int i = 0; i < 3; ++i) out[i] = std::clamp(c[i] + k + rng.U(-0.3, 0.3) * amount, 0.0, 1.0);
  return out;
}

}  // namespace

Rng::Rng(std::uint64_t seed) {
  std::uint64_t x = seed;
  for (auto& s : s_) s = SplitMix(&x);
}

std::uint64_t Rng::Next() {
  const std::uint64_t result = Rotl(s_[1] * 5, 7) * 9;
  const std::uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = Rotl(s_[3], 45);
  return result;
}

double Rng::U(double a, double b) {
  double u = static_cast<double>(Next() >> 11) * (1.0 / 9007199254740992.0);
  return a + (b - a) * u;
}

int Rng::I(int lo, int hi) {
  if (hi <= lo) return lo;
  std::uint64_t span = static_cast<std::uint64_t>(hi - lo) + 1;
  return lo + static_cast<int>(Next() % span);
}

bool Rng::P(double p) { return U(0.0, 1.0) < p; }

Material Wood(Rng& rng) {
  static const std::vector<V3> c = {{0.55, 0.38, 0.24}, {0.72, 0.55, 0.38}, {0.40, 0.26, 0.16},
                                    {0.85, 0.75, 0.60}, {0.93, 0.92, 0.90}, {0.25, 0.25, 0.27}};
  return Make("wood", Jitter(rng, rng.Pick(c), 0.04), 600.0);
}
Material Plastic(Rng& rng) {
  static const std::vector<V3> c = {{0.80, 0.15, 0.12}, {0.15, 0.35, 0.75}, {0.20, 0.60, 0.30},
                                    {0.95, 0.75, 0.15}, {0.90, 0.90, 0.88}, {0.15, 0.15, 0.17},
                                    {0.55, 0.55, 0.58}, {0.60, 0.30, 0.65}};
  return Make("plastic", Jitter(rng, rng.Pick(c), 0.05), 1100.0);
}
Material DarkPlastic(Rng& rng) {
  static const std::vector<V3> c = {{0.08, 0.08, 0.09}, {0.18, 0.18, 0.2}, {0.3, 0.3, 0.32}};
  return Make("plastic_dark", Jitter(rng, rng.Pick(c), 0.02), 1100.0);
}
Material LightPlastic(Rng& rng) {
  static const std::vector<V3> c = {{0.94, 0.94, 0.92}, {0.85, 0.86, 0.88}, {0.75, 0.76, 0.78}};
  return Make("plastic_light", Jitter(rng, rng.Pick(c), 0.02), 1100.0);
}
Material Steel(Rng& rng) { return Make("steel", Jitter(rng, V3(0.62, 0.63, 0.65), 0.05), 7800.0); }
Material Aluminium(Rng& rng) {
  return Make("aluminium", Jitter(rng, V3(0.77, 0.78, 0.80), 0.04), 2700.0);
}
Material Rubber() { return Make("rubber", V3(0.05, 0.05, 0.05), 1150.0); }
Material Glass() { return Make("glass", V3(0.70, 0.82, 0.88), 2500.0); }
Material Ceramic(Rng& rng) {
  static const std::vector<V3> c = {{0.96, 0.96, 0.95}, {0.92, 0.90, 0.85}, {0.85, 0.88, 0.90}};
  return Make("ceramic", Jitter(rng, rng.Pick(c), 0.02), 2300.0);
}
Material Fabric(Rng& rng) {
  static const std::vector<V3> c = {{0.15, 0.15, 0.17},
                                    {0.35, 0.12, 0.10},
                                    {0.20, 0.25, 0.40},
                                    {0.45, 0.45, 0.45},
                                    {0.50, 0.40, 0.30}};
  return Make("fabric", Jitter(rng, rng.Pick(c), 0.04), 400.0);
}
Material Paint(Rng& rng) {
  static const std::vector<V3> c = {{0.93, 0.93, 0.93},
                                    {0.75, 0.76, 0.78},
                                    {0.15, 0.15, 0.16},
                                    {0.55, 0.10, 0.10},
                                    {0.20, 0.30, 0.45}};
  return Make("painted_metal", Jitter(rng, rng.Pick(c), 0.03), 7800.0);
}

double Q(double x) { return std::round(x * 1e4) / 1e4; }
V3 Q(const V3& p) { return V3(Q(p.x()), Q(p.y()), Q(p.z())); }

// ---------------------------------------------------------------------------------------------
// ObjectBuilder

int ObjectBuilder::NewLink(int parent, const std::string& joint, const std::string& label) {
  GeneratedLink l;
  l.id = LinkCount();
  l.parent = parent;
  l.joint = joint;
  l.name = label;
  out_->links.push_back(l);
  return l.id;
}

int ObjectBuilder::Fixed(int parent, const std::string& joint, const std::string& label) {
  return NewLink(parent, joint, label);
}

int ObjectBuilder::Hinge(int parent, const std::string& label, const V3& origin, const V3& dir,
                         double lo, double hi) {
  int id = NewLink(parent, "hinge", label);
  GeneratedLink& l = Link(id);
  l.axis_origin = origin;
  l.axis_direction = dir.normalized();
  l.limit_a = std::round(std::min(lo, hi));
  l.limit_b = std::round(std::max(lo, hi));
  if (l.limit_a > 0 || l.limit_b < 0) throw Error("generator: hinge '" + label + "' excludes 0");
  return id;
}

int ObjectBuilder::Continuous(int parent, const std::string& label, const V3& origin,
                              const V3& dir) {
  int id = NewLink(parent, "hinge", label);
  GeneratedLink& l = Link(id);
  l.axis_origin = origin;
  l.axis_direction = dir.normalized();
  l.no_limit = true;
  l.limit_a = -180.0;
  l.limit_b = 180.0;
  return id;
}

int ObjectBuilder::Slider(int parent, const std::string& label, const V3& origin, const V3& dir,
                          double lo, double hi) {
  int id = NewLink(parent, "slider", label);
  GeneratedLink& l = Link(id);
  l.axis_origin = origin;
  l.axis_direction = dir.normalized();
  l.limit_a = Q(std::min(lo, hi));
  l.limit_b = Q(std::max(lo, hi));
  if (l.limit_a > 0 || l.limit_b < 0) throw Error("generator: slider '" + label + "' excludes 0");
  return id;
}

int ObjectBuilder::ScrewSlider(int parent, const std::string& label, const V3& origin,
                               const V3& dir, double lo, double hi) {
  int id = Slider(parent, label, origin, dir, lo, hi);
  Link(id).rotates = true;
  Link(id).no_rotation_limit = true;
  return id;
}

void ObjectBuilder::Dynamics(int link, double friction, double damping) {
  Link(link).friction = friction;
  Link(link).damping = damping;
}

int ObjectBuilder::Part(int link, const std::string& name) {
  GeneratedPart p;
  p.id = static_cast<int>(part_index_.size()) + 1;
  p.name = name;
  auto& parts = Link(link).parts;
  part_index_.emplace_back(link, static_cast<int>(parts.size()));
  parts.push_back(p);
  return p.id;
}

void ObjectBuilder::Add(int part, const Mesh& mesh, const Material& material) {
  auto [link, index] = part_index_[static_cast<size_t>(part - 1)];
  GeneratedPiece piece;
  piece.vertices = mesh.v;
  piece.triangles = mesh.f;
  piece.material = material.name;
  piece.color = material.kd;
  piece.density = material.density;
  Link(link).parts[static_cast<size_t>(index)].pieces.push_back(std::move(piece));
}

int ObjectBuilder::AddPart(int link, const std::string& name, const Mesh& mesh,
                           const Material& material) {
  int p = Part(link, name);
  Add(p, mesh, material);
  return p;
}

void ObjectBuilder::Finalize() {
  const int n = LinkCount();
  // mass, first and second moments of each link, then of each subtree (children have larger
  // ids), in the file frame at rest
  std::vector<double> mass(n, 0.0);
  std::vector<V3> first(n, V3::Zero());
  std::vector<M3> second(n, M3::Zero());
  for (int i = 0; i < n; ++i) {
    for (const GeneratedPart& part : Link(i).parts) {
      for (const GeneratedPiece& piece : part.pieces) {
        Mesh m;
        m.v = piece.vertices;
        m.f = piece.triangles;
        VolumeProps vp = ComputeVolumeProps(m);
        mass[i] += piece.density * vp.volume;
        first[i] += piece.density * vp.first;
        second[i] += piece.density * vp.second;
      }
    }
  }
  for (int i = n - 1; i >= 0; --i) {
    int p = Link(i).parent;
    if (p >= 0) {
      mass[p] += mass[i];
      first[p] += first[i];
      second[p] += second[i];
    }
  }
  for (int i = 0; i < n; ++i) {
    GeneratedLink& l = Link(i);
    if (l.joint != "hinge" && l.joint != "slider") continue;
    const bool slider = l.joint == "slider";
    const V3& o = l.axis_origin;
    const V3& d = l.axis_direction;
    // effective inertia of the joint at rest: subtree mass, or moment about the axis (for a
    // rotating slider both)
    M3 so = second[i] - o * first[i].transpose() - first[i] * o.transpose() +
            mass[i] * o * o.transpose();
    double moment = std::max(d.dot((so.trace() * M3::Identity() - so) * d), 1e-12);
    double inertia = std::max(slider ? mass[i] : moment, 1e-9);
    double range = std::max(l.limit_b - l.limit_a, 1e-6);  // m or degrees
    if (!slider) range *= kPi / 180.0;
    if (l.no_limit) range = 2 * kPi;
    // default dynamics, scaled with the part
    if (l.friction <= 0 && l.damping <= 0) {
      l.friction = 0.5 * inertia;
      l.damping = 0.5 * inertia;
    }
    // a part must be movable through its range by a modest effort: dry friction below an
    // acceleration of kMaxFrictionAccel (and below what a position drive of stiffness
    // kDriveStiffness gives a tenth of the range away from its target); damping that allows
    // kMinSweeps ranges per second at an acceleration of kDriveAccel. Free-turning parts (wheels,
    // knobs, rotors) keep some bearing friction and damping.
    double friction_cap = std::min(kMaxFrictionAccel, 0.02 * kDriveStiffness * range) * inertia;
    double damping_cap = std::min(kMaxDampingRate, kDriveAccel / (kMinSweeps * range)) * inertia;
    l.friction = std::min(l.friction, friction_cap);
    l.damping = std::min(l.damping, damping_cap);
    if (l.no_limit) {
      l.friction = kFreeTurnFriction * inertia;
      l.damping = kFreeTurnDamping * inertia;
    }
    if (l.rotates) {
      l.rotation_friction = kFreeTurnFriction * moment;
      l.rotation_damping = kFreeTurnDamping * moment;
    }
    // generalised gravity force on the joint at rest
    V3 force = V3(0, -kGravity, 0) * mass[i];
    V3 com = mass[i] > 0 ? V3(first[i] / mass[i]) : o;
    double g = slider ? d.dot(force) : d.dot((com - o).cross(force));
    // a joint at a limit that gravity pushes into holds by the limit
    bool held = !l.no_limit && ((l.limit_a == 0.0 && g < 0) || (l.limit_b == 0.0 && g > 0));
    bool mirror =
        !held && !l.no_limit &&
        std::find(rest_on_limit_.begin(), rest_on_limit_.end(), i) != rest_on_limit_.end() &&
        ((l.limit_b == 0.0 && g < 0) || (l.limit_a == 0.0 && g > 0));
    if (mirror) {
      double a = l.limit_a;
      l.limit_a = -l.limit_b + 0.0;
      l.limit_b = -a + 0.0;
      held = true;
    }
    // otherwise the part would creep: the physics engine's dry friction is a soft constraint
    // that lets a part under load slide at about 1 % of its free acceleration per (1/s) whatever
    // the friction; damping slows that down. Short-travel parts (keys, buttons) may carry the
    // damping that needs; parts that would then be too sluggish must rest on a limit instead.
    double accel = std::abs(g) / inertia;
    if (!held && accel > kCreepAccel) {
      double damping = kCreepDampingPerAccel * accel * inertia;
      double cap = kDriveAccel / (kMinSweepsLoaded * range) * inertia;
      if (damping > cap) {
        throw Error("generator: " + out_->category + " link_" + std::to_string(i) + " ('" + l.name +
                    "') rests under a gravity load it cannot hold");
      }
      l.damping = std::max(l.damping, damping);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// shared parts

void Shell(ObjectBuilder& b, int part, const V3& lo, const V3& hi, double t,
           const std::string& open, const Material& mat) {
  const char names[3][2] = {{'x', 'X'}, {'y', 'Y'}, {'z', 'Z'}};
  for (int k = 0; k < 3; ++k) {
    for (int side = 0; side < 2; ++side) {
      if (open.find(names[k][side]) != std::string::npos) continue;
      V3 a = lo, c = hi;
      if (side == 0) {
        c[k] = lo[k] + t;
      } else {
        a[k] = hi[k] - t;
      }
      b.Add(part, BoxLoHi(a, c), mat);
    }
  }
}

HandleStyle RandomHandleStyle(Rng& rng) {
  double u = rng.U(0, 1);
  if (u < 0.45) return HandleStyle::kBar;
  if (u < 0.65) return HandleStyle::kKnob;
  if (u < 0.85) return HandleStyle::kLoop;
  return HandleStyle::kEdge;
}

double AddHandle(ObjectBuilder& b, int link, HandleStyle style, const V3& c, const V3& n,
                 const V3& u, double len, const Material& mat) {
  int part = b.Part(link, "handle");
  V3 nn = n.normalized(), uu = u.normalized();
  V3 v = nn.cross(uu);
  switch (style) {
    case HandleStyle::kBar: {
      double standoff = 0.032, r = 0.0065;
      for (int s : {-1, 1}) {
        V3 p = c + s * 0.5 * len * uu;
        b.Add(part, Rod(p - 0.001 * nn, p + (standoff - r * 0.5) * nn, 0.0045, 12), mat);
      }
      b.Add(part,
            Rod(c + standoff * nn - (0.5 * len + 0.012) * uu,
                c + standoff * nn + (0.5 * len + 0.012) * uu, r, 16),
            mat);
      return standoff + r;
    }
    case HandleStyle::kKnob: {
      Frame f = FrameZ(c, nn);
      b.Add(part, Cylinder(f, 0.007, -0.001, 0.022, 16), mat);
      b.Add(
          part,
          Loft(Circle(1.0, 24),
               {Ring{0.018, 0.012}, Ring{0.024, 0.017}, Ring{0.03, 0.017}, Ring{0.034, 0.013}}, f),
          mat);
      return 0.034;
    }
    case HandleStyle::kEdge: {
      Frame f = FrameZ(c, nn, uu);
      b.Add(part, Prism(RoundRect(len, 0.014, 0.004, 3), f, -0.001, 0.022), mat);
      // a lip pointing down (along -v) at the front of the tab
      Frame g = FrameZ(c + 0.016 * nn - 0.007 * v, nn, uu);
      b.Add(part, Prism(Rect(len, 0.02), g, 0.0, 0.006), mat);
      return 0.022;
    }
    case HandleStyle::kLoop: {
      // a flat arch of rods with balls at the joints
      double h = 0.03, r = 0.006;
      const int seg = 5;
      std::vector<V3> pts;
      for (int i = 0; i <= seg; ++i) {
        double a = kPi * i / seg;
        pts.push_back(c - 0.5 * len * std::cos(a) * uu + (h * std::sin(a) - 0.001) * nn);
      }
      // end posts go into the face a little
      for (int i = 0; i < seg; ++i) b.Add(part, Rod(pts[i], pts[i + 1], r, 12), mat);
      for (int i = 1; i < seg; ++i) b.Add(part, Sphere(pts[i], r, 6, 12), mat);
      (void)v;
      return h + r;
    }
  }
  return 0.0;
}

int PanelHinge(ObjectBuilder& b, int parent, const std::string& label, const V3& lo, const V3& hi,
               const V3& n, const V3& e_dir, double max_deg, bool inset) {
  V3 origin;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(n[k]) > 0.5) {
      origin[k] = (n[k] > 0) != inset ? lo[k] : hi[k];
    } else if (std::abs(e_dir[k]) > 0.5) {
      origin[k] = e_dir[k] > 0 ? lo[k] : hi[k];
    } else {
      origin[k] = 0.5 * (lo[k] + hi[k]);
    }
  }
  return b.Hinge(parent, label, origin, e_dir.cross(n), 0.0, max_deg);
}

int HingedPanel(ObjectBuilder& b, int parent, const std::string& label,
                const std::string& part_name, const V3& lo, const V3& hi, const V3& n,
                const V3& e_dir, double max_deg, const Material& mat, bool inset) {
  int link = PanelHinge(b, parent, label, lo, hi, n, e_dir, max_deg, inset);
  b.AddPart(link, part_name, BoxLoHi(lo, hi), mat);
  return link;
}

std::vector<V2> Inset(const std::vector<V2>& poly, double d) {
  const size_t n = poly.size();
  // each edge as a line n . x = c, moved inwards
  std::vector<V2> normal(n);
  std::vector<double> c(n);
  for (size_t i = 0; i < n; ++i) {
    V2 e = (poly[(i + 1) % n] - poly[i]).normalized();
    normal[i] = V2(e.y(), -e.x());  // outward for counter-clockwise
    c[i] = normal[i].dot(poly[i]) - d;
  }
  std::vector<V2> out(n);
  for (size_t i = 0; i < n; ++i) {
    size_t j = (i + n - 1) % n;  // edges j and i meet at vertex i
    Eigen::Matrix2d a;
    a << normal[j].x(), normal[j].y(), normal[i].x(), normal[i].y();
    out[i] = a.inverse() * V2(c[j], c[i]);
  }
  return out;
}

Mesh ProfileX(const std::vector<V2>& zy, double x0, double x1) {
  Frame f;
  f.r.col(0) = V3::UnitZ();
  f.r.col(1) = V3::UnitY();
  f.r.col(2) = V3::UnitX();
  return Prism(zy, f, x0, x1);
}

Mesh ProfileY(const std::vector<V2>& xz, double y0, double y1) {
  Frame f;
  f.r.col(0) = V3::UnitX();
  f.r.col(1) = V3::UnitZ();
  f.r.col(2) = V3::UnitY();
  return Prism(xz, f, y0, y1);
}

Mesh ProfileZ(const std::vector<V2>& xy, double z0, double z1) {
  return Prism(xy, Frame(), z0, z1);
}

void Annulus(ObjectBuilder& b, int part, const Frame& f, double rin, double rout, double z0,
             double z1, int n, const Material& mat, double a0, double a1, double sx, double sy) {
  const int sub = 3;  // arc points per sector on the outside
  for (int i = 0; i < n; ++i) {
    double s0 = a0 + (a1 - a0) * i / n, s1 = a0 + (a1 - a0) * (i + 1) / n;
    std::vector<V2> poly;
    // counter-clockwise: inner start, outer arc, inner end
    poly.emplace_back(rin * std::cos(s0), rin * std::sin(s0));
    for (int k = 0; k <= sub; ++k) {
      double a = s0 + (s1 - s0) * k / sub;
      poly.emplace_back(rout * std::cos(a), rout * std::sin(a));
    }
    poly.emplace_back(rin * std::cos(s1), rin * std::sin(s1));
    for (V2& p : poly) p = V2(p.x() * sx, p.y() * sy);
    // the inner chord goes clockwise: reverse the list if the polygon came out clockwise
    double area = 0;
    for (size_t k = 0; k < poly.size(); ++k) {
      const V2& p = poly[k];
      const V2& q = poly[(k + 1) % poly.size()];
      area += p.x() * q.y() - q.x() * p.y();
    }
    if (area < 0) std::reverse(poly.begin(), poly.end());
    b.Add(part, Prism(poly, f, z0, z1), mat);
  }
}

void Polyline(ObjectBuilder& b, int part, const std::vector<V3>& pts, double r,
              const Material& mat) {
  for (size_t i = 0; i + 1 < pts.size(); ++i) b.Add(part, Rod(pts[i], pts[i + 1], r, 12), mat);
  for (size_t i = 1; i + 1 < pts.size(); ++i) b.Add(part, Sphere(pts[i], r, 6, 12), mat);
}

std::vector<V3> Arc(const V3& c, const V3& u, const V3& v, double r, double a0, double a1, int n) {
  std::vector<V3> pts;
  for (int i = 0; i <= n; ++i) {
    double a = a0 + (a1 - a0) * i / n;
    pts.push_back(c + r * (std::cos(a) * u + std::sin(a) * v));
  }
  return pts;
}

int Drawer(ObjectBuilder& b, int parent, const V3& clo, const V3& chi, double fx0, double fx1,
           double fy0, double fy1, double fz, double ft, double travel, HandleStyle handle,
           const Material& mat, const Material& handle_mat, const std::string& label) {
  V3 origin(0.5 * (fx0 + fx1), 0.5 * (fy0 + fy1), fz + ft);
  int link = b.Slider(parent, label, origin, V3::UnitZ(), 0.0, travel);
  double t = std::min(0.012, 0.15 * (chi.y() - clo.y()));
  int body = b.Part(link, "drawer_box");
  // bottom, sides and back; the front panel closes the box
  b.Add(body, BoxLoHi(clo, V3(chi.x(), clo.y() + t, fz)), mat);
  b.Add(body, BoxLoHi(clo, V3(clo.x() + t, chi.y(), fz)), mat);
  b.Add(body, BoxLoHi(V3(chi.x() - t, clo.y(), clo.z()), V3(chi.x(), chi.y(), fz)), mat);
  b.Add(body, BoxLoHi(clo, V3(chi.x(), chi.y(), clo.z() + t)), mat);
  b.AddPart(link, "drawer_front", BoxLoHi(V3(fx0, fy0, fz), V3(fx1, fy1, fz + ft)), mat);
  double w = fx1 - fx0;
  AddHandle(b, link, handle, V3(0.5 * (fx0 + fx1), 0.5 * (fy0 + fy1), fz + ft), V3::UnitZ(),
            V3::UnitX(), std::min(0.5 * w, 0.22), handle_mat);
  b.Dynamics(link, 1.0, 2.0);
  return link;
}

int Button(ObjectBuilder& b, int parent, const V3& c, const V3& n, const V3& u,
           const std::vector<V2>& footprint, double h, double travel, const Material& mat,
           const std::string& label) {
  V3 nn = n.normalized();
  int link = b.Slider(parent, label, c, -nn, 0.0, travel);
  Frame f = FrameZ(c, nn, u);
  double z0 = 0.002 + travel;
  // slightly rounded top: a loft that narrows over its last fifth
  double s_top = 0.92;
  b.AddPart(link, label,
            Loft(footprint, {Ring{z0, 1.0}, Ring{z0 + 0.75 * h, 1.0}, Ring{z0 + h, s_top}}, f),
            mat);
  b.Dynamics(link, 0.3, 0.05);
  return link;
}

int Knob(ObjectBuilder& b, int parent, const V3& c, const V3& n, double r, double h, double max_deg,
         const Material& mat, const std::string& label) {
  V3 nn = n.normalized();
  int link = max_deg > 0 ? b.Hinge(parent, label, c, nn, 0.0, max_deg)
                         : b.Continuous(parent, label, c, nn);
  Frame f = FrameZ(c, nn);
  int part = b.Part(link, label);
  double z0 = 0.002;
  b.Add(part, Cylinder(f, 0.45 * r, z0, z0 + 0.35 * h, 16), mat);
  b.Add(part,
        Loft(Circle(1.0, 28),
             {Ring{z0 + 0.3 * h, 0.92 * r}, Ring{z0 + 0.4 * h, r}, Ring{z0 + 0.85 * h, r},
              Ring{z0 + h, 0.85 * r}},
             f),
        mat);
  // a grip ridge across the face shows the knob's angle
  Frame g = FrameZ(c + (z0 + h) * nn, nn);
  b.Add(part, Box(Frame{g.o + 0.0025 * nn, g.r}, V3(1.5 * r, 0.25 * r, 0.005)), mat);
  b.Dynamics(link, 0.02, 0.002);
  return link;
}

int Wheel(ObjectBuilder& b, int parent, const V3& c, const V3& axle, double r, double w,
          const Material& tyre, const Material& hub, const std::string& label) {
  int link = b.Continuous(parent, label, c, axle);
  Frame f = FrameZ(c, axle);
  int part = b.Part(link, label);
  b.Add(
      part,
      Loft(Circle(1.0, 32),
           {Ring{-0.5 * w, 0.86 * r}, Ring{-0.3 * w, r}, Ring{0.3 * w, r}, Ring{0.5 * w, 0.86 * r}},
           f),
      tyre);
  b.Add(part, Cylinder(f, 0.45 * r, -0.5 * w - 0.001, 0.5 * w + 0.001, 20), hub);
  b.Dynamics(link, 0.005, 0.001);
  return link;
}

int Caster(ObjectBuilder& b, int parent, const V3& top, double height, const Material& fork,
           const Material& tyre, Rng& rng) {
  double rw = 0.42 * height, ww = std::max(0.018, 0.35 * height);
  double trail = 0.35 * rw;
  double heading = rng.U(0, 2 * kPi);
  V3 along(std::cos(heading), 0, std::sin(heading));  // trailing direction
  V3 axle = along.cross(V3::UnitY());
  int swivel = b.Continuous(parent, "caster", top, V3::UnitY());
  b.Dynamics(swivel, 0.01, 0.002);
  V3 wc = top - V3(0, height - rw, 0) + trail * along;
  double arm_t = 0.004;
  double plate_bottom = wc.y() + rw + kGap;
  int part = b.Part(swivel, "caster_fork");
  // stem, plate, two arms
  Frame fs;
  fs.o = V3(top.x(), plate_bottom, top.z());
  b.Add(part, Cylinder(FrameZ(fs.o, V3::UnitY()), 0.006, 0.0, top.y() - plate_bottom, 12), fork);
  Frame fp = FrameZ(V3(0, 0, 0), V3::UnitY(), axle);
  fp.o = V3(top.x(), plate_bottom, top.z()) + 0.5 * trail * along;
  double plate_len = trail + rw * 0.9;
  b.Add(part, Prism(RoundRect(ww + 2 * (kGap + arm_t), plate_len, 0.004, 3), fp, 0.0, 0.006), fork);
  for (int s : {-1, 1}) {
    V3 off = s * (0.5 * ww + kGap + 0.5 * arm_t) * axle;
    V3 a = V3(wc.x(), plate_bottom + 0.003, wc.z()) + off;
    V3 c = wc + off;
    b.Add(part, Bar(a, c, 0.55 * rw, arm_t, along), fork);
  }
  Wheel(b, swivel, wc, axle, rw, ww, tyre, fork);
  return 2;
}

}  // namespace partsim::internal::gen
