// Furniture and large objects: storage furniture, tables, chairs, doors, windows, toilets, trash
// cans, carts, safes, boxes and suitcases.
#include <algorithm>
#include <cmath>

#include "assets/generator/categories.h"
#include "partsim/core/constants.h"

namespace partsim::internal::gen {
namespace {

/// One row of a carcass front, bottom to top.
struct Row {
  enum Kind { kDrawer, kDoor, kOpen } kind;
  int columns;
  double weight;  ///< share of the inner height
};

/// A carcass (shell open at the front, between lo and hi, walls t) with rows of drawers, doors
/// or open shelves, added to link `body`. Fronts overlay the carcass by kGap in front of it.
void Carcass(ObjectBuilder& b, Rng& rng, int body, const V3& lo, const V3& hi, double t,
             const std::vector<Row>& rows, const Material& wood, const Material& handle_mat,
             HandleStyle hs) {
  int frame = b.Part(body, "frame");
  Shell(b, frame, lo, hi, t, "Z", wood);
  const double zf = hi.z(), ft = std::min(0.02, t + 0.002);
  double total = 0;
  for (const Row& r : rows) total += r.weight;
  // row boundaries over the inner height
  std::vector<double> ys = {lo.y() + t};
  double inner = hi.y() - lo.y() - 2 * t - (rows.size() - 1) * t;
  for (const Row& r : rows) ys.push_back(ys.back() + inner * r.weight / total + t);
  ys.back() = hi.y() - t + t;  // the last row ends at the top wall's inner face (+t below)
  bool door_left = rng.P(0.5);
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    double y0 = ys[i], y1 = ys[i + 1] - t;  // inner space of the row
    if (i + 1 < rows.size())
      b.Add(frame, BoxLoHi(V3(lo.x(), y1, lo.z()), V3(hi.x(), y1 + t, zf)), wood);
    // front panel extents: the outer rows reach the carcass edges
    double fy0 = i == 0 ? lo.y() : y0 - 0.5 * t + 0.5 * kGap;
    double fy1 = i + 1 == rows.size() ? hi.y() : y1 + 0.5 * t - 0.5 * kGap;
    double x_in0 = lo.x() + t, x_in1 = hi.x() - t;
    int cols = std::max(1, r.columns);
    double cw = (x_in1 - x_in0 - (cols - 1) * t) / cols;
    for (int c = 0; c < cols; ++c) {
      double cx0 = x_in0 + c * (cw + t), cx1 = cx0 + cw;
      if (r.kind == Row::kDrawer && c + 1 < cols) {
        b.Add(frame, BoxLoHi(V3(cx1, y0, lo.z()), V3(cx1 + t, y1, zf)), wood);
      }
      double fx0 = c == 0 ? lo.x() : cx0 - 0.5 * t + 0.5 * kGap;
      double fx1 = c + 1 == cols ? hi.x() : cx1 + 0.5 * t - 0.5 * kGap;
      if (r.kind == Row::kDrawer) {
        double depth = zf - lo.z() - t - 2 * kGap;
        double travel = std::min(0.85 * depth, rng.U(0.3, 0.5));
        Drawer(b, body, V3(cx0 + kGap, y0 + kGap, lo.z() + t + kGap),
               V3(cx1 - kGap, y1 - kGap - std::min(0.02, 0.2 * (y1 - y0)), zf), fx0, fx1, fy0, fy1,
               zf + kGap, ft, travel, hs, wood, handle_mat);
      }
    }
    if (r.kind == Row::kDoor) {
      // one door, or two meeting in the middle
      int doors = (hi.x() - lo.x() > 0.7 || (r.columns > 1)) ? 2 : 1;
      for (int d = 0; d < doors; ++d) {
        double dx0 = doors == 1 ? lo.x() : (d == 0 ? lo.x() : 0.5 * (lo.x() + hi.x()) + 0.5 * kGap);
        double dx1 = doors == 1 ? hi.x() : (d == 0 ? 0.5 * (lo.x() + hi.x()) - 0.5 * kGap : hi.x());
        bool left = doors == 1 ? door_left : d == 0;
        V3 plo(dx0, fy0, zf + kGap), phi(dx1, fy1, zf + kGap + ft);
        int door = HingedPanel(b, body, "door", "door", plo, phi, V3::UnitZ(),
                               left ? V3(1, 0, 0) : V3(-1, 0, 0), rng.U(90, 120), wood);
        b.Dynamics(door, 0.3, 0.5);
        double hx = left ? dx1 - 0.05 : dx0 + 0.05;
        double len = std::min(0.5 * (fy1 - fy0), 0.3);
        double hy = (fy1 - fy0) > 0.8 ? std::min(fy1 - 0.25, std::max(fy0 + 0.25, lo.y() + 1.0))
                                      : 0.5 * (fy0 + fy1);
        AddHandle(b, door, hs == HandleStyle::kEdge ? HandleStyle::kBar : hs,
                  V3(hx, hy, zf + kGap + ft), V3::UnitZ(), V3::UnitY(), len, handle_mat);
      }
      if (y1 - y0 > 0.5) {
        double ys_mid = 0.5 * (y0 + y1);
        b.Add(frame,
              BoxLoHi(V3(lo.x() + t, ys_mid, lo.z() + t), V3(hi.x() - t, ys_mid + t, zf - 0.02)),
              wood);
      }
    }
    if (r.kind == Row::kOpen && y1 - y0 > 0.35) {
      double ys_mid = 0.5 * (y0 + y1);
      b.Add(frame, BoxLoHi(V3(lo.x() + t, ys_mid, lo.z() + t), V3(hi.x() - t, ys_mid + t, zf)),
            wood);
    }
  }
}

/// Legs or plinth under a carcass whose bottom is at height h.
void Feet(ObjectBuilder& b, Rng& rng, int body, double x0, double x1, double z0, double z1,
          double h, const Material& mat) {
  if (h <= 0.001) return;
  int part = b.Part(body, "leg");
  if (rng.P(0.5)) {
    // plinth set back from the front
    b.Add(part, BoxLoHi(V3(x0 + 0.02, 0, z0 + 0.02), V3(x1 - 0.02, h + 0.001, z1 - 0.04)), mat);
  } else {
    double r = rng.U(0.012, 0.02);
    for (double x : {x0 + 0.04, x1 - 0.04}) {
      for (double z : {z0 + 0.04, z1 - 0.04}) {
        b.Add(part, Frustum(FrameZ(V3(x, 0, z), V3::UnitY()), 0.7 * r, r, 0.0, h + 0.001, 16), mat);
      }
    }
  }
}

}  // namespace

