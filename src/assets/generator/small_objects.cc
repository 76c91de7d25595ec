// Small objects: bottles, buckets, cameras, clocks, eyeglasses, globes, keyboards, laptops,
// lighters, mice, pens, phones, remotes, switches and USB sticks.
#include <algorithm>
#include <cmath>

#include "assets/generator/categories.h"
#include "partsim/core/constants.h"

namespace partsim::internal::gen {
namespace {

/// A grid of buttons on the face y = top of a slab; cells in (x, z) of size pitch, key
/// footprint `size` (fraction of the pitch).
void ButtonGrid(ObjectBuilder& b, int parent, const V3& origin, int rows, int cols, double px,
                double pz, double fx, double fz, double h, double travel, const Material& mat,
                const std::string& label = "button") {
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      V3 p = origin + V3((c - 0.5 * (cols - 1)) * px, 0, (r - 0.5 * (rows - 1)) * pz);
      Button(b, parent, p, V3::UnitY(), V3::UnitX(),
             RoundRect(fx * px, fz * pz, 0.25 * std::min(fx * px, fz * pz), 2), h, travel, mat,
             label);
    }
  }
}

}  // namespace

void BuildBottle(ObjectBuilder& b, Rng& rng) {
  Material glassy = rng.P(0.5) ? Glass().WithDensity(1200) : Plastic(rng).WithDensity(900);
  Material cap = Plastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  int bp = b.Part(body, "body");
  double r = rng.U(0.03, 0.05), h = rng.U(0.15, 0.3), nr = rng.U(0.012, 0.02);
  bool square = rng.P(0.25);
  std::vector<V2> poly = square ? RoundRect(2.0, 2.0, 0.4, 4) : Circle(1.0, 40);
  Frame fy = FrameZ(V3::Zero(), V3::UnitY());
  double sh = h * rng.U(0.6, 0.75);  // shoulder
  b.Add(bp,
        Loft(poly,
             {Ring{0.0, 0.95 * r}, Ring{0.006, r}, Ring{sh, r}, Ring{sh + 0.5 * (h - sh), 0.75 * r},
              Ring{h - 0.02, nr / (square ? 1.0 : 1.0)}},
             fy),
        glassy);
  b.Add(bp, Cylinder(fy, nr, h - 0.021, h, 32), glassy);
  if (rng.P(0.75)) {
    // screw cap that lifts and turns, or a push-on cap that only lifts
    double ch = rng.U(0.015, 0.03);
    int lid = rng.P(0.7) ? b.ScrewSlider(body, "lid", V3(0, h + kGap, 0), V3::UnitY(), 0, 0.03)
                         : b.Slider(body, "lid", V3(0, h + kGap, 0), V3::UnitY(), 0, 0.03);
    b.AddPart(lid, "lid",
              Loft(Circle(1.0, 32),
                   {Ring{0.0, nr + 0.002}, Ring{ch - 0.003, nr + 0.002}, Ring{ch, nr - 0.001}},
                   FrameZ(V3(0, h + kGap, 0), V3::UnitY())),
              cap);
    b.Dynamics(lid, 0.05, 0.02);
  } else {
    // flip-top lid hinged at the back of the neck
    double ch = 0.015;
    V3 o(0, h + kGap, -(nr + 0.002));
    int lid = b.Hinge(body, "lid", o, -V3::UnitX(), 0, 150);
    b.AddPart(
        lid, "lid",
        Loft(Circle(1.0, 32), {Ring{0.0, nr + 0.002}, Ring{ch - 0.003, nr + 0.002}, Ring{ch, nr}},
             FrameZ(V3(0, h + kGap, 0), V3::UnitY())),
        cap);
    b.Dynamics(lid, 0.01, 0.005);
  }
}

void BuildBucket(ObjectBuilder& b, Rng& rng) {
  Material mat = rng.P(0.5) ? Plastic(rng) : Steel(rng);
  Material handle_mat = Steel(rng);
  int body = b.Fixed(-1, "heavy", "body");
  int bp = b.Part(body, "body");
  double r0 = rng.U(0.09, 0.13), r1 = r0 * rng.U(1.1, 1.3), h = rng.U(0.2, 0.32), wt = 0.006;
  Frame fy = FrameZ(V3::Zero(), V3::UnitY());
  b.Add(bp, Cylinder(fy, r0, 0.0, 0.006, 40), mat);
  // tapered wall: staves lofted from the bottom ring to the top ring
  const int n = 16;
  for (int i = 0; i < n; ++i) {
    double a = 2 * kPi * (i + 0.5) / n;
    V3 dir(std::cos(a), 0, std::sin(a));
    double half = std::tan(kPi / n);
    // stave: trapezoid (width 2 r half) lofted from bottom to top, tilted with the wall
    Frame f;
    V3 bottom = dir * (r0 - wt / 2), top = dir * (r1 - wt / 2) + V3(0, h, 0);
    V3 along = (top - bottom).normalized();
    f.o = bottom;
    f.r.col(2) = along;
    f.r.col(0) = V3(-dir.z(), 0, dir.x());
    f.r.col(1) = f.r.col(2).cross(f.r.col(0));
    double len = (top - bottom).norm();
    std::vector<V2> quad = {V2(-1, -wt / (2 * r0 * half)), V2(1, -wt / (2 * r0 * half)),
                            V2(1, wt / (2 * r0 * half)), V2(-1, wt / (2 * r0 * half))};
    b.Add(bp, Loft(quad, {Ring{0.0, r0 * half}, Ring{len, r1 * half}}, f), mat);
  }
  // lugs for the handle on both sides at the rim
  double re = r1 + 0.025;
  for (int s : {-1, 1})
    b.Add(bp,
          BoxLoHi(V3(s > 0 ? r1 - 0.01 : -(re - 0.006 - kGap), h - 0.03, -0.012),
                  V3(s > 0 ? re - 0.006 - kGap : -(r1 - 0.01), h, 0.012)),
          mat);
  // bail handle: lies down towards the back at rest, turns over the top to the front
  int handle = b.Hinge(body, "handle", V3(0, h - 0.012, 0), V3::UnitX(), 0, 180);
  int hp = b.Part(handle, "handle");
  std::vector<V3> pts = Arc(V3(0, h - 0.012, 0), V3::UnitX(), -V3::UnitZ(), re, 0.0, kPi, 12);
  Polyline(b, hp, pts, 0.004, handle_mat);
  b.Dynamics(handle, 0.02, 0.01);
}

