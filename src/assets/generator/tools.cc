// Hand tools: folding knives, pliers, scissors and staplers. They lie flat; parts that turn
// against each other sit in separate layers (along y) so that they never touch.
#include <algorithm>
#include <cmath>

#include "assets/generator/categories.h"
#include "partsim/core/constants.h"

namespace partsim::internal::gen {
namespace {

/// Counter-clockwise in the (x, z) plane (ProfileY's polygon orientation).
std::vector<V2> Ccw(std::vector<V2> poly) {
  double area = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const V2& p = poly[i];
    const V2& q = poly[(i + 1) % poly.size()];
    area += p.x() * q.y() - q.x() * p.y();
  }
  if (area < 0) std::reverse(poly.begin(), poly.end());
  return poly;
}

/// A flat bar in the (x, z) plane from a to b (x, z), width w, over y in [y0, y1].
Mesh FlatBar(const V2& a, const V2& b, double w, double y0, double y1) {
  V2 d = (b - a).normalized();
  V2 n(-d.y(), d.x());
  return ProfileY(Ccw({a - 0.5 * w * n, b - 0.5 * w * n, b + 0.5 * w * n, a + 0.5 * w * n}), y0,
                  y1);
}

/// One leg of pliers or scissors: jaw from the pivot along +x, handle backwards, in layer
/// [y0, y1]; `side` (+1 or -1) bends the handle towards +z or -z.
void Leg(ObjectBuilder& b, int part, double side, double jaw, double handle, double y0, double y1,
         bool rings, const Material& metal, const Material& grip, Rng& rng) {
  double jw = 0.012;
  // jaw: tapering towards the tip
  b.Add(part,
        ProfileY(Ccw({V2(-0.008, -side * 0.002), V2(-0.008, side * 0.5 * jw + side * 0.004),
                      V2(jaw, side * 0.002), V2(jaw, -side * 0.0005)}),
                 y0, y1),
        metal);
  b.Add(part, ProfileY(Circle(0.009, 20), y0, y1), metal);
  // handle: two straight segments bending away from the axis
  V2 p0(-0.005, 0.0), p1(-0.4 * handle, side * 0.012), p2(-handle, side * 0.03);
  b.Add(part, FlatBar(p0, p1, 0.009, y0, y1), metal);
  if (rings) {
    b.Add(part, FlatBar(p1, p2, 0.007, y0, y1), metal);
    double rr = rng.U(0.012, 0.016);
    Frame f;
    f.o = V3(p2.x() - rr + 0.002, y0, p2.y() + side * 0.004);
    f.r.col(0) = V3::UnitX();
    f.r.col(1) = V3::UnitZ();
    f.r.col(2) = -V3::UnitY();
    // ring as sectors; the frame flips y so build it upside down between -y1 and -y0
    Annulus(b, part, FrameZ(f.o, V3::UnitY(), V3::UnitX()), rr - 0.004, rr, 0.0, y1 - y0, 10, grip);
  } else {
    b.Add(part, FlatBar(p1, p2, 0.012, y0 - 0.0005, y1 + 0.0005), grip);
  }
}

}  // namespace