void BuildStorageFurniture(ObjectBuilder& b, Rng& rng) {
  Material wood = Wood(rng);
  Material hmat = rng.P(0.6) ? Steel(rng) : Wood(rng);
  HandleStyle hs = RandomHandleStyle(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.4, 1.2), d = rng.U(0.35, 0.6), t = rng.U(0.015, 0.02);
  double feet = rng.P(0.6) ? rng.U(0.04, 0.12) : 0.0;
  std::vector<Row> rows;
  double u = rng.U(0, 1), h;
  if (u < 0.3) {
    // chest of drawers
    int n = rng.I(2, 4);
    int cols = w > 0.8 && rng.P(0.4) ? 2 : 1;
    for (int i = 0; i < n; ++i) rows.push_back({Row::kDrawer, i == n - 1 ? cols : 1, 1.0});
    h = rng.U(0.16, 0.25) * n;
  } else if (u < 0.6) {
    // cupboard with one or two doors, tall or low
    h = rng.U(0.5, 1.9);
    rows.push_back({Row::kDoor, 1, 1.0});
    if (h > 1.3 && rng.P(0.4)) rows.push_back({Row::kDoor, 1, 0.6});
  } else if (u < 0.85) {
    // doors below, drawers above
    h = rng.U(0.7, 1.2);
    rows.push_back({Row::kDoor, 1, 3.0});
    int n = rng.I(1, 2);
    for (int i = 0; i < n; ++i) rows.push_back({Row::kDrawer, w > 0.8 ? 2 : 1, 1.0});
  } else {
    // open shelf with a drawer or a door
    h = rng.U(0.6, 1.6);
    rows.push_back(rng.P(0.5) ? Row{Row::kDrawer, 1, 1.0} : Row{Row::kDoor, 1, 1.5});
    rows.push_back({Row::kOpen, 1, 2.0});
  }
  Feet(b, rng, body, -w / 2, w / 2, -d / 2, d / 2, feet, wood);
  Carcass(b, rng, body, V3(-w / 2, feet, -d / 2), V3(w / 2, feet + h, d / 2), t, rows, wood, hmat,
          hs);
}

void BuildTable(ObjectBuilder& b, Rng& rng) {
  Material wood = Wood(rng);
  Material metal = Steel(rng);
  Material hmat = rng.P(0.6) ? Steel(rng) : Wood(rng);
  HandleStyle hs = RandomHandleStyle(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.8, 1.6), d = rng.U(0.5, 0.85), h = rng.U(0.68, 0.78);
  double tt = rng.U(0.025, 0.04);
  double u = rng.U(0, 1);
  bool wheels = u > 0.8;
  double wheel_r = wheels ? rng.U(0.03, 0.05) : 0.0;
  double leg_bottom = wheels ? 2 * wheel_r + 0.006 : 0.0;
  int top = b.Part(body, "tabletop");
  b.Add(top, RoundedSlab(FrameZ(V3(0, h - tt, 0), V3::UnitY(), V3::UnitX()), w, d, tt, 0.01, 0.004),
        wood);
  // legs
  int legs = b.Part(body, "leg");
  double lw = rng.U(0.035, 0.06);
  bool pedestal = u < 0.45;
  double ped_w = std::min(0.42, 0.35 * w);
  std::vector<double> leg_x = {-w / 2 + 0.03 + lw / 2, w / 2 - 0.03 - lw / 2};
  for (double x : leg_x) {
    for (double z : {-d / 2 + 0.03 + lw / 2, d / 2 - 0.03 - lw / 2}) {
      if (pedestal && x > 0) continue;
      b.Add(legs,
            BoxLoHi(V3(x - lw / 2, leg_bottom, z - lw / 2),
                    V3(x + lw / 2, h - tt + 0.001, z + lw / 2)),
            wood);
      if (wheels) {
        Wheel(b, body, V3(x, wheel_r, z), V3::UnitX(), wheel_r, 0.025, Rubber(), metal);
        // fork holding the wheel
        int fork = b.Part(body, "wheel_fork");
        for (int s : {-1, 1}) {
          b.Add(fork,
                BoxLoHi(V3(x + s * (0.0125 + 0.002 + kGap) - (s < 0 ? 0.004 : 0), wheel_r - 0.01,
                           z - 0.012),
                        V3(x + s * (0.0125 + 0.002 + kGap) + (s > 0 ? 0.004 : 0),
                           leg_bottom + 0.001, z + 0.012)),
                metal);
        }
      }
    }
  }
  // drawers under the top (an apron box) and a pedestal
  double apron_h = rng.U(0.1, 0.16);
  int n_apron = wheels ? rng.I(0, 1) : rng.I(1, pedestal ? 2 : 3);
  double ax0 = -w / 2 + 0.03 + lw + 0.01,
         ax1 = pedestal ? w / 2 - ped_w - 0.01 : w / 2 - 0.03 - lw - 0.01;
  if (n_apron > 0) {
    double seg = (ax1 - ax0) / n_apron;
    for (int i = 0; i < n_apron; ++i) {
      double x0 = ax0 + i * seg, x1 = x0 + seg;
      std::vector<Row> rows = {{Row::kDrawer, 1, 1.0}};
      Carcass(b, rng, body, V3(x0 + 0.001, h - tt - apron_h, -d / 2 + 0.04),
              V3(x1 - 0.001, h - tt - kGap, d / 2 - 0.03), 0.015, rows, wood, hmat, hs);
    }
  }
  if (pedestal) {
    std::vector<Row> rows;
    if (rng.P(0.5)) {
      rows =
          std::vector<Row>{{Row::kDrawer, 1, 1.0}, {Row::kDrawer, 1, 1.0}, {Row::kDrawer, 1, 1.0}};
    } else {
      rows = std::vector<Row>{{Row::kDoor, 1, 2.0}, {Row::kDrawer, 1, 1.0}};
    }
    Carcass(b, rng, body, V3(w / 2 - ped_w, 0.0, -d / 2 + 0.02),
            V3(w / 2 - 0.01, h - tt - kGap, d / 2 - 0.03), 0.016, rows, wood, hmat, hs);
  }
}