void BuildCamera(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.6) ? DarkPlastic(rng) : Aluminium(rng);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  int bp = b.Part(body, "body");
  double w = rng.U(0.1, 0.14), h = rng.U(0.06, 0.09), d = rng.U(0.035, 0.07);
  b.Add(bp, RoundedSlab(FrameZ(V3(0, 0, 0), V3::UnitY(), V3::UnitX()), w, d, h, 0.008, 0.004),
        skin);
  if (rng.P(0.5))
    b.Add(bp,
          RoundedSlab(FrameZ(V3(-w / 2 + 0.015, 0, d / 2 + 0.006), V3::UnitY(), V3::UnitX()), 0.025,
                      0.012, 0.85 * h, 0.005, 0.003),
          dark);
  // lens barrel on the front; its front ring turns (zoom)
  double lr = std::min(0.4 * h, rng.U(0.02, 0.035));
  V3 lc(0.1 * w, 0.48 * h, d / 2);
  double l1 = rng.U(0.01, 0.03);
  b.Add(bp, Cylinder(FrameZ(lc, V3::UnitZ()), lr, -0.002, l1, 40), dark);
  int lens = b.Continuous(body, "lens", lc + V3(0, 0, l1 + kGap), V3::UnitZ());
  int lp = b.Part(lens, "lens");
  double l2 = rng.U(0.015, 0.04);
  b.Add(lp,
        Loft(Circle(1.0, 40), {Ring{0.0, lr}, Ring{l2 - 0.004, lr}, Ring{l2, 0.9 * lr}},
             FrameZ(lc + V3(0, 0, l1 + kGap), V3::UnitZ())),
        dark);
  b.AddPart(lens, "glass",
            Cylinder(FrameZ(lc + V3(0, 0, l1 + kGap + l2 - 0.001), V3::UnitZ()), 0.7 * lr, 0.0,
                     0.002, 32),
            Glass());
  b.Dynamics(lens, 0.01, 0.002);
  // top: shutter button, power button, mode dial
  Button(b, body, V3(-0.3 * w, h, 0.1 * d), V3::UnitY(), V3::UnitX(), Circle(0.006, 20), 0.004,
         0.002, Aluminium(rng));
  Button(b, body, V3(-0.15 * w, h, 0.1 * d), V3::UnitY(), V3::UnitX(),
         RoundRect(0.008, 0.005, 0.002, 2), 0.002, 0.0015, dark);
  if (rng.P(0.8)) Knob(b, body, V3(0.3 * w, h, 0), V3::UnitY(), 0.011, 0.008, 0, dark, "knob");
  // back: a screen and a column of buttons
  double zb = -d / 2;
  b.AddPart(body, "screen",
            BoxLoHi(V3(-w / 2 + 0.008, 0.12 * h, zb - 0.001), V3(0.2 * w, 0.88 * h, zb + 0.001)),
            Material{"screen", V3(0.04, 0.05, 0.06), 2500});
  int buttons = rng.I(3, 7);
  double pitch = std::min(0.012, 0.75 * h / buttons);
  for (int i = 0; i < buttons; ++i) {
    double x = 0.2 * w + 0.012 + (i % 2) * 0.014;
    const int row = i / 2;  // two buttons per row
    double y = 0.8 * h - row * pitch * 1.4 - (i % 2) * 0.5 * pitch;
    Button(b, body, V3(x, y, zb), -V3::UnitZ(), V3::UnitX(), Circle(0.0035, 16), 0.002, 0.0015,
           dark);
  }
}

