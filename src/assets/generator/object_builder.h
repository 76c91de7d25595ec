// Internal tools of the object generator: a portable random generator, materials, the object
// builder (links, joints, parts, pieces) and parts shared by many categories (panels, drawers,
// hinged doors, handles, knobs, buttons, wheels).
//
// Frame: the file frame, y up, metres, the object's front facing +z. Objects are built at rest;
// every joint is at q = 0 at rest.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "assets/generator/mesh_builder.h"
#include "partsim/assets/generator.h"

namespace partsim::internal::gen {

/// splitmix64-seeded xoshiro256** generator with portable uniform draws (the standard
/// distributions differ between standard libraries).
class Rng {
 public:
  explicit Rng(std::uint64_t seed);
  std::uint64_t Next();
  /// Uniform in [a, b).
  double U(double a, double b);
  /// Uniform integer in [lo, hi].
  int I(int lo, int hi);
  /// True with probability p.
  bool P(double p);
  /// Uniform pick.
  template <class T>
  const T& Pick(const std::vector<T>& v) {
    return v[static_cast<size_t>(I(0, static_cast<int>(v.size()) - 1))];
  }

 private:
  std::uint64_t s_[4];
};

/// A material: name (in the .mtl), diffuse colour and density.
struct Material {
  std::string name;
  V3 kd = V3::Constant(0.8);
  double density = 1000.0;  ///< kg/m^3
  Material WithDensity(double d) const {
    Material m = *this;
    m.density = d;
    return m;
  }
};

// Material palettes: each call picks a colour of the palette.
Material Wood(Rng& rng);
Material Plastic(Rng& rng);       ///< coloured plastic, 1100 kg/m^3
Material DarkPlastic(Rng& rng);   ///< black and greys, 1100 kg/m^3
Material LightPlastic(Rng& rng);  ///< whites and light greys, 1100 kg/m^3
Material Steel(Rng& rng);         ///< 7800 kg/m^3
Material Aluminium(Rng& rng);     ///< 2700 kg/m^3
Material Rubber();                ///< 1150 kg/m^3
Material Glass();                 ///< 2500 kg/m^3
Material Ceramic(Rng& rng);       ///< 2300 kg/m^3
Material Fabric(Rng& rng);        ///< upholstery, 400 kg/m^3 (foam and cloth)
Material Paint(Rng& rng);         ///< painted metal sheet colours, 7800 kg/m^3

/// Clearance between a moving part and anything else (m).
constexpr double kGap = 0.003;

/// Builds a GeneratedObject: links with their joints, parts and convex pieces. Links are named
/// with a key ("door", "lid", "knob", ...: the `label` arguments below), which ApplyLabels
/// (labels.cc) turns into the link's semantics label and PartNet name once the object is built.
class ObjectBuilder {
 public:
  explicit ObjectBuilder(GeneratedObject* out) : out_(out) {}

  /// A link fixed to `parent` (-1: base): joint "heavy" (the body), "static" or "free".
  int Fixed(int parent, const std::string& joint, const std::string& label);
  /// A hinge about the line through `origin` along `dir`, range [lo, hi] degrees (rounded to
  /// whole degrees), containing 0.
  int Hinge(int parent, const std::string& label, const V3& origin, const V3& dir, double lo,
            double hi);
  /// A continuous hinge.
  int Continuous(int parent, const std::string& label, const V3& origin, const V3& dir);
  /// A slider along `dir` through `origin`, range [lo, hi] metres (rounded to 0.1 mm).
  int Slider(int parent, const std::string& label, const V3& origin, const V3& dir, double lo,
             double hi);
  /// A slider that also turns about its axis without limit (a screw cap).
  int ScrewSlider(int parent, const std::string& label, const V3& origin, const V3& dir, double lo,
                  double hi);
  /// Base friction and damping of link's joint (raised later where gravity needs it).
  void Dynamics(int link, double friction, double damping);
  /// Lets Finalize mirror the link's range ([lo, hi] -> [-hi, -lo]) when that puts the rest
  /// position at the limit gravity pushes into (for parts that move either way, e.g. lamp arms).
  void RestOnLimit(int link) { rest_on_limit_.push_back(link); }

  /// A new part of `link` named `name`; returns its part id.
  int Part(int link, const std::string& name);
  /// Adds a convex piece to part `part`.
  void Add(int part, const Mesh& mesh, const Material& material);
  /// Part + Add in one call, for single-piece parts.
  int AddPart(int link, const std::string& name, const Mesh& mesh, const Material& material);

  GeneratedLink& Link(int id) { return out_->links[static_cast<size_t>(id)]; }
  int LinkCount() const { return static_cast<int>(out_->links.size()); }

  /// Sets joint friction where gravity would move a part at rest, and default dynamics where
  /// none were given. Called once at the end.
  void Finalize();