void BuildChair(ObjectBuilder& b, Rng& rng) {
  Material frame = rng.P(0.5) ? DarkPlastic(rng) : Aluminium(rng);
  Material fabric = Fabric(rng);
  Material dark = DarkPlastic(rng);
  // star base and gas column
  int body = b.Fixed(-1, "heavy", "leg");
  const int n_legs = 5;
  double caster_h = rng.U(0.055, 0.075);
  double base_r = rng.U(0.28, 0.34);
  double leg_y = caster_h + 0.004;  // bottom of the star legs
  int star = b.Part(body, "leg");
  b.Add(star, Cylinder(FrameZ(V3(0, leg_y, 0), V3::UnitY()), 0.04, 0.0, 0.06, 24), frame);
  for (int i = 0; i < n_legs; ++i) {
    double a = 2 * kPi * i / n_legs + 0.3;
    V3 dir(std::cos(a), 0, std::sin(a));
    V3 tip = dir * base_r;
    b.Add(star,
          Bar(V3(0, leg_y + 0.02, 0), V3(tip.x(), leg_y + 0.02, tip.z()), 0.03, 0.03, V3::UnitY()),
          frame);
    b.Add(star, Cylinder(FrameZ(V3(tip.x(), leg_y, tip.z()), V3::UnitY()), 0.015, 0.0, 0.03, 16),
          frame);
    Caster(b, body, V3(tip.x(), leg_y - kGap, tip.z()), caster_h - kGap + 0.004 - 0.004, dark,
           Rubber(), rng);
  }
  double seat_y = rng.U(0.42, 0.5);
  double st = rng.U(0.05, 0.08);
  double col_top = seat_y - st - 0.06;
  b.Add(
      star,
      Cylinder(FrameZ(V3(0, leg_y + 0.05, 0), V3::UnitY()), 0.025, 0.0, col_top - leg_y - 0.05, 20),
      dark);
  // seat: mechanism block, cushion, back, arms; swivels about the column
  int seat = b.Continuous(body, "seat", V3(0, col_top, 0), V3::UnitY());
  b.Dynamics(seat, 0.5, 0.3);
  double sw = rng.U(0.44, 0.52), sd = rng.U(0.42, 0.5);
  double mech_y0 = col_top + kGap;
  int mech = b.Part(seat, "mechanism");
  b.Add(mech, BoxLoHi(V3(-0.1, mech_y0, -0.12), V3(0.1, seat_y - st, 0.1)), dark);
  int cushion = b.Part(seat, "seat_cushion");
  b.Add(cushion,
        RoundedSlab(FrameZ(V3(0, seat_y - st, 0.01), V3::UnitY(), V3::UnitX()), sw, sd, st, 0.06,
                    0.015),
        fabric);
  double back_h = rng.U(0.4, 0.65), back_t = rng.U(0.05, 0.08);
  int back = b.Part(seat, "backrest");
  double back_z = -sd / 2 + 0.01 - 0.03;
  b.Add(back,
        Bar(V3(0, seat_y - st - 0.005, back_z + 0.06), V3(0, seat_y + 0.08, back_z - back_t / 2),
            0.06, 0.012, V3::UnitX()),
        dark);
  b.Add(back,
        BoxLoHi(V3(-0.03, seat_y + 0.06, back_z - back_t / 2 - 0.008),
                V3(0.03, seat_y + 0.12, back_z - back_t / 2 + 0.002)),
        dark);
  Frame bf = FrameZ(V3(0, seat_y + 0.1 + back_h / 2, back_z), V3::UnitZ(), V3::UnitX());
  b.Add(back, Prism(RoundRect(sw * rng.U(0.85, 1.0), back_h, 0.07, 6), bf, -back_t / 2, back_t / 2),
        fabric);
  // arms
  bool arms = rng.P(0.75);
  if (arms) {
    int arm = b.Part(seat, "armrest");
    for (int s : {-1, 1}) {
      double x = s * (sw / 2 + 0.03);
      b.Add(arm,
            BoxLoHi(V3(x - 0.012, seat_y - st - 0.02, -0.08), V3(x + 0.012, seat_y + 0.2, -0.04)),
            dark);
      b.Add(arm,
            BoxLoHi(V3(x - 0.012, seat_y - st - 0.03, -0.12),
                    V3(x + 0.012, seat_y - st - 0.01, 0.05)),
            dark);
      b.Add(arm,
            RoundedSlab(FrameZ(V3(x, seat_y + 0.2, -0.04), V3::UnitY(), V3::UnitX()), 0.07, 0.25,
                        0.025, 0.02, 0.008),
            dark);
    }
  }
  // height lever (and a tilt lever), tension knob (and a second knob), under the seat
  int levers = rng.P(0.7) ? 2 : 1;
  for (int i = 0; i < levers; ++i) {
    double s = i == 0 ? 1.0 : -1.0;
    V3 pivot(s * (0.1 + kGap), seat_y - st - 0.045, 0.0);
    int lever = b.Hinge(seat, "lever", pivot, s * V3::UnitZ(), -12, 0);
    b.RestOnLimit(lever);
    int part = b.Part(lever, "lever");
    b.Add(part,
          Bar(pivot + V3(s * 0.003, 0, 0), pivot + V3(s * 0.095, 0, 0), 0.012, 0.008, V3::UnitZ()),
          dark);
    b.Add(part, Sphere(pivot + V3(s * 0.105, 0, 0), 0.012, 6, 12), dark);
  }
  int knobs = rng.P(0.7) ? 2 : 1;
  for (int i = 0; i < knobs; ++i) {
    double x = knobs == 1 ? 0.0 : (i == 0 ? -0.05 : 0.05);
    Knob(b, seat, V3(x, 0.5 * (mech_y0 + seat_y - st), 0.1), V3::UnitZ(), 0.022, 0.03, 0, dark);
  }
}

void BuildFoldingChair(ObjectBuilder& b, Rng& rng) {
  Material metal = rng.P(0.5) ? Steel(rng) : Aluminium(rng);
  Material seat_mat = rng.P(0.5) ? Wood(rng) : Plastic(rng);
  int body = b.Fixed(-1, "heavy", "leg");
  double w = rng.U(0.4, 0.46), sd = rng.U(0.38, 0.44), sy = rng.U(0.42, 0.46);
  double tube = rng.U(0.011, 0.014);
  int legs = b.Part(body, "leg");
  double zb = -sd / 2 - 0.03;  // back legs and back rest plane
  double bt = 0.02;            // backrest board thickness
  for (int s : {-1, 1}) {
    double x = s * (w / 2 + tube + kGap);
    // back leg rising to the backrest, front leg crossing under the seat
    b.Add(legs, Rod(V3(x, 0, zb + 0.12), V3(x, sy + rng.U(0.35, 0.42), zb), tube, 12), metal);
    b.Add(legs,
          Rod(V3(x + s * 2.2 * tube, 0, sd / 2), V3(x + s * 2.2 * tube, sy - 0.01, zb + 0.02), tube,
              12),
          metal);
  }
  b.Add(legs,
        Rod(V3(-w / 2 - 0.02, sy - 0.04, zb + 0.03), V3(w / 2 + 0.02, sy - 0.04, zb + 0.03), 0.008,
            10),
        metal);
  b.Add(
      legs,
      Rod(V3(-w / 2 - tube, 0.12, sd / 2 - 0.02), V3(w / 2 + tube, 0.12, sd / 2 - 0.02), 0.008, 10),
      metal);
  double by = sy + rng.U(0.18, 0.25);
  b.AddPart(body, "backrest",
            BoxLoHi(V3(-w / 2, by, zb - bt - kGap - 0.01), V3(w / 2, by + 0.15, zb - kGap - 0.01)),
            seat_mat);
  // seat folds up about its back edge
  double t = rng.U(0.012, 0.02);
  V3 lo(-w / 2, sy, zb + 0.01 + t + 2 * kGap), hi(w / 2, sy + t, sd / 2);
  int seat = HingedPanel(b, body, "seat", "seat", lo, hi, V3::UnitY(), V3::UnitZ(), rng.U(80, 90),
                         seat_mat);
  b.Dynamics(seat, 0.2, 0.2);
}