void BuildClock(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? Wood(rng) : Plastic(rng);
  Material face = LightPlastic(rng);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  int bp = b.Part(body, "body");
  double r = rng.U(0.08, 0.18), t = rng.U(0.025, 0.05);
  bool stand = rng.P(0.4);
  double cy = stand ? r + 0.03 : r;
  bool round = rng.P(0.6);
  Frame f = FrameZ(V3(0, cy, -t), V3::UnitZ(), V3::UnitX());
  std::vector<V2> poly = round ? Circle(1.0, 48) : RoundRect(2.0, 2.0, 0.2, 4);
  b.Add(bp, Loft(poly, {Ring{0.0, 0.95 * r}, Ring{0.004, r}, Ring{t, r}}, f), skin);
  b.Add(bp, Prism(poly, FrameZ(V3(0, cy, 0), V3::UnitZ(), V3::UnitX()), -0.001, 0.001), face);
  b.Link(body).parts.back().pieces.back().density = 1000;
  if (stand) b.Add(bp, BoxLoHi(V3(-0.6 * r, 0.0, -t), V3(0.6 * r, cy - 0.8 * r, 0.0)), skin);
  // hour marks
  for (int i = 0; i < 12; ++i) {
    double a = 2 * kPi * i / 12;
    V3 p(0.82 * r * std::cos(a), cy + 0.82 * r * std::sin(a), 0.001);
    b.Add(bp,
          Box(Frame{p, FrameZ(V3::Zero(), V3::UnitZ(), V3(std::cos(a), std::sin(a), 0)).r},
              V3(0.08 * r, 0.015 * r + 0.001, 0.0015)),
          dark);
  }
  // hands on layered planes, all turning about z through the centre
  int hands = rng.P(0.42) ? 3 : 2;
  double z = 0.001 + 0.0008 + kGap;
  const char* names[3] = {"hour_hand", "minute_hand", "second_hand"};
  const double lengths[3] = {0.5, 0.75, 0.85};
  for (int i = 0; i < hands; ++i) {
    int hand = b.Continuous(body, "hand", V3(0, cy, z), V3::UnitZ());
    double a = rng.U(0, 2 * kPi);
    V3 dir(std::cos(a), std::sin(a), 0);
    double len = lengths[i] * r, wdt = (0.05 - 0.015 * i) * r;
    Frame hf = FrameZ(V3(0, cy, z) + dir * (0.35 * len), V3::UnitZ(), dir);
    Material hm = i == 2 ? Material{"paint_red", V3(0.8, 0.1, 0.1), 2700} : dark;
    int hp = b.AddPart(hand, names[i],
                       Prism({V2(-0.5 * len, -wdt / 2), V2(0.65 * len, -wdt / 4),
                              V2(0.65 * len, wdt / 4), V2(-0.5 * len, wdt / 2)},
                             hf, 0.0, 0.0015),
                       hm);
    // a round counterweight on the tail balances the hand about its axis
    {
      const GeneratedPiece& blade = b.Link(hand).parts.back().pieces.back();
      Mesh m;
      m.v = blade.vertices;
      m.f = blade.triangles;
      VolumeProps vp = ComputeVolumeProps(m);
      double moment = (vp.first - vp.volume * V3(0, cy, z)).dot(dir);  // volume x arm
      double s_cw = 0.12 * len;
      const int sides = 24;
      double unit_area = 0.5 * sides * std::sin(2 * kPi / sides);  // polygon of radius 1
      double rc = std::sqrt(moment / (s_cw * 0.0015 * unit_area));
      b.Add(hp, Cylinder(FrameZ(V3(0, cy, z) - s_cw * dir, V3::UnitZ()), rc, 0.0, 0.0015, sides),
            hm);
    }
    b.Dynamics(hand, 0.001, 0.0001);
    z += 0.0015 + kGap;
  }
  b.Add(bp, Cylinder(FrameZ(V3(0, cy, 0), V3::UnitZ()), 0.004, 0.0, 0.0005, 12), dark);
}

void BuildEyeglasses(ObjectBuilder& b, Rng& rng) {
  Material frame = rng.P(0.5) ? DarkPlastic(rng) : Steel(rng);
  int body = b.Fixed(-1, "heavy", "body");
  int bp = b.Part(body, "frame");
  double lw = rng.U(0.045, 0.058), lh = rng.U(0.03, 0.045), bridge = rng.U(0.014, 0.022);
  double ft = 0.004;  // frame depth
  double cy = 0.03;
  double ew = bridge / 2 + lw + 0.006;  // half width to the end pieces
  // a folded leg (and its ear hook) stops short of the other hinge
  double leg_len = 2 * ew - 0.045;
  for (int s : {-1, 1}) {
    V3 c(s * (bridge / 2 + lw / 2), cy, 0);
    Frame f = FrameZ(c, V3::UnitZ(), V3::UnitX());
    // lens rim as a ring of sectors, lens inside
    Annulus(b, bp, f, 0.5 * lh - 0.003, 0.5 * lh, -ft / 2, ft / 2, 12, frame, 0.0, 2 * kPi, lw / lh,
            1.0);
    b.AddPart(body, "lens",
              Prism(Ellipse(0.5 * lw - 0.002, 0.5 * lh - 0.002, 32), f, -0.0012, 0.0012), Glass());
    // end piece reaching back to the hinge
    b.Add(bp,
          BoxLoHi(V3(s > 0 ? ew - 0.008 : -ew, cy + 0.3 * lh - 0.004, -ft / 2 - 0.008),
                  V3(s > 0 ? ew : -ew + 0.008, cy + 0.3 * lh + 0.004, ft / 2)),
          frame);
  }
  b.Add(bp,
        Bar(V3(-bridge / 2 - 0.002, cy + 0.2 * lh, 0), V3(bridge / 2 + 0.002, cy + 0.2 * lh, 0),
            0.004, 0.003, V3::UnitY()),
        frame);
  // legs: fold inwards about vertical axes at the back of the end pieces
  for (int s : {-1, 1}) {
    double xi = s * (ew - 0.001);  // inner face of the leg
    double zf = -ft / 2 - 0.008 - kGap;
    int leg = b.Hinge(body, "leg", V3(xi, cy + 0.3 * lh, zf), s > 0 ? V3(0, 1, 0) : V3(0, -1, 0), 0,
                      rng.U(80, 88));
    int p = b.Part(leg, "leg");
    // the leg extends outwards from its inner face, where the axis lies
    double lo_x = s > 0 ? xi : xi - 0.0035, hi_x = s > 0 ? xi + 0.0035 : xi;
    b.Add(
        p,
        BoxLoHi(V3(lo_x, cy + 0.3 * lh - 0.003, zf - leg_len), V3(hi_x, cy + 0.3 * lh + 0.003, zf)),
        frame);
    b.Add(p,
          Bar(V3(0.5 * (lo_x + hi_x), cy + 0.3 * lh, zf - leg_len),
              V3(0.5 * (lo_x + hi_x), cy + 0.3 * lh - 0.03, zf - leg_len - 0.02), 0.006, 0.0035,
              V3::UnitY()),
          frame);
    b.Dynamics(leg, 0.005, 0.001);
  }
}