 private:
  int NewLink(int parent, const std::string& joint, const std::string& label);
  GeneratedObject* out_;
  std::vector<std::pair<int, int>> part_index_;  // part id -> (link, index in link's parts)
  std::vector<int> rest_on_limit_;
};

// ---------------------------------------------------------------------------------------------
// shared parts

/// Panels of a box shell between lo and hi with wall thickness t; `open` lists open faces as
/// characters among "xXyYzZ" (lower-case: the face at lo, upper-case: at hi).
void Shell(ObjectBuilder& b, int part, const V3& lo, const V3& hi, double t,
           const std::string& open, const Material& mat);

enum class HandleStyle { kBar, kKnob, kEdge, kLoop };
HandleStyle RandomHandleStyle(Rng& rng);

/// A handle on a face of a link: centre `c` on the face, `n` the face's outward normal, `u` the
/// handle's long direction, `len` its length. Adds part "handle" to `link`. Returns how far it
/// stands out of the face (m).
double AddHandle(ObjectBuilder& b, int link, HandleStyle style, const V3& c, const V3& n,
                 const V3& u, double len, const Material& mat);

/// Hinged flap: a panel box [lo, hi] (the panel at rest) that turns about its edge. `hinge`
/// names the edge: the panel's face with outward normal -n (towards the body) and the side of
/// the panel given by `e_dir` (unit, from the hinge edge towards the free edge). Returns the
/// link; the panel is part `part_name`, limits [0, max_deg].
/// With `inset` the axis lies on the panel's outer face instead (a panel set inside a frame
/// whose front is flush with that face).
int HingedPanel(ObjectBuilder& b, int parent, const std::string& label,
                const std::string& part_name, const V3& lo, const V3& hi, const V3& n,
                const V3& e_dir, double max_deg, const Material& mat, bool inset = false);

/// The hinge of HingedPanel without the panel: returns the link.
int PanelHinge(ObjectBuilder& b, int parent, const std::string& label, const V3& lo, const V3& hi,
               const V3& n, const V3& e_dir, double max_deg, bool inset = false);

/// Moves every edge of a convex counter-clockwise polygon inwards by d.
std::vector<V2> Inset(const std::vector<V2>& poly, double d);

/// Polygon (z, y) extruded along x over [x0, x1]; polygon (x, z) along y; (x, y) along z.
Mesh ProfileX(const std::vector<V2>& zy, double x0, double x1);
Mesh ProfileY(const std::vector<V2>& xz, double y0, double y1);
Mesh ProfileZ(const std::vector<V2>& xy, double z0, double z1);

/// Adds an annulus (local z in [z0, z1] of frame f, radii rin..rout, angles a0..a1 radians) as
/// `n` convex sectors to `part`; `sx`, `sy` stretch it into an elliptic ring.
void Annulus(ObjectBuilder& b, int part, const Frame& f, double rin, double rout, double z0,
             double z1, int n, const Material& mat, double a0 = 0.0, double a1 = 6.283185307179586,
             double sx = 1.0, double sy = 1.0);

/// Adds rods through `pts` (radius r) with balls at the inner joints to `part`.
void Polyline(ObjectBuilder& b, int part, const std::vector<V3>& pts, double r,
              const Material& mat);

/// Points of an arc: centre c, radius r, from angle a0 to a1 in the plane spanned by u
/// (angle 0) and v (angle pi/2), n segments.
std::vector<V3> Arc(const V3& c, const V3& u, const V3& v, double r, double a0, double a1, int n);

/// A drawer in a cavity: box [clo, chi] is the free space for the drawer body (already shrunk
/// by the clearance), the front panel spans x in [fx0, fx1], y in [fy0, fy1] at z in
/// [fz, fz + ft]. Slides along +z over [0, travel]. Returns the link.
int Drawer(ObjectBuilder& b, int parent, const V3& clo, const V3& chi, double fx0, double fx1,
           double fy0, double fy1, double fz, double ft, double travel, HandleStyle handle,
           const Material& mat, const Material& handle_mat, const std::string& label = "drawer");

/// A push button on a face: footprint polygon centred at `c` on the face with outward normal
/// `n`, height `h`, travel `travel`; slides along -n. Returns the link.
int Button(ObjectBuilder& b, int parent, const V3& c, const V3& n, const V3& u,
           const std::vector<V2>& footprint, double h, double travel, const Material& mat,
           const std::string& label = "button");

/// A round knob on a face (turns about n): radius r, height h. Continuous when max_deg <= 0,
/// else limited to [0, max_deg]. Returns the link.
int Knob(ObjectBuilder& b, int parent, const V3& c, const V3& n, double r, double h, double max_deg,
         const Material& mat, const std::string& label = "knob");

/// A wheel turning about `axle` through `c`: radius r, width w (tyre and hub). Returns the link.
int Wheel(ObjectBuilder& b, int parent, const V3& c, const V3& axle, double r, double w,
          const Material& tyre, const Material& hub, const std::string& label = "wheel");

/// A caster: a swivel (continuous about +y) holding a fork at whose bottom turns a wheel.
/// `top` is the mounting point (the swivel's top); the wheel touches y = top.y - height.
/// Returns the number of links added (2).
int Caster(ObjectBuilder& b, int parent, const V3& top, double height, const Material& fork,
           const Material& tyre, Rng& rng);

/// Rounds a length to 0.1 mm (used for positions that land in the files).
double Q(double x);
V3 Q(const V3& p);

}  // namespace partsim::internal::gen