void BuildDoor(ObjectBuilder& b, Rng& rng) {
  Material wood = Wood(rng);
  Material metal = rng.P(0.5) ? Steel(rng) : Aluminium(rng);
  int body = b.Fixed(-1, "heavy", "frame");
  double w = rng.U(0.7, 1.0), h = rng.U(1.9, 2.2), T = rng.U(0.035, 0.05), jw = rng.U(0.05, 0.09);
  double depth = T + rng.U(0.04, 0.1);
  int frame = b.Part(body, "frame");
  double zf = T / 2, zb = zf - depth;
  b.Add(frame, BoxLoHi(V3(-w / 2 - jw, 0, zb), V3(-w / 2, h + jw, zf)), wood);
  b.Add(frame, BoxLoHi(V3(w / 2, 0, zb), V3(w / 2 + jw, h + jw, zf)), wood);
  b.Add(frame, BoxLoHi(V3(-w / 2, h, zb), V3(w / 2, h + jw, zf)), wood);
  bool left = rng.P(0.5);
  // the free edge of an inset door swings out past its closed position by up to T^2 / 2w
  double free = kGap + T * T / w;
  V3 lo(-w / 2 + (left ? kGap : free), kGap + 0.005, -T / 2),
      hi(w / 2 - (left ? free : kGap), h - kGap, T / 2);
  int door = HingedPanel(b, body, "rotation_door", "door", lo, hi, V3::UnitZ(),
                         left ? V3(1, 0, 0) : V3(-1, 0, 0), rng.U(90, 110), wood, true);
  b.Dynamics(door, 1.0, 2.0);
  // panels on the door face
  if (rng.P(0.6)) {
    int deco = b.Part(door, "panel");
    double pw = (w - 0.25) / 2;
    for (int i = 0; i < 2; ++i) {
      double x0 = -w / 2 + 0.1 + i * (pw + 0.05);
      b.Add(deco, BoxLoHi(V3(x0, 0.25, T / 2 - 0.001), V3(x0 + pw, h - 0.25, T / 2 + 0.006)), wood);
    }
  }
  // door knobs on both sides (a rose, a stem and a knob), turning about the door's normal;
  // round, so that they balance at rest
  double hx = left ? w / 2 - 0.07 : -w / 2 + 0.07, hy = rng.U(0.95, 1.05);
  int handle = b.Hinge(door, "handle", V3(hx, hy, 0), V3::UnitZ(), 0, rng.U(45, 90));
  b.Dynamics(handle, 0.05, 0.005);
  int hp = b.Part(handle, "handle");
  double kr = rng.U(0.024, 0.032);
  for (int side : {-1, 1}) {
    double z0 = side * (T / 2 + kGap);
    Frame f = FrameZ(V3(hx, hy, z0), side * V3::UnitZ());
    b.Add(hp, Cylinder(f, 0.027, 0.0, 0.008, 24), metal);
    b.Add(hp, Cylinder(f, 0.008, 0.006, 0.04, 16), metal);
    b.Add(hp,
          Loft(Circle(1.0, 32),
               {Ring{0.036, 0.6 * kr}, Ring{0.046, kr}, Ring{0.062, kr}, Ring{0.068, 0.7 * kr}}, f),
          metal);
  }
  // a keyhole escutcheon below (part of the door)
  if (rng.P(0.5)) {
    b.AddPart(door, "lock",
              Cylinder(FrameZ(V3(hx, hy - 0.08, T / 2), V3::UnitZ()), 0.015, -0.001, 0.004, 20),
              metal);
  }
}