void BuildGlobe(ObjectBuilder& b, Rng& rng) {
  Material frame = rng.P(0.5) ? Wood(rng) : Steel(rng);
  Material earth{"globe", V3(0.2, 0.45, 0.7), 150};
  earth.kd += V3(rng.U(-0.05, 0.05), rng.U(-0.05, 0.05), rng.U(-0.05, 0.05));
  int body = b.Fixed(-1, "heavy", "frame");
  int bp = b.Part(body, "frame");
  double R = rng.U(0.1, 0.2);
  double post = rng.U(0.04, 0.2);  // height of the post above the base
  const int n = 14;
  double rm = (R + 0.006) / std::cos(kPi / (2 * n)) + 0.004;  // meridian radius (bar centres)
  double cy = 0.03 + post + rm + 0.006;
  V3 c(0, cy, 0);
  b.Add(bp,
        Loft(Circle(1.0, 40), {Ring{0.0, 0.7 * R}, Ring{0.015, 0.7 * R}, Ring{0.03, 0.5 * R}},
             FrameZ(V3::Zero(), V3::UnitY())),
        frame);
  double tilt = 23.5 * kPi / 180;
  V3 axis(std::sin(tilt), std::cos(tilt), 0);
  V3 side(std::cos(tilt), -std::sin(tilt), 0);  // perpendicular to the axis in the x-y plane
  // the meridian (a half ring in the plane of the axis) passes under the sphere at angle
  // pi - tilt, where the post holds it; it swivels on the post for some globes
  bool swivel = rng.P(0.13);
  int mer_link = body;
  double split = 0.03 + 0.5 * post;
  if (swivel) {
    mer_link = b.Continuous(body, "frame", V3(0, split + kGap, 0), V3::UnitY());
    b.Dynamics(mer_link, 0.05, 0.02);
    b.Add(bp, Cylinder(FrameZ(V3(0, 0.029, 0), V3::UnitY()), 0.012, 0.0, split - 0.029, 16), frame);
  }
  int mp = b.Part(mer_link, "meridian");
  for (int i = 0; i < n; ++i) {
    double a0 = kPi * i / n, a1 = kPi * (i + 1) / n;
    V3 p0 = c + rm * (std::cos(a0) * axis + std::sin(a0) * side);
    V3 p1 = c + rm * (std::cos(a1) * axis + std::sin(a1) * side);
    b.Add(mp, Bar(p0, p1, 0.008, 0.012, V3(0, 0, 1)), frame);
  }
  // pins from the meridian towards the poles, stopping short of the sphere
  for (int s : {-1, 1})
    b.Add(mp, Rod(c + s * axis * (R + kGap + 0.001), c + s * axis * (rm + 0.004), 0.004), frame);
  double y0 = swivel ? split + kGap : 0.029;
  b.Add(mp, Cylinder(FrameZ(V3(0, y0, 0), V3::UnitY()), 0.012, 0.0, cy - rm - y0, 16), frame);
  // the sphere turns about the tilted axis
  int sphere = b.Continuous(mer_link, "sphere", c, axis);
  b.AddPart(sphere, "sphere", Ellipsoid(FrameZ(c, axis), V3::Constant(R), 16, 32), earth);
  b.Dynamics(sphere, 0.01, 0.005);
}

void BuildKeyboard(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.6) ? DarkPlastic(rng) : LightPlastic(rng);
  Material keys = rng.P(0.6) ? DarkPlastic(rng) : LightPlastic(rng);
  int body = b.Fixed(-1, "heavy", "base");
  const double u = 0.01905;  // key pitch
  // rows of key widths (in units); negative widths are gaps
  std::vector<std::vector<double>> main = {{1, -1, 1, 1, 1, 1, -0.5, 1, 1, 1, 1, -0.5, 1, 1, 1, 1},
                                           {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2},
                                           {1.5, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1.5},
                                           {1.75, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2.25},
                                           {2.25, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2.75},
                                           {1.25, 1.25, 1.25, 6.25, 1.25, 1.25, 1.25, 1.25}};
  double v = rng.U(0, 1);
  int layout = v < 0.55 ? 2 : (v < 0.9 ? 1 : 0);  // 0: 60 %, 1: tenkeyless, 2: full
  if (layout == 0) main.erase(main.begin());
  std::vector<std::vector<std::pair<double, double>>> blocks;  // (x start, width) per row
  int rows = static_cast<int>(main.size());
  std::vector<std::vector<std::pair<double, double>>> keys_xy(rows);
  double width_units = 15.0;
  for (int r = 0; r < rows; ++r) {
    double x = 0;
    for (double wk : main[r]) {
      if (wk > 0) keys_xy[r].push_back({x, wk});
      x += std::abs(wk);
    }
  }
  if (layout >= 1) {
    // navigation cluster
    double x0 = 15.25;
    keys_xy[0].insert(keys_xy[0].end(), {{x0, 1}, {x0 + 1, 1}, {x0 + 2, 1}});
    for (int r = 1; r <= 2; ++r)
      keys_xy[r].insert(keys_xy[r].end(), {{x0, 1}, {x0 + 1, 1}, {x0 + 2, 1}});
    keys_xy[4].push_back({x0 + 1, 1});
    keys_xy[5].insert(keys_xy[5].end(), {{x0, 1}, {x0 + 1, 1}, {x0 + 2, 1}});
    width_units = 18.25;
  }
  if (layout == 2) {
    double x0 = 18.5;
    keys_xy[1].insert(keys_xy[1].end(), {{x0, 1}, {x0 + 1, 1}, {x0 + 2, 1}, {x0 + 3, 1}});
    keys_xy[2].insert(keys_xy[2].end(), {{x0, 1}, {x0 + 1, 1}, {x0 + 2, 1}, {x0 + 3, 1}});
    keys_xy[3].insert(keys_xy[3].end(), {{x0, 1}, {x0 + 1, 1}, {x0 + 2, 1}});
    keys_xy[4].insert(keys_xy[4].end(), {{x0, 1}, {x0 + 1, 1}, {x0 + 2, 1}, {x0 + 3, 1}});
    keys_xy[5].insert(keys_xy[5].end(), {{x0, 2}, {x0 + 2, 1}});
    width_units = 22.5;
  }
  double margin = rng.U(0.008, 0.02);
  double W = width_units * u + 2 * margin, D = rows * u + 2 * margin + (layout == 0 ? 0 : 0.25 * u);
  double H = rng.U(0.015, 0.025);
  int bp = b.Part(body, "base");
  b.Add(bp, RoundedSlab(FrameZ(V3(0, 0, 0), V3::UnitY(), V3::UnitX()), W, D, H, 0.006, 0.002),
        skin);
  double travel = rng.U(0.003, 0.004);
  double kh = rng.U(0.006, 0.01);
  for (int r = 0; r < rows; ++r) {
    double zc = -D / 2 + margin + (r + 0.5) * u + (r > 0 && layout > 0 ? 0.25 * u : 0.0);
    for (const auto& [x, wk] : keys_xy[r]) {
      double xc = -W / 2 + margin + (x + 0.5 * wk) * u;
      double fx = wk * u - 0.0025, fz = u - 0.0025;
      V3 c(xc, H, zc);
      int key = b.Slider(body, "key", c, -V3::UnitY(), 0, travel);
      Frame f = FrameZ(c, V3::UnitY(), V3::UnitX());
      double z0 = 0.002 + travel;
      // keycap narrows towards its top (homothetic about its centre)
      double s1 = 1.0 - 0.003 / std::min(fx, fz);
      b.AddPart(key, "key",
                Loft(RoundRect(fx, fz, 0.0015, 2), {Ring{z0, 1.0}, Ring{z0 + kh, s1}}, f), keys);
      b.Dynamics(key, 0.3, 0.02);
    }
  }
}