void BuildKnife(ObjectBuilder& b, Rng& rng) {
  Material handle = rng.P(0.5) ? Plastic(rng) : Wood(rng);
  Material steel = Steel(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double L = rng.U(0.08, 0.11), W = rng.U(0.018, 0.026), st = 0.003, bt = 0.0018;
  double u = rng.U(0, 1);
  int tools = u < 0.25 ? 1 : (u < 0.5 ? 2 : (u < 0.85 ? 3 : 4));
  double inner = tools * (bt + kGap) + kGap;
  int bp = b.Part(body, "handle");
  std::vector<V2> outline = RoundRect(L, W, 0.5 * W - 0.001, 8);
  b.Add(bp, ProfileY(outline, 0.0, st), handle);
  b.Add(bp, ProfileY(outline, st + inner, 2 * st + inner), handle);
  // spine along the back (-z) edge joining the scales
  b.Add(bp,
        BoxLoHi(V3(-0.3 * L, st - 0.0005, -W / 2 + 0.001),
                V3(0.3 * L, st + inner + 0.0005, -W / 2 + 0.003)),
        steel);
  for (int k = 0; k < tools; ++k) {
    double y0 = st + kGap + k * (bt + kGap);
    bool end_a = k % 2 == 0;  // pivot at +x or at -x
    double px = end_a ? L / 2 - 0.008 : -L / 2 + 0.008;
    double s = end_a ? 1.0 : -1.0;  // the folded blade points towards -s x
    double lb = (k < 2 ? 0.92 : rng.U(0.5, 0.8)) * (L - 0.02);
    double bw = std::min(W / 2 - 0.003 - kGap, 0.5 * W - 0.004) * 2 * (k == 0 ? 1.0 : 0.7);
    int blade = b.Hinge(body, "blade", V3(px, y0, 0), s * V3::UnitY(), 0, 180);
    // profile relative to the pivot, folded inside the handle
    std::vector<V2> prof;
    if (k == 0) {
      prof = {V2(0.006, -bw / 2), V2(0.006, bw / 2), V2(-0.75 * lb, bw / 2), V2(-lb, 0.1 * bw),
              V2(-0.85 * lb, -bw / 2)};
    } else {
      prof = {V2(0.005, -bw / 2), V2(0.005, bw / 2), V2(-lb, bw / 2), V2(-lb, -bw / 2)};
    }
    for (V2& p : prof) p = V2(px + s * p.x(), p.y() + 0.0015);
    b.AddPart(blade, k == 0 ? "blade" : "tool", ProfileY(Ccw(prof), y0, y0 + bt), steel);
    b.Dynamics(blade, 0.02, 0.002);
  }
}

void BuildPliers(ObjectBuilder& b, Rng& rng) {
  Material metal = Steel(rng);
  Material grip = rng.P(0.5) ? Plastic(rng) : Rubber();
  double t = rng.U(0.006, 0.009);
  double jaw = rng.U(0.04, 0.06), handle = rng.U(0.1, 0.14);
  int body = b.Fixed(-1, "heavy", "leg");
  Leg(b, b.Part(body, "leg"), -1, jaw, handle, 0.0, t, false, metal, grip, rng);
  int leg = b.Hinge(body, "leg", V3(0, t + kGap, 0), V3::UnitY(), -rng.U(20, 35), 0);
  Leg(b, b.Part(leg, "leg"), 1, jaw, handle, t + kGap, 2 * t + kGap, false, metal, grip, rng);
  b.Dynamics(leg, 0.05, 0.005);
}

void BuildScissors(ObjectBuilder& b, Rng& rng) {
  Material metal = Steel(rng);
  Material grip = Plastic(rng);
  double t = rng.U(0.002, 0.003);
  double blade = rng.U(0.06, 0.11), handle = rng.U(0.06, 0.08);
  int body = b.Fixed(-1, "heavy", "leg");
  Leg(b, b.Part(body, "leg"), -1, blade, handle, 0.0, t, true, metal, grip, rng);
  int leg = b.Hinge(body, "leg", V3(0, t + kGap, 0), V3::UnitY(), -rng.U(35, 60), 0);
  Leg(b, b.Part(leg, "leg"), 1, blade, handle, t + kGap, 2 * t + kGap, true, metal, grip, rng);
  b.Dynamics(leg, 0.02, 0.002);
  (void)kPi;
}

void BuildStapler(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? Plastic(rng) : DarkPlastic(rng);
  Material metal = Steel(rng);
  int body = b.Fixed(-1, "heavy", "base");
  double L = rng.U(0.12, 0.18), w = rng.U(0.03, 0.045), hp = rng.U(0.025, 0.035);
  int bp = b.Part(body, "base");
  b.Add(bp, RoundedSlab(FrameZ(V3::Zero(), V3::UnitY(), V3::UnitX()), w, L, 0.008, 0.01, 0.002),
        skin);
  b.Add(bp, BoxLoHi(V3(-0.3 * w, 0.008, L / 2 - 0.03), V3(0.3 * w, 0.0095, L / 2 - 0.01)),
        metal);                                                                            // anvil
  b.Add(bp, BoxLoHi(V3(-0.4 * w, 0.006, -L / 2), V3(0.4 * w, hp, -L / 2 + 0.025)), skin);  // post
  // arm hinged at the top of the post, lifted up
  double ha = rng.U(0.018, 0.025);
  V3 lo(-w / 2, hp + kGap, -L / 2), hi(w / 2, hp + kGap + ha, L / 2 - 0.005);
  int arm = PanelHinge(b, body, "body", lo, hi, V3::UnitY(), V3::UnitZ(), rng.U(45, 70));
  int ap = b.Part(arm, "body");
  b.Add(ap, BoxLoHi(lo, V3(hi.x(), hi.y(), hi.z() - 0.01)), metal);
  b.Add(ap,
        Loft(Rect(1.0, 1.0), {Ring{0.0, 1.0}, Ring{0.01, 0.6}},
             Frame{V3(0, 0.5 * (lo.y() + hi.y()), hi.z() - 0.01),
                   FrameZ(V3::Zero(), V3::UnitZ(), V3::UnitX()).r * V3(w, ha, 1).asDiagonal()}),
        metal);
  b.Dynamics(arm, 0.1, 0.01);
  // top cover on the arm, hinged at its back
  V3 clo(-w / 2 + 0.002, hi.y() + kGap, -L / 2 + 0.015),
      chi(w / 2 - 0.002, hi.y() + kGap + 0.006, L / 2 - 0.012);
  int lid = PanelHinge(b, arm, "lid", clo, chi, V3::UnitY(), V3::UnitZ(), rng.U(80, 110));
  b.AddPart(lid, "lid",
            RoundedSlab(FrameZ(V3(0, clo.y(), 0.5 * (clo.z() + chi.z())), V3::UnitY(), V3::UnitX()),
                        chi.x() - clo.x(), chi.z() - clo.z(), chi.y() - clo.y(), 0.006, 0.003),
            skin);
  b.Dynamics(lid, 0.05, 0.005);
}

}  // namespace partsim::internal::gen