void BuildWindow(ObjectBuilder& b, Rng& rng) {
  Material frame_mat = rng.P(0.5) ? Wood(rng) : LightPlastic(rng);
  Material glass = Glass();
  int body = b.Fixed(-1, "heavy", "frame");
  double w = rng.U(0.6, 1.6), h = rng.U(0.6, 1.5), fw = rng.U(0.04, 0.07);
  double sash_t = rng.U(0.03, 0.05), sw = rng.U(0.035, 0.055);
  int frame = b.Part(body, "frame");
  double u = rng.U(0, 1);
  auto sash_parts = [&](int link, const V3& lo, const V3& hi) {
    int p = b.Part(link, "sash");
    Shell(b, p, lo, hi, sw, "zZ", frame_mat);
    double zm = 0.5 * (lo.z() + hi.z());
    b.AddPart(link, "glass",
              BoxLoHi(V3(lo.x() + sw - 0.001, lo.y() + sw - 0.001, zm - 0.003),
                      V3(hi.x() - sw + 0.001, hi.y() - sw + 0.001, zm + 0.003)),
              glass);
  };
  if (u < 0.55) {
    // sliding window: sashes on parallel tracks
    int n = u < 0.4 ? 2 : 3;
    double depth = n * (sash_t + 2 * kGap) + 0.01;
    double z0 = -depth / 2;
    b.Add(frame, BoxLoHi(V3(-w / 2 - fw, -fw, z0), V3(w / 2 + fw, 0, z0 + depth)), frame_mat);
    b.Add(frame, BoxLoHi(V3(-w / 2 - fw, h, z0), V3(w / 2 + fw, h + fw, z0 + depth)), frame_mat);
    b.Add(frame, BoxLoHi(V3(-w / 2 - fw, 0, z0), V3(-w / 2, h, z0 + depth)), frame_mat);
    b.Add(frame, BoxLoHi(V3(w / 2, 0, z0), V3(w / 2 + fw, h, z0 + depth)), frame_mat);
    double pane = (w + (n - 1) * 0.04) / n;
    for (int i = 0; i < n; ++i) {
      double x0 = -w / 2 + kGap + i * (pane - 0.04), x1 = x0 + pane - 2 * kGap;
      if (i == n - 1) x1 = w / 2 - kGap;
      double zt = z0 + 0.005 + kGap + i * (sash_t + 2 * kGap);
      int sash;
      // sashes slide towards the middle; the last one slides to the left
      double room_right = w / 2 - kGap - x1, room_left = x0 + w / 2 - kGap;
      bool to_right = room_right > room_left;
      double travel = std::max(room_right, room_left) - 0.001;
      sash = b.Slider(body, "window", V3(0.5 * (x0 + x1), h / 2, zt + sash_t / 2),
                      to_right ? V3(1, 0, 0) : V3(-1, 0, 0), 0, travel);
      b.Dynamics(sash, 2.0, 2.0);
      sash_parts(sash, V3(x0, kGap, zt), V3(x1, h - kGap, zt + sash_t));
      double hx = to_right ? x0 + 0.03 : x1 - 0.03;
      if (i == n - 1) {
        AddHandle(b, sash, HandleStyle::kEdge, V3(hx, h / 2, zt + sash_t), V3::UnitZ(), V3::UnitY(),
                  0.08, frame_mat);
      } else if (i == 0) {
        AddHandle(b, sash, HandleStyle::kEdge, V3(hx, h / 2, zt), -V3::UnitZ(), V3::UnitY(), 0.08,
                  frame_mat);
      }
    }
    // a sash at the end of its travel would leave the frame: clamp by the frame's jambs
  } else {
    // casement sashes set in the frame, hinged at the sides, and an optional awning on top
    double depth = sash_t + rng.U(0.01, 0.04);
    double zf = sash_t / 2, zb = zf - depth;
    bool awning = rng.P(0.45);  // a hopper sash above the casements
    double ha = awning ? rng.U(0.25, 0.4) * h : 0.0;
    double hc = h - ha - (awning ? fw : 0.0);
    b.Add(frame, BoxLoHi(V3(-w / 2 - fw, -fw, zb), V3(w / 2 + fw, 0, zf)), frame_mat);
    b.Add(frame, BoxLoHi(V3(-w / 2 - fw, h, zb), V3(w / 2 + fw, h + fw, zf)), frame_mat);
    b.Add(frame, BoxLoHi(V3(-w / 2 - fw, 0, zb), V3(-w / 2, h, zf)), frame_mat);
    b.Add(frame, BoxLoHi(V3(w / 2, 0, zb), V3(w / 2 + fw, h, zf)), frame_mat);
    if (awning) b.Add(frame, BoxLoHi(V3(-w / 2, hc, zb), V3(w / 2, hc + fw, zf)), frame_mat);
    int n = w > 0.8 ? 2 : 1;
    bool left_first = rng.P(0.5);
    for (int i = 0; i < n; ++i) {
      bool left = n == 1 ? left_first : i == 0;
      // an inset sash's free edge swings out past its closed position by up to t^2 / 2w:
      // leave room for it
      double sw_ = n == 1 ? w : w / 2;
      double free = kGap + sash_t * sash_t / sw_;
      double x0 = n == 1 ? -w / 2 + (left ? kGap : free) : (i == 0 ? -w / 2 + kGap : free / 2);
      double x1 = n == 1 ? w / 2 - (left ? free : kGap) : (i == 0 ? -free / 2 : w / 2 - kGap);
      V3 lo(x0, kGap, -sash_t / 2), hi(x1, hc - kGap, sash_t / 2);
      int sash = PanelHinge(b, body, "window", lo, hi, V3::UnitZ(),
                            left ? V3(1, 0, 0) : V3(-1, 0, 0), rng.U(80, 100), true);
      sash_parts(sash, lo, hi);
      b.Dynamics(sash, 0.3, 0.3);
      AddHandle(b, sash, HandleStyle::kEdge, V3(left ? x1 - 0.03 : x0 + 0.03, hc / 2, sash_t / 2),
                V3::UnitZ(), V3::UnitY(), 0.07, Steel(rng));
    }
    if (awning) {
      // a hopper: hinged at the bottom, its top tilts inwards (-z); gravity holds it closed
      V3 lo(-w / 2 + kGap, hc + fw + kGap, -sash_t / 2),
          hi(w / 2 - kGap, h - kGap - sash_t * sash_t / (h - hc - fw), sash_t / 2);
      int sash =
          PanelHinge(b, body, "window", lo, hi, -V3::UnitZ(), V3::UnitY(), rng.U(30, 50), true);
      sash_parts(sash, lo, hi);
      b.Dynamics(sash, 0.5, 0.5);
    }
  }
}