void BuildLaptop(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? Aluminium(rng) : DarkPlastic(rng);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "base");
  double w = rng.U(0.3, 0.4), d = rng.U(0.2, 0.27), hb = rng.U(0.012, 0.022),
         ts = rng.U(0.005, 0.01);
  int bp = b.Part(body, "base");
  b.Add(bp, RoundedSlab(FrameZ(V3::Zero(), V3::UnitY(), V3::UnitX()), w, d, hb, 0.008, 0.001),
        skin);
  b.AddPart(body, "keyboard",
            BoxLoHi(V3(-0.42 * w, hb - 0.0008, -0.4 * d), V3(0.42 * w, hb + 0.0002, 0.05 * d)),
            dark);
  b.AddPart(body, "touchpad",
            BoxLoHi(V3(-0.15 * w, hb - 0.0008, 0.12 * d), V3(0.15 * w, hb + 0.0002, 0.42 * d)),
            skin);
  // screen lid closed on the base, hinged at the back
  V3 lo(-w / 2, hb + kGap, -d / 2), hi(w / 2, hb + kGap + ts, d / 2);
  int screen = PanelHinge(b, body, "screen", lo, hi, V3::UnitY(), V3::UnitZ(), rng.U(110, 150));
  int sp = b.Part(screen, "screen");
  b.Add(sp,
        RoundedSlab(FrameZ(V3(0, hi.y(), 0), -V3::UnitY(), V3::UnitX()), w, d, ts, 0.008, 0.001),
        skin);
  b.AddPart(
      screen, "display",
      BoxLoHi(V3(-0.46 * w, lo.y() - 0.0002, -0.44 * d), V3(0.46 * w, lo.y() + 0.0008, 0.42 * d)),
      Material{"screen", V3(0.03, 0.03, 0.04), 2500});
  b.Dynamics(screen, 0.3, 0.05);
}

void BuildLighter(ObjectBuilder& b, Rng& rng) {
  Material skin = Plastic(rng);
  Material metal = Steel(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.022, 0.028), d = rng.U(0.012, 0.016), h = rng.U(0.06, 0.075);
  int bp = b.Part(body, "body");
  b.Add(bp,
        Prism(RoundRect(w, d, 0.5 * d - 0.001, 6), FrameZ(V3::Zero(), V3::UnitY(), V3::UnitX()),
              0.0, h),
        skin);
  // guards on both sides of the wheel, the wheel turning about x
  double wr = rng.U(0.004, 0.0055), ww = 0.006;
  double wy = h + 0.007;
  for (int s : {-1, 1}) {
    double x = s * (ww / 2 + kGap + 0.001);
    b.Add(bp,
          BoxLoHi(V3(s > 0 ? x : x - 0.002, h - 0.001, -0.002 - wr - 0.001),
                  V3(s > 0 ? x + 0.002 : x, h + 0.012, -0.002 + wr - 0.001)),
          metal);
  }
  int wheel = Wheel(b, body, V3(0, wy, -0.002), V3::UnitX(), wr, ww, metal, metal, "wheel");
  b.Dynamics(wheel, 0.002, 0.0002);
  // fork button in front of the wheel, pressed down about its back edge
  double bz0 = -0.002 + wr + kGap;
  V3 pivot(0, h + kGap + 0.003, bz0 + 0.006);  // pivots at its middle, balanced
  int button = b.Hinge(body, "button", pivot, V3::UnitX(), 0, 6);
  b.AddPart(button, "button",
            BoxLoHi(V3(-0.006, h + kGap, bz0), V3(0.006, h + kGap + 0.006, bz0 + 0.012)),
            Plastic(rng));
  b.Dynamics(button, 0.05, 0.002);
}

void BuildMouse(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.6) ? DarkPlastic(rng) : LightPlastic(rng);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.055, 0.068), l = rng.U(0.1, 0.125), h1 = 0.018, h2 = rng.U(0.03, 0.04);
  int bp = b.Part(body, "body");
  Frame fy = FrameZ(V3::Zero(), V3::UnitY(), V3::UnitX());
  b.Add(bp, Loft(Ellipse(w / 2, l / 2, 40), {Ring{0.0, 0.92}, Ring{0.004, 1.0}, Ring{h1, 1.0}}, fy),
        skin);
  // rear hump
  Frame fh = FrameZ(V3(0, h1, -0.22 * l), V3::UnitY(), V3::UnitX());
  b.Add(bp,
        Loft(Ellipse(w / 2 - 0.001, 0.25 * l, 40),
             {Ring{0.0, 1.0}, Ring{0.4 * (h2 - h1), 0.9}, Ring{0.8 * (h2 - h1), 0.6},
              Ring{h2 - h1, 0.25}},
             fh),
        skin);
  // buttons over the front half, pressed down; a wheel between them
  double travel = 0.0015;
  double ww = 0.008, wr = 0.009;
  for (int s : {-1, 1}) {
    double x0 = s > 0 ? ww / 2 + kGap : -w / 2 + 0.004, x1 = s > 0 ? w / 2 - 0.004 : -ww / 2 - kGap;
    double y0 = h1 + kGap + travel;
    double zb = 0.05 * l + kGap, zf = 0.46 * l;
    int button =
        b.Slider(body, "button", V3(0.5 * (x0 + x1), y0, 0.5 * (zb + zf)), -V3::UnitY(), 0, travel);
    // a wedge sloping down to the front
    std::vector<V2> zy = {V2(zb, y0), V2(zf, y0), V2(zf, y0 + 0.004), V2(zb, y0 + 0.6 * (h2 - h1))};
    b.AddPart(button, "button", ProfileX(zy, x0, x1), skin);
    b.Dynamics(button, 0.3, 0.01);
  }
  int wheel =
      Wheel(b, body, V3(0, h1 + wr + kGap, 0.2 * l), V3::UnitX(), wr, ww, dark, dark, "wheel");
  b.Dynamics(wheel, 0.005, 0.0005);
  if (rng.P(0.36)) {
    for (int i = 0; i < 2; ++i) {
      V3 c(-w / 2, 0.6 * h1, -0.05 * l + i * 0.022);
      Button(b, body, c, -V3::UnitX(), V3::UnitZ(), RoundRect(0.016, 0.006, 0.002, 2), 0.002,
             0.0015, dark);
    }
  }
}

void BuildPen(ObjectBuilder& b, Rng& rng) {
  Material skin = Plastic(rng);
  Material metal = Steel(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double r = rng.U(0.004, 0.0065), len = rng.U(0.11, 0.14);
  int bp = b.Part(body, "body");
  // the pen lies along x, tip towards +x
  Frame fx = FrameZ(V3(0, r, 0), V3::UnitX(), V3::UnitY());
  if (rng.P(0.5)) {
    // cap over the front, pulled off along +x (the tip is inside it)
    double cl = rng.U(0.04, 0.055);
    double x0 = len / 2 - 0.035;
    b.Add(bp, Cylinder(fx, r, -len / 2, x0 - kGap, 24), skin);
    int cap = b.Slider(body, "cap", V3(x0, r, 0), V3::UnitX(), 0, 0.06);
    int cp = b.Part(cap, "cap");
    b.Add(cp,
          Loft(Circle(1.0, 24),
               {Ring{x0, 1.06 * r}, Ring{x0 + cl - 0.004, 1.06 * r}, Ring{x0 + cl, 0.8 * r}}, fx),
          skin);
    b.Add(cp,
          Bar(V3(x0 + 0.008, 2.06 * r + 0.0015, 0), V3(x0 + cl - 0.006, 2.06 * r + 0.0015, 0),
              0.003, 0.0012, V3::UnitZ()),
          metal);
    b.Dynamics(cap, 0.3, 0.05);
  } else {
    b.Add(bp, Cylinder(fx, r, -len / 2, len / 2 - 0.02, 24), skin);
    b.Add(bp, Frustum(fx, r, 0.0015, len / 2 - 0.02, len / 2, 24), metal);
    // click button at the back end
    double travel = 0.003;
    V3 o(-len / 2 - kGap - travel, r, 0);
    int btn = b.Slider(body, "button", o, V3::UnitX(), 0, travel);
    b.AddPart(
        btn, "button",
        Loft(Circle(1.0, 20), {Ring{-0.012, 0.5 * r}, Ring{-0.002, 0.5 * r}, Ring{0.0, 0.4 * r}},
             FrameZ(o, V3::UnitX(), V3::UnitY())),
        metal);
    b.Dynamics(btn, 0.5, 0.02);
  }
}

void BuildPhone(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? DarkPlastic(rng) : Plastic(rng);
  Material keys = rng.P(0.5) ? LightPlastic(rng) : DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "base");
  double w = rng.U(0.045, 0.055), l = rng.U(0.1, 0.12), t = rng.U(0.012, 0.018);
  bool flip = rng.P(0.25);
  int bp = b.Part(body, "base");
  b.Add(bp, RoundedSlab(FrameZ(V3::Zero(), V3::UnitY(), V3::UnitX()), w, l, t, 0.008, 0.0015),
        skin);
  // the phone lies on its back, keys up (y), its top end towards -z
  double za0 = flip ? -l / 2 + 0.012 : -0.1 * l, za1 = l / 2 - 0.01;
  if (!flip) {
    b.AddPart(body, "screen",
              BoxLoHi(V3(-0.4 * w, t - 0.0005, -0.45 * l), V3(0.4 * w, t + 0.0003, -0.13 * l)),
              Material{"screen", V3(0.04, 0.05, 0.06), 2500});
  }
  double travel = 0.0012, hb = 0.0025;
  // call / end / select row
  double zr = za0 + 0.0045;
  Button(b, body, V3(-0.33 * w, t, zr), V3::UnitY(), V3::UnitX(), RoundRect(0.011, 0.007, 0.002, 2),
         hb, travel, keys);
  Button(b, body, V3(0.33 * w, t, zr), V3::UnitY(), V3::UnitX(), RoundRect(0.011, 0.007, 0.002, 2),
         hb, travel, keys);
  Button(b, body, V3(0, t, zr), V3::UnitY(), V3::UnitX(), Circle(0.0055, 20), hb, travel, keys);
  if (rng.P(0.5)) {
    Button(b, body, V3(-0.33 * w, t, zr + 0.0095), V3::UnitY(), V3::UnitX(),
           RoundRect(0.011, 0.006, 0.002, 2), hb, travel, keys);
    Button(b, body, V3(0.33 * w, t, zr + 0.0095), V3::UnitY(), V3::UnitX(),
           RoundRect(0.011, 0.006, 0.002, 2), hb, travel, keys);
  }
  // keypad 3 x 4 below
  double g0 = zr + 0.016, kz = std::min(0.012, (za1 - g0) / 4.0);
  ButtonGrid(b, body, V3(0, t, g0 + 2 * kz - 0.5 * kz + 0.5 * kz), 4, 3, 0.26 * w, kz, 0.8, 0.72,
             hb, travel, keys);
  // side buttons (volume)
  int side = rng.I(0, 2);
  for (int i = 0; i < side; ++i) {
    Button(b, body, V3(w / 2, 0.5 * t, -0.25 * l + 0.014 * i), V3::UnitX(), V3::UnitZ(),
           RoundRect(0.01, 0.003, 0.001, 2), 0.0015, 0.001, skin);
  }
  if (flip) {
    // clamshell lid hinged at the top end, folded over the keys
    double y0 = t + 0.002 + travel + hb + kGap;
    V3 lo(-w / 2, y0, -l / 2), hi(w / 2, y0 + 0.8 * t, l / 2);
    int lid = PanelHinge(b, body, "screen", lo, hi, V3::UnitY(), V3::UnitZ(), 160);
    int lp = b.Part(lid, "screen");
    b.Add(lp,
          RoundedSlab(FrameZ(V3(0, hi.y(), 0), -V3::UnitY(), V3::UnitX()), w, l, 0.8 * t, 0.008,
                      0.0015),
          skin);
    b.Dynamics(lid, 0.05, 0.005);
  }
}