void BuildToilet(ObjectBuilder& b, Rng& rng) {
  Material cer = Ceramic(rng);
  Material seat_mat = rng.P(0.7) ? LightPlastic(rng) : Wood(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double bw = rng.U(0.34, 0.4), bl = rng.U(0.45, 0.55), bh = rng.U(0.36, 0.42);
  int bowl = b.Part(body, "bowl");
  // pedestal and bowl: elliptic lofts
  Frame fy = FrameZ(V3(0, 0, 0.02), V3::UnitY(), V3::UnitX());
  double ratio = bl / bw;
  Mesh ped = Loft(Ellipse(1.0, ratio * 0.8, 32), {Ring{0.0, 0.14}, Ring{0.5 * bh, 0.11}}, fy);
  b.Add(bowl, ped, cer);
  Mesh top = Loft(Ellipse(1.0, ratio, 32),
                  {Ring{0.45 * bh, 0.12}, Ring{0.8 * bh, 0.18}, Ring{bh, bw / 2}}, fy);
  b.Add(bowl, top, cer);
  double zback = 0.02 - ratio * bw / 2;  // back of the bowl rim
  // seat ring and lid, hinged at the back of the rim; the lid rides on the seat
  double ts = rng.U(0.015, 0.025), tl = rng.U(0.012, 0.02);
  bool has_seat = rng.P(0.6);
  double lid_y0 = bh + kGap + (has_seat ? ts + kGap : 0.0);
  double hinge_z = zback - 0.002;
  int parent = body;
  if (has_seat) {
    int seat = b.Hinge(body, "seat", V3(0, bh + kGap, hinge_z), -V3::UnitX(), 0, 92);
    b.Dynamics(seat, 0.2, 0.1);
    int sp = b.Part(seat, "seat");
    Frame f = FrameZ(V3(0, bh + kGap, 0.02), V3::UnitY(), V3::UnitX());
    // the seat ring, squeezed into an ellipse (local y maps to -z)
    Annulus(b, sp, f, 0.62 * bw / 2, bw / 2, 0.0, ts, 12, seat_mat, 0.0, 2 * kPi, 1.0, ratio);
    parent = seat;
  }
  int lid = b.Hinge(parent, "lid", V3(0, lid_y0, hinge_z), -V3::UnitX(), 0, 92);
  b.Dynamics(lid, 0.2, 0.1);
  Frame fl = FrameZ(V3(0, lid_y0, 0.02 + 0.005), V3::UnitY(), V3::UnitX());
  double lid_r = bw / 2 * 0.98;
  b.AddPart(lid, "lid",
            Loft(Ellipse(1.0, (ratio * bw / 2 - 0.012) / lid_r, 32),
                 {Ring{0.0, lid_r}, Ring{0.7 * tl, lid_r}, Ring{tl, lid_r * 0.95}}, fl),
            seat_mat);
  // tank behind the hinge, clear of the raised seat and lid
  double stack = lid_y0 + tl - bh;
  double tank_front = hinge_z - stack - 0.025;
  double th = rng.U(0.3, 0.42), tw = rng.U(0.36, 0.46), td = rng.U(0.15, 0.2);
  int tank = b.Part(body, "tank");
  b.Add(tank, BoxLoHi(V3(-0.12, 0.3 * bh, tank_front - td + 0.02), V3(0.12, bh, tank_front - 0.02)),
        cer);
  b.Add(tank,
        RoundedSlab(FrameZ(V3(0, bh - 0.01, tank_front - td / 2), V3::UnitY(), V3::UnitX()), tw, td,
                    th, 0.03, 0.01),
        cer);
  double tank_top = bh - 0.01 + th;
  if (rng.P(0.7)) {
    if (rng.P(0.6)) {
      // flush lever on the left side of the tank, clear of the raised lid, pointing back
      V3 pivot(-tw / 2 - kGap, tank_top - 0.05, tank_front - 0.045);
      int lever = b.Hinge(body, "lever", pivot, -V3::UnitX(), 0, 35);
      b.RestOnLimit(lever);
      int lp = b.Part(lever, "lever");
      b.Add(lp, Cylinder(FrameZ(pivot, -V3::UnitX()), 0.018, 0.0, 0.012, 20), Steel(rng));
      b.Add(lp,
            Bar(pivot - V3(0.012, 0, 0), pivot + V3(-0.016, 0, -0.09), 0.015, 0.008, V3::UnitY()),
            Steel(rng));
    } else {
      Button(b, body, V3(0, tank_top, tank_front - td / 2), V3::UnitY(), V3::UnitX(),
             Circle(0.025, 24), 0.008, 0.003, Steel(rng));
    }
  }
}

void BuildTrashCan(ObjectBuilder& b, Rng& rng) {
  Material mat = rng.P(0.5) ? Plastic(rng) : Steel(rng).WithDensity(1200);  // thin sheet
  int body = b.Fixed(-1, "heavy", "body");
  double h = rng.U(0.3, 0.75), r = rng.U(0.12, 0.22);
  bool round = rng.P(0.5);
  bool wheels = rng.P(0.25);
  double y0 = wheels ? 0.0 : 0.0;
  int shell = b.Part(body, "body");
  Frame f = FrameZ(V3(0, y0, 0), V3::UnitY(), V3::UnitX());
  std::vector<V2> poly = round ? Circle(1.0, 40) : RoundRect(2.0, 1.6, 0.2, 4);
  b.Add(shell, Loft(poly, {Ring{0.0, 0.88 * r}, Ring{h, r}}, f), mat);
  // lid hinged at the back of the top
  double lt = rng.U(0.015, 0.03);
  double lr = 1.02 * r;
  double zb = round ? -lr : -0.8 * lr;
  int lid = b.Hinge(body, "lid", V3(0, h + kGap, zb), -V3::UnitX(), 0, rng.U(75, 95));
  b.Dynamics(lid, 0.1, 0.1);
  Frame fl = FrameZ(V3(0, h + kGap, 0), V3::UnitY(), V3::UnitX());
  b.AddPart(lid, "lid", Loft(poly, {Ring{0.0, lr}, Ring{0.6 * lt, lr}, Ring{lt, 0.9 * lr}}, fl),
            mat);
  // hinge block behind, on the body
  b.AddPart(body, "hinge",
            BoxLoHi(V3(-0.04, h - 0.03, zb - lt - 0.025 - kGap),
                    V3(0.04, h - 0.005, zb - lt - kGap - 0.003)),
            mat);
  b.Add(shell, BoxLoHi(V3(-0.04, h - 0.04, zb - lt - 0.02 - kGap), V3(0.04, h - 0.025, 0.9 * zb)),
        mat);
  if (rng.P(0.5)) {
    // pedal at the front foot
    double zf = (round ? 1.0 : 0.8) * (0.88 * r + 0.12 * r * 0.06 / h);
    // a rocker pivoting at its middle, so that it balances at rest
    V3 pivot(0, 0.036, zf + kGap + 0.045);
    int pedal = b.Hinge(body, "pad", pivot, V3::UnitX(), 0, 12);
    b.AddPart(pedal, "pad", BoxLoHi(V3(-0.05, 0.03, zf + kGap), V3(0.05, 0.042, zf + kGap + 0.09)),
              Steel(rng));
  }
  if (wheels) {
    double wr = 0.04;
    for (int s : {-1, 1}) {
      V3 c(s * (0.88 * r * 0.6), wr + 0.005, -(round ? r : 0.8 * r) - wr - kGap - 0.005);
      Wheel(b, body, c, V3::UnitX(), wr, 0.03, Rubber(), mat);
      int axle = b.Part(body, "axle");
      double ax = c.x() - s * (0.016 + kGap + 0.004);
      b.Add(axle,
            BoxLoHi(V3(ax - 0.004, c.y() - 0.008, c.z() - 0.008),
                    V3(ax + 0.004, c.y() + 0.008, -(round ? 0.85 : 0.68) * r)),
            mat);
    }
  }
}

void BuildCart(ObjectBuilder& b, Rng& rng) {
  Material metal = Steel(rng);
  Material deck = rng.P(0.5) ? Wood(rng) : Plastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double wr = rng.U(0.04, 0.1), ww = rng.U(0.025, 0.05);
  if (rng.P(0.4)) {
    // platform cart: deck on four wheels, push handle at the back
    double w = rng.U(0.45, 0.7), d = rng.U(0.7, 1.1);
    double deck_y = 2 * wr + 0.03;
    int dp = b.Part(body, "deck");
    b.Add(dp, BoxLoHi(V3(-w / 2, deck_y, -d / 2), V3(w / 2, deck_y + 0.03, d / 2)), deck);
    double hh = rng.U(0.8, 1.0);
    b.Add(dp,
          Rod(V3(-w / 2 + 0.02, deck_y + 0.03, -d / 2 + 0.02), V3(-w / 2 + 0.02, hh, -d / 2 + 0.02),
              0.012),
          metal);
    b.Add(dp,
          Rod(V3(w / 2 - 0.02, deck_y + 0.03, -d / 2 + 0.02), V3(w / 2 - 0.02, hh, -d / 2 + 0.02),
              0.012),
          metal);
    b.Add(dp, Rod(V3(-w / 2 + 0.02, hh, -d / 2 + 0.02), V3(w / 2 - 0.02, hh, -d / 2 + 0.02), 0.014),
          metal);
    for (int sx : {-1, 1}) {
      for (int sz : {-1, 1}) {
        V3 c(sx * (w / 2 - ww / 2 - 0.02), wr, sz * (d / 2 - wr - 0.02));
        Wheel(b, body, c, V3::UnitX(), wr, ww, Rubber(), metal);
        for (int s : {-1, 1}) {
          double x = c.x() + s * (ww / 2 + 0.001 + kGap + 0.003);
          b.Add(dp,
                BoxLoHi(V3(x - 0.003, wr - 0.01, c.z() - 0.015),
                        V3(x + 0.003, deck_y + 0.001, c.z() + 0.015)),
                metal);
        }
      }
    }
  } else {
    // hand truck: upright frame, nose plate, two wheels at the bottom back
    double w = rng.U(0.35, 0.5), h = rng.U(1.0, 1.3);
    int fp = b.Part(body, "frame");
    double zf = 0.0;
    for (int s : {-1, 1})
      b.Add(fp, Rod(V3(s * w / 2, 0.02, zf), V3(s * w / 2, h, zf - 0.08), 0.014), metal);
    for (double y : {0.35, 0.7, h - 0.02})
      b.Add(fp, Rod(V3(-w / 2, y, zf - 0.08 * y / h), V3(w / 2, y, zf - 0.08 * y / h), 0.01),
            metal);
    b.Add(fp, BoxLoHi(V3(-w / 2 - 0.01, 0.0, zf), V3(w / 2 + 0.01, 0.012, zf + rng.U(0.18, 0.25))),
          metal);
    for (int s : {-1, 1}) {
      V3 c(s * (w / 2 + 0.03 + ww / 2), wr, zf - wr - 0.04);
      Wheel(b, body, c, V3::UnitX(), wr, ww, Rubber(), metal);
      // short axle along x, held by a strut from the frame
      b.Add(fp,
            Rod(V3(s * (w / 2 - 0.012), wr, c.z()), V3(s * (w / 2 + 0.03 - 2 * kGap), wr, c.z()),
                0.008),
            metal);
      b.Add(fp, Rod(V3(s * w / 2, 0.1, zf), V3(s * w / 2, wr, c.z()), 0.01), metal);
    }
  }
}

void BuildSafe(ObjectBuilder& b, Rng& rng) {
  Material paint = Paint(rng);
  Material steel = Steel(rng);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.3, 0.6), h = rng.U(0.25, 0.7), d = rng.U(0.3, 0.5), t = rng.U(0.02, 0.04);
  int shell = b.Part(body, "body");
  Shell(b, shell, V3(-w / 2, 0, -d / 2), V3(w / 2, h, d / 2), t, "Z", paint.WithDensity(2500));
  bool left = rng.P(0.5);
  double dt = rng.U(0.03, 0.05);
  V3 lo(-w / 2, 0, d / 2 + kGap), hi(w / 2, h, d / 2 + kGap + dt);
  int door =
      HingedPanel(b, body, "door", "door", lo, hi, V3::UnitZ(), left ? V3(1, 0, 0) : V3(-1, 0, 0),
                  rng.U(90, 110), paint.WithDensity(3000));
  b.Dynamics(door, 0.5, 1.0);
  double zf = d / 2 + kGap + dt;
  double cx = left ? w * 0.15 : -w * 0.15;
  bool keypad = rng.P(0.3);
  if (!keypad) Knob(b, door, V3(cx, h * 0.62, zf), V3::UnitZ(), 0.035, 0.025, 0, steel, "knob");
  // handle: a turning lever
  V3 hc(cx, h * 0.3, zf);
  int handle = b.Hinge(door, "handle", hc, V3::UnitZ(), 0, 90);
  int hp = b.Part(handle, "handle");
  b.Add(hp, Cylinder(FrameZ(hc, V3::UnitZ()), 0.015, 0.002, 0.045, 20), steel);
  b.Add(hp, Rod(hc + V3(-0.06, 0, 0.045), hc + V3(0.06, 0, 0.045), 0.008), steel);
  b.Dynamics(handle, 0.3, 0.05);
  if (keypad) {
    double kx = cx;
    double pitch = 0.016;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 3; ++c) {
        V3 p(kx + (c - 1) * pitch, h * 0.62 + (1.5 - r) * pitch, zf);
        Button(b, door, p, V3::UnitZ(), V3::UnitX(), RoundRect(0.012, 0.012, 0.003, 2), 0.004,
               0.002, dark);
      }
    }
  }
}