void BuildRemote(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.7) ? DarkPlastic(rng) : LightPlastic(rng);
  Material keys = rng.P(0.5) ? LightPlastic(rng) : DarkPlastic(rng);
  Material accent = Plastic(rng);
  int body = b.Fixed(-1, "heavy", "base");
  double w = rng.U(0.04, 0.055), l = rng.U(0.15, 0.22), t = rng.U(0.015, 0.022);
  int bp = b.Part(body, "base");
  b.Add(bp, RoundedSlab(FrameZ(V3::Zero(), V3::UnitY(), V3::UnitX()), w, l, t, 0.01, 0.003), skin);
  double travel = 0.0015, hb = 0.003;
  // power button at the top end (towards -z)
  double z = -l / 2 + 0.015;
  Button(b, body, V3(-0.25 * w, t, z), V3::UnitY(), V3::UnitX(), Circle(0.005, 20), hb, travel,
         accent);
  if (rng.P(0.5))
    Button(b, body, V3(0.25 * w, t, z), V3::UnitY(), V3::UnitX(), Circle(0.004, 20), hb, travel,
           keys);
  z += 0.016;
  // number pad 3 x 4 (or 3 x 3)
  double px = 0.28 * w, pz = std::min(0.012, 0.08 * l);
  int rows = rng.P(0.8) ? 4 : 3;
  ButtonGrid(b, body, V3(0, t, z + (rows - 1) * pz / 2), rows, 3, px, pz, 0.75, 0.7, hb, travel,
             keys);
  z += rows * pz + 0.004;
  // colour row
  if (rng.P(0.6)) {
    ButtonGrid(b, body, V3(0, t, z), 1, 4, 0.22 * w, 0.008, 0.8, 0.7, hb, travel, accent);
    z += 0.01;
  }
  // navigation ring: four arrows and OK
  double nz = z + 0.016;
  Button(b, body, V3(0, t, nz), V3::UnitY(), V3::UnitX(), Circle(0.0055, 20), hb, travel, keys);
  for (int k = 0; k < 4; ++k) {
    double a = k * kPi / 2;
    V3 c(0.0125 * std::cos(a), t, nz + 0.0125 * std::sin(a));
    Button(b, body, c, V3::UnitY(), V3::UnitX(), RoundRect(0.007, 0.007, 0.002, 2), hb, travel,
           keys);
  }
  z = nz + 0.025;
  // volume / channel rockers and a grid of function keys to fill the rest
  double zmax = l / 2 - 0.012;
  int rows2 = std::max(0, static_cast<int>((zmax - z) / 0.011));
  rows2 = std::min(rows2, rng.I(2, 5));
  if (rows2 > 0)
    ButtonGrid(b, body, V3(0, t, z + (rows2 - 1) * 0.011 / 2), rows2, 3, px, 0.011, 0.75, 0.65, hb,
               travel, keys);
}

void BuildSwitch(ObjectBuilder& b, Rng& rng) {
  Material plate = rng.P(0.7) ? LightPlastic(rng) : Paint(rng).WithDensity(2000);
  Material act = rng.P(0.7) ? plate : DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "frame");
  double u = rng.U(0, 1);
  int n = u < 0.4 ? 1 : (u < 0.8 ? 2 : 3);
  double h = 0.086, w = n == 3 ? 0.086 : rng.U(0.07, 0.086), t = 0.008;
  int bp = b.Part(body, "frame");
  b.Add(bp, RoundedSlab(FrameZ(V3(0, h / 2, 0), V3::UnitZ(), V3::UnitX()), w, h, t, 0.004, 0.0015),
        plate);
  double kind_u = rng.U(0, 1);
  int kind = kind_u < 0.5
                 ? 0
                 : (kind_u < 0.7 ? 1 : (kind_u < 0.9 ? 2 : 3));  // rocker, toggle, button, slider
  double pitch = (w - 0.02) / n;
  for (int i = 0; i < n; ++i) {
    double x = -w / 2 + 0.01 + pitch * (i + 0.5);
    V3 c(x, h / 2, t);
    if (kind == 0) {
      // rocker: a block tilting about x through its centre; at rest tilted to one side
      double rw = 0.8 * pitch, rh = 0.05, rd = 0.008;
      double tilt = 10.0 * kPi / 180;
      double zc = t + kGap + rd / 2 + 0.5 * rh * std::sin(2 * tilt) + 0.001;
      int rocker = b.Hinge(body, "lever", V3(x, h / 2, zc), V3::UnitX(), 0, 20);
      Frame f;
      f.o = V3(x, h / 2, zc);
      f.r = Eigen::AngleAxisd(-tilt, V3::UnitX()).toRotationMatrix();
      b.AddPart(rocker, "lever", Box(f, V3(rw, rh, rd)), act);
      b.Dynamics(rocker, 0.05, 0.001);
    } else if (kind == 1) {
      // toggle bat on a round boss
      b.Add(bp, Cylinder(FrameZ(c, V3::UnitZ()), 0.008, 0.0, 0.004, 20), Steel(rng));
      V3 pivot(x, h / 2, t + 0.004 + kGap + 0.003);
      int lever = b.Hinge(body, "lever", pivot, V3::UnitX(), 0, 40);
      b.RestOnLimit(lever);
      Frame f = FrameZ(pivot, V3(0, -std::sin(0.35), std::cos(0.35)), V3::UnitX());
      b.AddPart(lever, "lever", Frustum(f, 0.003, 0.0022, 0.0, 0.02, 12), Steel(rng));
      b.Dynamics(lever, 0.05, 0.001);
    } else if (kind == 2) {
      Button(b, body, c, V3::UnitZ(), V3::UnitX(), RoundRect(0.8 * pitch, 0.045, 0.004, 3), 0.006,
             0.002, act);
    } else {
      // dimmer: a knob sliding along y in a slot
      b.Add(bp, BoxLoHi(V3(x - 0.002, 0.018, t - 0.0005), V3(x + 0.002, h - 0.018, t + 0.0003)),
            DarkPlastic(rng));
      int slider = b.Slider(body, "slider", V3(x, 0.025, t + kGap), V3::UnitY(), 0, h - 0.05);
      b.AddPart(slider, "slider",
                Loft(RoundRect(0.6 * pitch, 0.012, 0.003, 2),
                     {Ring{0.0, 1.0}, Ring{0.008, 1.0}, Ring{0.01, 0.85}},
                     FrameZ(V3(x, 0.025, t + kGap), V3::UnitZ(), V3::UnitX())),
                act);
      b.Dynamics(slider, 0.3, 0.02);
    }
  }
}

void BuildUSB(ObjectBuilder& b, Rng& rng) {
  Material skin = Plastic(rng);
  Material metal = Steel(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.016, 0.02), l = rng.U(0.035, 0.05), t = rng.U(0.007, 0.01);
  int bp = b.Part(body, "body");
  // lies flat, connector towards +x
  b.Add(bp, RoundedSlab(FrameZ(V3(0, 0, 0), V3::UnitY(), V3::UnitZ()), l, w, t, 0.003, 0.001),
        skin);
  double cl = 0.012;
  b.AddPart(
      body, "connector",
      BoxLoHi(V3(l / 2 - 0.001, 0.5 * t - 0.0023, -0.006), V3(l / 2 + cl, 0.5 * t + 0.0023, 0.006)),
      metal);
  if (rng.P(0.6)) {
    // swivel cover: two plates above and below joined at the far end, turning about y
    V3 pivot(-l / 2 + 0.008, 0, 0);
    double reach = std::hypot(l / 2 + cl - pivot.x(), w / 2) + kGap + 0.002;
    int cover = b.Continuous(body, "rotation", pivot, V3::UnitY());
    int cp = b.Part(cover, "cover");
    double pw = w + 0.002;
    double x1 = pivot.x() + reach;
    b.Add(cp,
          BoxLoHi(V3(pivot.x() - 0.006, t + kGap, -pw / 2),
                  V3(x1 + 0.0012, t + kGap + 0.0008, pw / 2)),
          metal);
    b.Add(cp,
          BoxLoHi(V3(pivot.x() - 0.006, -kGap - 0.0008, -pw / 2), V3(x1 + 0.0012, -kGap, pw / 2)),
          metal);
    b.Add(cp, BoxLoHi(V3(x1, -kGap - 0.0008, -pw / 2), V3(x1 + 0.0012, t + kGap + 0.0008, pw / 2)),
          metal);
    b.Dynamics(cover, 0.005, 0.0005);
  } else {
    // cap pulled off the connector
    double x0 = l / 2 + cl + kGap;
    int cap = b.Slider(body, "lid", V3(x0, 0.5 * t, 0), V3::UnitX(), 0, 0.03);
    b.AddPart(cap, "cap",
              RoundedSlab(FrameZ(V3(x0 + 0.008, 0, 0), V3::UnitY(), V3::UnitZ()), 0.016, w, t,
                          0.003, 0.001),
              skin);
    b.Dynamics(cap, 0.2, 0.02);
  }
}

}  // namespace partsim::internal::gen