void BuildBox(ObjectBuilder& b, Rng& rng) {
  Material card = rng.P(0.7) ? Material{"cardboard", V3(0.66, 0.5, 0.33), 700} : Wood(rng);
  card.kd += V3::Constant(rng.U(-0.05, 0.05));
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.15, 0.6), d = rng.U(0.12, 0.45), h = rng.U(0.1, 0.4), t = rng.U(0.004, 0.01);
  int shell = b.Part(body, "body");
  Shell(b, shell, V3(-w / 2, 0, -d / 2), V3(w / 2, h, d / 2), t, "Y", card);
  double y0 = h + kGap;
  double u = rng.U(0, 1);
  if (u < 0.2) {
    // one lid hinged at the back
    int lid = HingedPanel(b, body, "rotation_lid", "lid", V3(-w / 2, y0, -d / 2 - kGap),
                          V3(w / 2, y0 + t, d / 2), V3::UnitY(), V3::UnitZ(), 110, card);
    b.Dynamics(lid, 0.05, 0.02);
  } else if (u < 0.8) {
    // two flaps meeting in the middle
    for (int s : {-1, 1}) {
      // the flaps overhang the walls a little so that, turned over, they clear them
      V3 lo(s < 0 ? -w / 2 - kGap : kGap / 2, y0, -d / 2),
          hi(s < 0 ? -kGap / 2 : w / 2 + kGap, y0 + t, d / 2);
      int flap = HingedPanel(b, body, "rotation_lid", "flap", lo, hi, V3::UnitY(),
                             s < 0 ? V3(1, 0, 0) : V3(-1, 0, 0), 180, card);
      b.Dynamics(flap, 0.03, 0.01);
    }
  } else {
    // four flaps cut along the diagonals of the top (a hip-roof plan), in (x, z)
    double m = std::min(w, d) / 2 + kGap;
    const double X = w / 2 + kGap, Z = d / 2 + kGap;
    std::vector<std::vector<V2>> flaps = {
        {V2(-X, -Z), V2(-X, Z), V2(-X + m, Z - m), V2(-X + m, -Z + m)},
        {V2(X, Z), V2(X, -Z), V2(X - m, -Z + m), V2(X - m, Z - m)},
        {V2(X, -Z), V2(-X, -Z), V2(-X + m, -Z + m), V2(X - m, -Z + m)},
        {V2(-X, Z), V2(X, Z), V2(X - m, Z - m), V2(-X + m, Z - m)}};
    const V3 outward[4] = {-V3::UnitX(), V3::UnitX(), -V3::UnitZ(), V3::UnitZ()};
    for (int k = 0; k < 4; ++k) {
      std::vector<V2> poly;
      for (const V2& p : flaps[k]) {
        if (poly.empty() || (p - poly.back()).norm() > 1e-6) poly.push_back(p);
      }
      if ((poly.front() - poly.back()).norm() < 1e-6) poly.pop_back();
      // counter-clockwise in the (x, z) plane
      double area = 0;
      for (size_t i = 0; i < poly.size(); ++i) {
        const V2& p = poly[i];
        const V2& q = poly[(i + 1) % poly.size()];
        area += p.x() * q.y() - q.x() * p.y();
      }
      if (area < 0) std::reverse(poly.begin(), poly.end());
      poly = Inset(poly, 0.5 * kGap);
      V3 origin(outward[k].x() * X, y0, outward[k].z() * Z);
      int flap = b.Hinge(body, "rotation_lid", origin, (-outward[k]).cross(V3::UnitY()), 0, 180);
      b.AddPart(flap, "flap", ProfileY(poly, y0, y0 + t), card);
      b.Dynamics(flap, 0.03, 0.01);
    }
  }
}

void BuildSuitcase(ObjectBuilder& b, Rng& rng) {
  Material shell = rng.P(0.5) ? Plastic(rng).WithDensity(250) : Fabric(rng).WithDensity(200);
  Material dark = DarkPlastic(rng);
  Material alu = Aluminium(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.35, 0.5), d = rng.U(0.2, 0.3), h = rng.U(0.5, 0.75);
  double u = rng.U(0, 1);
  int kind = u < 0.45 ? 0 : (u < 0.9 ? 1 : 2);  // 0 two wheels, 1 no wheels, 2 spinner
  double lift = kind == 1 ? 0.02 : 0.07;
  int bp = b.Part(body, "body");
  b.Add(bp, RoundedSlab(FrameZ(V3(0, lift, 0), V3::UnitY(), V3::UnitX()), w, d, h, 0.04, 0.02),
        shell);
  if (kind == 1) {
    for (int sx : {-1, 1})
      b.Add(bp, Box(V3(sx * (w / 2 - 0.04), lift / 2, 0), V3(0.04, lift + 0.002, 0.04)), dark);
  }
  double top = lift + h;
  // carry handle on top, folding flat
  double hl = rng.U(0.12, 0.18);
  {
    V3 lo(-hl / 2, top + kGap, -0.02), hi(hl / 2, top + kGap + 0.012, 0.02);
    int handle = b.Hinge(body, "rotation_handle", V3(0, top + kGap, -0.02), V3(-1, 0, 0), 0, 90);
    int hp = b.Part(handle, "handle");
    b.Add(hp, BoxLoHi(V3(lo.x(), lo.y(), lo.z()), V3(lo.x() + 0.015, hi.y(), hi.z())), dark);
    b.Add(hp, BoxLoHi(V3(hi.x() - 0.015, lo.y(), lo.z()), V3(hi.x(), hi.y(), hi.z())), dark);
    b.Add(hp, BoxLoHi(V3(lo.x(), lo.y(), hi.z() - 0.014), V3(hi.x(), hi.y() + 0.004, hi.z())),
          dark);
    b.Dynamics(handle, 0.02, 0.01);
  }
  if (kind != 1) {
    // telescopic handle behind the case: two tubes and a grip, pulled up
    double zb = -d / 2 - kGap - 0.012;
    int tr = b.Slider(body, "translation_handle", V3(0, top, zb), V3::UnitY(), 0, rng.U(0.3, 0.45));
    int tp = b.Part(tr, "handle");
    double tx = std::min(0.14, w / 2 - 0.05);
    for (int s : {-1, 1})
      b.Add(tp,
            Box(V3(s * tx, lift + 0.06 + (h - 0.06) / 2 + 0.015, zb), V3(0.018, h - 0.03, 0.018)),
            alu);
    b.Add(tp, Box(V3(0, top + 0.025, zb), V3(2 * tx + 0.03, 0.03, 0.024)), dark);
    b.Dynamics(tr, 1.0, 1.0);
    // brackets on the case back that the tubes run past
    b.Add(bp, Box(V3(0, lift + 0.03, -d / 2 + 0.001), V3(w * 0.8, 0.05, 0.004)), dark);
  }
  if (kind == 0) {
    for (int s : {-1, 1}) {
      double wr = 0.032;
      V3 c(s * (w / 2 - 0.04), wr, -d / 2 + 0.01);
      Wheel(b, body, c, V3::UnitX(), wr, 0.022, Rubber(), dark);
      b.Add(bp,
            Box(V3(c.x() - s * (0.011 + kGap + 0.006), wr + 0.012, c.z()), V3(0.012, 0.06, 0.05)),
            dark);
    }
  } else if (kind == 2) {
    for (int sx : {-1, 1}) {
      for (int sz : {-1, 1}) {
        Caster(b, body, V3(sx * (w / 2 - 0.05), lift - kGap, sz * (d / 2 - 0.05)), lift - kGap,
               dark, Rubber(), rng);
      }
    }
  }
}

}  // namespace partsim::internal::gen
