// Appliances and household objects: dishwashers, microwaves, ovens, refrigerators, washing
// machines, coffee machines, toasters, printers, fans, lamps, displays, kettles, pots, soap
// dispensers and faucets.
#include <algorithm>
#include <cmath>

#include "assets/generator/categories.h"
#include "partsim/core/constants.h"

namespace partsim::internal::gen {

void BuildDishwasher(ObjectBuilder& b, Rng& rng) {
  Material skin = Paint(rng);
  Material steel = Steel(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.45, 0.6), h = rng.U(0.8, 0.87), d = rng.U(0.55, 0.6), t = 0.02;
  double kick = rng.U(0.08, 0.12), panel = rng.U(0.0, 0.1);
  int bp = b.Part(body, "body");
  Shell(b, bp, V3(-w / 2, kick, -d / 2), V3(w / 2, h - panel, d / 2), t, "Z",
        skin.WithDensity(1500));
  b.Add(bp, BoxLoHi(V3(-w / 2, 0, -d / 2), V3(w / 2, kick, d / 2 - 0.05)), skin.WithDensity(500));
  if (panel > 0.01)
    b.Add(bp, BoxLoHi(V3(-w / 2, h - panel, -d / 2), V3(w / 2, h, d / 2)), skin.WithDensity(500));
  // racks inside (static)
  int rack = b.Part(body, "rack");
  for (double fy : {0.3, 0.65}) {
    double y = kick + fy * (h - panel - kick);
    b.Add(rack,
          BoxLoHi(V3(-w / 2 + t + 0.01, y, -d / 2 + t + 0.01),
                  V3(w / 2 - t - 0.01, y + 0.01, d / 2 - 0.03)),
          steel.WithDensity(800));
  }
  // door hinged at the bottom front, handle at its top
  double dt = rng.U(0.04, 0.06);
  V3 lo(-w / 2, kick + kGap, d / 2 + kGap),
      hi(w / 2, h - panel - (panel > 0.01 ? kGap : 0.0), d / 2 + kGap + dt);
  int door = b.Hinge(body, "rotation_door", V3(0, lo.y(), hi.z()), V3::UnitX(), 0, rng.U(85, 95));
  b.AddPart(door, "door", BoxLoHi(lo, hi), skin.WithDensity(1500));
  b.Dynamics(door, 0.5, 1.0);
  AddHandle(b, door, rng.P(0.5) ? HandleStyle::kBar : HandleStyle::kEdge,
            V3(0, hi.y() - 0.05, hi.z()), V3::UnitZ(), V3::UnitX(), 0.6 * w, steel);
  if (panel > 0.06 && rng.P(0.66)) {
    Knob(b, body, V3(w / 2 - 0.08, h - panel / 2, d / 2), V3::UnitZ(), 0.02, 0.02, 300,
         DarkPlastic(rng));
  }
}

void BuildMicrowave(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? Paint(rng) : LightPlastic(rng);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.45, 0.6), h = rng.U(0.26, 0.35), d = rng.U(0.33, 0.45), t = 0.015;
  double pw = rng.U(0.1, 0.14);  // control panel width on the right
  int bp = b.Part(body, "body");
  double cx1 = w / 2 - pw;
  Shell(b, bp, V3(-w / 2, 0.01, -d / 2), V3(cx1, h, d / 2), t, "Z", skin.WithDensity(1500));
  b.Add(bp, BoxLoHi(V3(cx1, 0.01, -d / 2), V3(w / 2, h, d / 2)), skin.WithDensity(300));
  for (double x : {-w / 2 + 0.04, w / 2 - 0.04}) {
    for (double z : {-d / 2 + 0.04, d / 2 - 0.04})
      b.Add(bp, Cylinder(FrameZ(V3(x, 0, z), V3::UnitY()), 0.012, 0.0, 0.011, 12), dark);
  }
  b.AddPart(body, "tray",
            Cylinder(FrameZ(V3(0.5 * (cx1 - w / 2), 0.01 + t, 0), V3::UnitY()),
                     0.4 * std::min(cx1 + w / 2, d), 0.0, 0.006, 32),
            Glass());
  // door over the cavity, hinged on the left
  double dt = 0.03;
  V3 lo(-w / 2, 0.01, d / 2 + kGap), hi(cx1 - kGap, h, d / 2 + kGap + dt);
  int door = PanelHinge(b, body, "door", lo, hi, V3::UnitZ(), V3::UnitX(), rng.U(95, 120));
  int dp = b.Part(door, "door");
  Shell(b, dp, lo, hi, 0.04, "zZ", skin);
  b.Add(dp, BoxLoHi(V3(lo.x(), lo.y(), lo.z()), V3(hi.x(), hi.y(), lo.z() + 0.01)), skin);
  b.AddPart(door, "glass",
            BoxLoHi(V3(lo.x() + 0.039, lo.y() + 0.039, lo.z() + 0.01),
                    V3(hi.x() - 0.039, hi.y() - 0.039, hi.z() - 0.005)),
            Glass());
  b.Dynamics(door, 0.1, 0.2);
  if (rng.P(0.5))
    AddHandle(b, door, HandleStyle::kBar, V3(hi.x() - 0.03, h / 2, hi.z()), V3::UnitZ(),
              V3::UnitY(), 0.5 * h, dark);
  // control panel: buttons and up to two knobs
  double px = w / 2 - pw / 2;
  int knobs = rng.I(0, 2);
  int buttons = std::max(1, rng.I(2, 6) - knobs);
  double y = h - 0.04;
  for (int k = 0; k < knobs; ++k, y -= 0.07)
    Knob(b, body, V3(px, y - 0.02, d / 2), V3::UnitZ(), 0.022, 0.02, rng.P(0.5) ? 0 : 300, dark);
  for (int i = 0; i < buttons && y > 0.05; ++i, y -= 0.035) {
    Button(b, body, V3(px, y, d / 2), V3::UnitZ(), V3::UnitX(),
           RoundRect(0.6 * pw, 0.022, 0.004, 2), 0.004, 0.002, dark);
  }
}

void BuildOven(ObjectBuilder& b, Rng& rng) {
  Material skin = Paint(rng);
  Material dark = DarkPlastic(rng);
  Material steel = Steel(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.5, 0.76), h = rng.U(0.55, 0.9), d = rng.U(0.5, 0.62), t = 0.02;
  bool tray = rng.P(0.3);
  double tray_h = tray ? rng.U(0.1, 0.15) : 0.0;
  double panel = rng.U(0.08, 0.12);
  double y0 = tray_h + (tray ? 0.02 : 0.0);
  int bp = b.Part(body, "body");
  Shell(b, bp, V3(-w / 2, y0, -d / 2), V3(w / 2, h - panel, d / 2), t, "Z", skin.WithDensity(2000));
  b.Add(bp, BoxLoHi(V3(-w / 2, h - panel, -d / 2), V3(w / 2, h, d / 2)), skin.WithDensity(500));
  b.Add(bp,
        BoxLoHi(V3(-w / 2 + t, y0 + 0.2 * (h - panel - y0), -d / 2 + t),
                V3(w / 2 - t, y0 + 0.2 * (h - panel - y0) + 0.008, d / 2 - 0.03)),
        steel.WithDensity(1000));
  if (tray) {
    Shell(b, bp, V3(-w / 2, 0, -d / 2), V3(w / 2, y0, d / 2), t, "Z", skin.WithDensity(2000));
    double depth = d - t - 2 * kGap;
    Drawer(b, body, V3(-w / 2 + t + kGap, t + kGap, -d / 2 + t + kGap),
           V3(w / 2 - t - kGap, y0 - t - kGap, d / 2), -w / 2, w / 2, 0.0, y0 - kGap / 2,
           d / 2 + kGap, 0.02, std::min(0.85 * depth, 0.4), HandleStyle::kEdge, skin, steel,
           "translation_tray");
  }
  // door hinged at the bottom with a window and a bar handle
  double dt = rng.U(0.04, 0.06);
  V3 lo(-w / 2, y0 + (tray ? kGap / 2 : 0.0), d / 2 + kGap),
      hi(w / 2, h - panel - kGap, d / 2 + kGap + dt);
  int door = b.Hinge(body, "door", V3(0, lo.y(), hi.z()), V3::UnitX(), 0, rng.U(85, 95));
  int dp = b.Part(door, "door");
  double frame = 0.07;
  Shell(b, dp, lo, hi, frame, "zZ", skin.WithDensity(2000));
  b.AddPart(door, "glass",
            BoxLoHi(V3(lo.x() + frame - 0.001, lo.y() + frame - 0.001, lo.z() + 0.01),
                    V3(hi.x() - frame + 0.001, hi.y() - frame + 0.001, hi.z() - 0.01)),
            Glass());
  b.Dynamics(door, 1.0, 1.0);
  AddHandle(b, door, HandleStyle::kBar, V3(0, hi.y() - 0.035, hi.z()), V3::UnitZ(), V3::UnitX(),
            0.7 * w, steel);
  // knobs (and buttons) on the panel face
  int knobs = rng.I(3, 6);
  double pitch = std::min(0.09, (w - 0.08) / (knobs + (rng.P(0.3) ? 1 : 0)));
  double yk = h - panel / 2;
  for (int i = 0; i < knobs; ++i) {
    double x = -w / 2 + 0.04 + pitch * (i + 0.5);
    Knob(b, body, V3(x, yk, d / 2), V3::UnitZ(), std::min(0.025, 0.4 * pitch), 0.025,
         rng.P(0.5) ? 0 : 270, dark);
  }
  double xb = -w / 2 + 0.04 + pitch * knobs + 0.02;
  int buttons = rng.P(0.3) ? rng.I(1, 2) : 0;
  for (int i = 0; i < buttons && xb + 0.03 * i < w / 2 - 0.02; ++i) {
    Button(b, body, V3(xb + 0.03 * i, yk, d / 2), V3::UnitZ(), V3::UnitX(),
           RoundRect(0.02, 0.014, 0.003, 2), 0.005, 0.002, dark);
  }
}

void BuildRefrigerator(ObjectBuilder& b, Rng& rng) {
  Material skin = Paint(rng);
  Material steel = Steel(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.55, 0.9), h = rng.U(0.85, 1.9), d = rng.U(0.55, 0.7), t = 0.04;
  double u = rng.U(0, 1);
  int layout =
      h < 1.1
          ? 0
          : (u < 0.25 ? 0 : (u < 0.85 ? 1 : 2));  // 0 one door, 1 top/bottom, 2 French + freezer
  double base = 0.03;
  int bp = b.Part(body, "body");
  b.Add(bp, BoxLoHi(V3(-w / 2 + 0.03, 0, -d / 2 + 0.03), V3(w / 2 - 0.03, base, d / 2 - 0.06)),
        DarkPlastic(rng));
  double split = layout == 0 ? h : base + rng.U(0.3, 0.4) * (h - base);
  std::vector<std::pair<double, double>> bands;  // compartments (y0, y1)
  if (layout == 0) {
    bands = {{base, h}};
  } else {
    bands = {{base, split}, {split, h}};
  }
  Shell(b, bp, V3(-w / 2, base, -d / 2), V3(w / 2, h, d / 2), t, "Z", skin.WithDensity(800));
  if (layout != 0)
    b.Add(bp, BoxLoHi(V3(-w / 2, split - t / 2, -d / 2), V3(w / 2, split + t / 2, d / 2)),
          skin.WithDensity(800));
  // shelves
  for (const auto& [y0, y1] : bands) {
    for (double f : {0.35, 0.7}) {
      double y = y0 + f * (y1 - y0);
      if (y1 - y0 > 0.5)
        b.Add(bp, BoxLoHi(V3(-w / 2 + t, y, -d / 2 + t), V3(w / 2 - t, y + 0.006, d / 2 - 0.05)),
              Glass());
    }
  }
  bool hinge_left = rng.P(0.5);
  double dt = rng.U(0.05, 0.07);
  auto door = [&](double x0, double x1, double y0, double y1, bool left) {
    V3 lo(x0, y0, d / 2 + kGap), hi(x1, y1, d / 2 + kGap + dt);
    int link =
        HingedPanel(b, body, "door", "door", lo, hi, V3::UnitZ(), left ? V3(1, 0, 0) : V3(-1, 0, 0),
                    rng.U(95, 120), skin.WithDensity(500));
    b.Dynamics(link, 0.5, 1.0);
    double len = std::min(0.6 * (y1 - y0), 0.4);
    double hy = y1 - y0 > 0.8 ? y0 + 0.5 * (y1 - y0)
                              : (y0 < 0.5 * h ? y1 - len / 2 - 0.04 : y0 + len / 2 + 0.04);
    AddHandle(b, link, HandleStyle::kBar, V3(left ? x1 - 0.04 : x0 + 0.04, hy, hi.z()), V3::UnitZ(),
              V3::UnitY(), len, steel);
  };
  if (layout == 0) {
    door(-w / 2, w / 2, base, h, hinge_left);
  } else if (layout == 1) {
    door(-w / 2, w / 2, base, split - kGap / 2, hinge_left);
    door(-w / 2, w / 2, split + kGap / 2, h, hinge_left);
  } else {
    door(-w / 2, w / 2, base, split - kGap / 2, hinge_left);
    door(-w / 2, -kGap / 2, split + kGap / 2, h, true);
    door(kGap / 2, w / 2, split + kGap / 2, h, false);
  }
}

void BuildWashingMachine(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.7) ? LightPlastic(rng) : Paint(rng);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.55, 0.62), h = rng.U(0.8, 0.88), d = rng.U(0.5, 0.62);
  double panel = rng.U(0.1, 0.14);
  int bp = b.Part(body, "body");
  b.Add(bp, RoundedSlab(FrameZ(V3(0, 0, 0), V3::UnitY(), V3::UnitX()), w, d, h, 0.02, 0.004),
        skin.WithDensity(250));
  // porthole door on the front, hinged on the left
  double r = rng.U(0.17, 0.22);
  double cy = 0.5 * (h - panel) + 0.02;
  V3 c(0, cy, d / 2 + kGap);
  double hx = -r - 0.015;
  int door = b.Hinge(body, "door", V3(hx, cy, d / 2 + kGap), -V3::UnitY(), 0, 90);
  int dp = b.Part(door, "door");
  Frame f = FrameZ(c, V3::UnitZ());
  Annulus(b, dp, f, 0.72 * r, r, 0.0, 0.05, 12, skin.WithDensity(1200));
  b.AddPart(door, "glass",
            Dome(FrameZ(c + V3(0, 0, -0.25 * r + 0.005), V3::UnitZ()), 0.9 * r, 0.25 * r, 6, 32),
            Glass());
  b.Add(dp, BoxLoHi(V3(hx, cy - 0.05, d / 2 + kGap), V3(-0.7 * r, cy + 0.05, d / 2 + kGap + 0.03)),
        dark);
  AddHandle(b, door, HandleStyle::kEdge, V3(0.85 * r, cy, d / 2 + kGap + 0.05), V3::UnitZ(),
            V3::UnitY(), 0.08, dark);
  b.Dynamics(door, 0.3, 0.5);
  // detergent drawer top left, knobs and buttons on the panel
  double py = h - panel / 2;
  double dw = rng.U(0.16, 0.22), dh = 0.8 * panel;
  int drawer = b.Slider(body, "drawer", V3(-w / 2 + 0.03 + dw / 2, py, d / 2 + kGap), V3::UnitZ(),
                        0, rng.U(0.12, 0.2));
  int drp = b.Part(drawer, "drawer");
  b.Add(drp,
        BoxLoHi(V3(-w / 2 + 0.03, py - dh / 2, d / 2 + kGap),
                V3(-w / 2 + 0.03 + dw, py + dh / 2, d / 2 + kGap + 0.015)),
        skin);
  b.Dynamics(drawer, 0.5, 0.5);
  int knobs = rng.I(1, 2);
  double x = w / 2 - 0.08;
  for (int k = 0; k < knobs; ++k, x -= 0.11)
    Knob(b, body, V3(x, py, d / 2), V3::UnitZ(), 0.035, 0.03, rng.P(0.5) ? 0 : 330, dark);
  double x0 = -w / 2 + 0.06 + dw, x1 = x + 0.03;
  int buttons = std::min(rng.I(3, 6), static_cast<int>((x1 - x0) / 0.022));
  double pitch = std::min(0.035, (x1 - x0) / std::max(1, buttons));
  for (int i = 0; i < buttons; ++i) {
    Button(b, body, V3(x0 + pitch * (i + 0.5), py, d / 2), V3::UnitZ(), V3::UnitX(),
           RoundRect(0.7 * pitch, 0.015, 0.003, 2), 0.005, 0.002, dark);
  }
}

void BuildCoffeeMachine(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? DarkPlastic(rng) : Plastic(rng);
  Material steel = Steel(rng);
  Material light = LightPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.2, 0.32), h = rng.U(0.3, 0.42), d = rng.U(0.25, 0.38);
  int bp = b.Part(body, "body");
  double tower_d = 0.45 * d;  // the back tower holds the tank and the head
  b.Add(bp, BoxLoHi(V3(-w / 2, 0, -d / 2), V3(w / 2, 0.03, d / 2)), skin);  // base
  b.Add(bp, BoxLoHi(V3(-w / 2, 0.03, -d / 2), V3(w / 2, h - 0.03, -d / 2 + tower_d)),
        skin);  // tower
  double head_y = h - 0.11;
  b.Add(bp, BoxLoHi(V3(-w / 2, head_y, -d / 2 + tower_d - 0.001), V3(w / 2, h - 0.03, d / 2)),
        skin);  // head
  // container: a carafe or drip tray sliding out of the front bay
  double bay_y0 = 0.03 + kGap, bay_y1 = head_y - kGap;
  double cz0 = -d / 2 + tower_d + kGap, cz1 = d / 2 - 0.01;
  double cw = std::min(0.6 * w, 0.16);
  int cont = b.Slider(body, "container", V3(0, bay_y0, cz1), V3::UnitZ(), 0, 0.8 * (cz1 - cz0));
  int cp = b.Part(cont, "container");
  b.Add(cp,
        Loft(RoundRect(1.0, 0.9 * (cz1 - cz0) / cw, 0.2, 4),
             {Ring{0.0, cw * 0.85}, Ring{0.8 * (bay_y1 - bay_y0), cw}},
             FrameZ(V3(0, bay_y0, 0.5 * (cz0 + cz1)), V3::UnitY(), V3::UnitX())),
        Glass().WithDensity(600));
  b.Add(cp,
        BoxLoHi(V3(cw / 2 - 0.01, bay_y0 + 0.03, 0.5 * (cz0 + cz1) - 0.015),
                V3(cw / 2 + 0.02, bay_y0 + 0.6 * (bay_y1 - bay_y0), 0.5 * (cz0 + cz1) + 0.015)),
        skin);
  b.Dynamics(cont, 0.5, 0.5);
  // tank lid on top of the tower, hinged at the back
  double top = h - 0.03;
  V3 lo(-w / 2 + 0.01, top + kGap, -d / 2 + 0.01),
      hi(w / 2 - 0.01, top + kGap + 0.02, -d / 2 + tower_d + 0.05);
  int lid =
      HingedPanel(b, body, "lid", "lid", lo, hi, V3::UnitY(), V3::UnitZ(), rng.U(80, 100), skin);
  b.Dynamics(lid, 0.05, 0.05);
  // buttons on the head front, a knob, a steam lever on the side
  double zf = d / 2;
  int buttons = rng.I(2, 5);
  double pitch = std::min(0.035, (w - 0.06) / buttons);
  for (int i = 0; i < buttons; ++i) {
    double x = -w / 2 + 0.03 + pitch * (i + 0.5);
    Button(b, body, V3(x, head_y + 0.04, zf), V3::UnitZ(), V3::UnitX(), Circle(0.35 * pitch, 16),
           0.005, 0.002, light);
  }
  if (rng.P(0.8))
    Knob(b, body, V3(w / 2 - 0.035, head_y + 0.04 + (buttons * pitch > w - 0.1 ? 0.035 : 0.0), zf),
         V3::UnitZ(), 0.016, 0.02, rng.P(0.5) ? 0 : 270, steel);
  if (rng.P(0.5)) {
    V3 pivot(w / 2 + kGap, head_y + 0.03, 0.0);
    int lever = b.Hinge(body, "lever", pivot, V3::UnitX(), 0, 60);
    b.RestOnLimit(lever);
    int lp = b.Part(lever, "lever");
    b.Add(lp, Cylinder(FrameZ(pivot, V3::UnitX()), 0.012, 0.0, 0.01, 16), steel);
    b.Add(lp,
          Bar(pivot + V3(0.01, 0, 0), pivot + V3(0.015, -0.05, 0.04), 0.015, 0.008, V3::UnitZ()),
          steel);
  }
  if (rng.P(0.4)) {
    // a second container: the bean hopper lid on top of the head
    V3 lo2(-w / 2 + 0.02, top + kGap, -d / 2 + tower_d + 0.05 + 0.015 + 3 * kGap),
        hi2(w / 2 - 0.02, top + kGap + 0.015, d / 2 - 0.02);
    int l2 = HingedPanel(b, body, "lid", "lid", lo2, hi2, V3::UnitY(), V3::UnitZ(), 90, skin);
    b.Dynamics(l2, 0.05, 0.05);
  }
}

void BuildToaster(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? Steel(rng).WithDensity(800) : Plastic(rng);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.25, 0.4), h = rng.U(0.17, 0.22), d = rng.U(0.14, 0.2);
  int bp = b.Part(body, "body");
  b.Add(bp, RoundedSlab(FrameZ(V3(0, 0, 0), V3::UnitY(), V3::UnitX()), w, d, h, 0.03, 0.01), skin);
  int slots = w > 0.33 ? 4 : 2;
  for (int i = 0; i < slots; ++i) {
    double z = (i - 0.5 * (slots - 1)) * std::min(0.04, d / (slots + 1));
    b.Add(bp, Box(V3(0, h - 0.0005, z), V3(w * 0.7, 0.0012, 0.012)), dark);
  }
  // lever(s) sliding down the front, browning knob, buttons
  int levers = slots == 4 && rng.P(0.5) ? 2 : 1;
  double zf = d / 2;
  for (int i = 0; i < levers; ++i) {
    double x = levers == 1 ? -w / 2 + 0.05 : (i == 0 ? -w / 2 + 0.05 : w / 2 - 0.05);
    // the lever rests at the bottom of its slot (pushed down) and lifts up
    V3 bottom(x, 0.045, zf + kGap);
    int lever = b.Slider(body, "slider", bottom, V3::UnitY(), 0, h - 0.09);
    b.AddPart(lever, "lever",
              BoxLoHi(V3(x - 0.02, 0.035, zf + kGap), V3(x + 0.02, 0.055, zf + kGap + 0.025)),
              dark);
    b.Dynamics(lever, 0.3, 0.2);
  }
  double xc = levers == 1 ? w / 2 - 0.05 : 0.0;
  Knob(b, body, V3(xc, 0.09, zf), V3::UnitZ(), 0.016, 0.015, 240, dark);
  int buttons = rng.I(1, 3);
  for (int i = 0; i < buttons; ++i) {
    Button(b, body, V3(xc, 0.058 - 0.018 * i, zf), V3::UnitZ(), V3::UnitX(),
           RoundRect(0.022, 0.012, 0.003, 2), 0.004, 0.002, dark);
  }
}

void BuildPrinter(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? LightPlastic(rng) : DarkPlastic(rng);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  double w = rng.U(0.38, 0.5), h = rng.U(0.15, 0.3), d = rng.U(0.3, 0.42);
  int bp = b.Part(body, "body");
  double tray_h = 0.04;
  // lower part with a paper cassette bay, upper part under the scanner lid
  Shell(b, bp, V3(-w / 2, 0, -d / 2), V3(w / 2, tray_h + 0.02, d / 2), 0.01, "Z", skin);
  b.Add(bp, BoxLoHi(V3(-w / 2, tray_h + 0.02, -d / 2), V3(w / 2, h, d / 2 - 0.03)),
        skin.WithDensity(400));
  double pw = 0.35 * w;
  b.Add(bp, BoxLoHi(V3(w / 2 - pw, tray_h + 0.02, d / 2 - 0.03 - 0.001), V3(w / 2, h, d / 2)),
        skin.WithDensity(400));
  // paper tray
  Drawer(b, body, V3(-w / 2 + 0.01 + kGap, 0.01 + kGap, -d / 2 + 0.01 + kGap),
         V3(w / 2 - 0.01 - kGap, tray_h + 0.01 - kGap, d / 2), -w / 2, w / 2, 0.0,
         tray_h + 0.02 - kGap / 2, d / 2 + kGap, 0.01, 0.7 * d, HandleStyle::kEdge, skin, dark,
         "drawer");
  // output flap on the front of the upper part, hinged at its bottom
  V3 flo(-w / 2 + 0.02, tray_h + 0.03, d / 2 - 0.03 + kGap),
      fhi(w / 2 - pw - kGap, h - 0.03, d / 2 - 0.03 + kGap + 0.01);
  int flap = b.Hinge(body, "lid", V3(0, flo.y(), fhi.z()), V3::UnitX(), 0, 90);
  b.AddPart(flap, "flap", BoxLoHi(flo, fhi), skin);
  b.Dynamics(flap, 0.05, 0.02);
  // scanner lid
  V3 llo(-w / 2, h + kGap, -d / 2), lhi(w / 2, h + kGap + 0.025, d / 2);
  int lid =
      HingedPanel(b, body, "lid", "lid", llo, lhi, V3::UnitY(), V3::UnitZ(), rng.U(70, 90), skin);
  b.Dynamics(lid, 0.2, 0.1);
  // buttons on the side panel's front
  int buttons = rng.I(6, 12);
  int cols = 3;
  double pitch = std::min(0.03, (pw - 0.02) / cols);
  for (int i = 0; i < buttons; ++i) {
    int r = i / cols, c = i % cols;
    double y = h - 0.03 - r * pitch;
    if (y < tray_h + 0.04) break;
    Button(b, body, V3(w / 2 - pw + 0.01 + pitch * (c + 0.5), y, d / 2), V3::UnitZ(), V3::UnitX(),
           RoundRect(0.7 * pitch, 0.7 * pitch, 0.003, 2), 0.004, 0.002, dark);
  }
}

void BuildFan(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? LightPlastic(rng) : Plastic(rng);
  Material metal = Steel(rng);
  int body = b.Fixed(-1, "heavy", "frame");
  int fp = b.Part(body, "frame");
  int blades = rng.I(3, 6);
  if (rng.P(0.35)) {
    // ceiling fan: canopy, downrod, motor; rotor about y
    double y_top = rng.U(0.5, 0.9);
    double motor_y = y_top - rng.U(0.2, 0.5);
    b.Add(fp, Frustum(FrameZ(V3(0, y_top - 0.06, 0), V3::UnitY()), 0.04, 0.07, 0.0, 0.06, 24),
          skin);
    b.Add(fp,
          Cylinder(FrameZ(V3(0, motor_y, 0), V3::UnitY()), 0.012, 0.0,
                   y_top - 0.06 - motor_y + 0.001, 12),
          metal);
    b.Add(fp, Cylinder(FrameZ(V3(0, motor_y - 0.005, 0), V3::UnitY()), 0.09, 0.0, 0.03, 32), skin);
    int rotor = b.Continuous(body, "rotor", V3(0, motor_y - 0.005 - kGap, 0), V3::UnitY());
    int rp = b.Part(rotor, "rotor");
    double hub_y1 = motor_y - 0.005 - kGap;
    b.Add(rp,
          Loft(Circle(1.0, 32),
               {Ring{hub_y1 - 0.08, 0.04}, Ring{hub_y1 - 0.05, 0.1}, Ring{hub_y1, 0.1}},
               FrameZ(V3::Zero(), V3::UnitY())),
          skin);
    double len = rng.U(0.45, 0.65);
    for (int i = 0; i < blades; ++i) {
      double a = 2 * kPi * i / blades;
      V3 dir(std::cos(a), 0, std::sin(a));
      Frame f = FrameZ(V3(0, hub_y1 - 0.03, 0) + dir * (0.09 + len / 2), dir, V3::UnitY());
      b.Add(rp,
            Box(Frame{f.o, f.r * Eigen::AngleAxisd(0.2, V3::UnitZ()).toRotationMatrix()},
                V3(0.008, 0.12, len)),
            Wood(rng));
    }
    b.Dynamics(rotor, 0.05, 0.02);
  } else {
    // desk or pedestal fan: base, pole, motor, guard; rotor about z
    double pole = rng.P(0.5) ? rng.U(0.6, 1.0) : rng.U(0.1, 0.2);
    double r = rng.U(0.12, 0.22);
    b.Add(fp, Cylinder(FrameZ(V3::Zero(), V3::UnitY()), rng.U(0.12, 0.18), 0.0, 0.03, 32), skin);
    double cy = 0.03 + pole + r;
    b.Add(fp,
          Cylinder(FrameZ(V3(0, 0.03, -0.05), V3::UnitY()), 0.015, -0.001, cy - 0.03 - 0.05, 16),
          metal);
    b.Add(fp,
          Loft(Circle(1.0, 24), {Ring{-0.2, 0.05}, Ring{-0.12, 0.07}, Ring{-0.02, 0.07}},
               FrameZ(V3(0, cy, 0), V3::UnitZ())),
          skin);
    // rotor: hub and blades in front of the motor
    int rotor = b.Continuous(body, "rotor", V3(0, cy, -0.02 + kGap), V3::UnitZ());
    int rp = b.Part(rotor, "rotor");
    double z0 = -0.02 + kGap;
    b.Add(rp,
          Loft(Circle(1.0, 24), {Ring{z0, 0.04}, Ring{z0 + 0.03, 0.04}, Ring{z0 + 0.045, 0.025}},
               FrameZ(V3(0, cy, 0), V3::UnitZ())),
          skin);
    const double pitch_angle = 0.25;
    double bz = z0 + 0.03 + 0.45 * r * std::sin(pitch_angle) + 0.003;  // blade centre plane
    for (int i = 0; i < blades; ++i) {
      double a = 2 * kPi * i / blades;
      V3 dir(std::cos(a), std::sin(a), 0);
      V3 side = V3::UnitZ().cross(dir);
      Frame f;
      f.o = V3(0, cy, bz) + dir * (0.035 + (r - 0.05) / 2);
      f.r.col(0) = dir;
      f.r.col(1) =
          (side * std::cos(pitch_angle) + V3::UnitZ() * std::sin(pitch_angle)).normalized();
      f.r.col(2) = f.r.col(0).cross(f.r.col(1));
      b.Add(rp, Prism(Ellipse((r - 0.05) / 2, 0.45 * r, 20), f, -0.002, 0.002), Plastic(rng));
    }
    b.Dynamics(rotor, 0.02, 0.005);
    // guard: a front ring, a back ring and spokes, clear of the blades
    int gp = b.Part(body, "guard");
    double gr = r + 0.02;
    double gz = bz + 0.45 * r * std::sin(pitch_angle) + 0.012;  // front plane of the guard
    Annulus(b, gp, FrameZ(V3(0, cy, gz - 0.003), V3::UnitZ()), gr - 0.008, gr, 0.0, 0.006, 16,
            metal);
    Annulus(b, gp, FrameZ(V3(0, cy, -0.03), V3::UnitZ()), gr - 0.008, gr, 0.0, 0.006, 16, metal);
    for (int i = 0; i < 12; ++i) {
      double a = 2 * kPi * i / 12;
      V3 dir(std::cos(a), std::sin(a), 0);
      b.Add(
          gp,
          Rod(V3(0, cy, -0.025) + dir * (gr - 0.004), V3(0, cy, gz) + dir * (gr - 0.004), 0.002, 6),
          metal);
      b.Add(gp,
            Rod(V3(0, cy, gz + 0.002) + dir * (gr - 0.006), V3(0, cy, gz + 0.002) + dir * 0.05,
                0.0015, 6),
            metal);
      if (i % 4 == 0)
        b.Add(gp,
              Rod(V3(0, cy, -0.027) + dir * 0.06, V3(0, cy, -0.027) + dir * (gr - 0.004), 0.002, 6),
              metal);
    }
    b.Add(gp, Cylinder(FrameZ(V3(0, cy, gz), V3::UnitZ()), 0.05, 0.0, 0.006, 24), skin);
    if (rng.P(0.15))
      Button(b, body, V3(0, 0.03, 0.08), V3::UnitY(), V3::UnitX(), RoundRect(0.03, 0.02, 0.004, 2),
             0.006, 0.003, DarkPlastic(rng));
  }
}

void BuildLamp(ObjectBuilder& b, Rng& rng) {
  Material metal = rng.P(0.5) ? Steel(rng) : Paint(rng);
  Material shade = rng.P(0.5) ? Paint(rng).WithDensity(2000) : Plastic(rng);
  int body = b.Fixed(-1, "heavy", "base");
  int bp = b.Part(body, "base");
  double br = rng.U(0.08, 0.13);
  b.Add(bp,
        Loft(Circle(1.0, 32), {Ring{0.0, br}, Ring{0.02, br}, Ring{0.03, 0.8 * br}},
             FrameZ(V3::Zero(), V3::UnitY())),
        metal.WithDensity(7800));
  double post_h = rng.U(0.04, 0.1);
  double aw = 0.014;  // arm width along x
  b.Add(bp, Box(V3(0, 0.03 + post_h / 2, 0), V3(aw, post_h + 0.002, 0.03)), metal);
  // chain of arms, each in its own slab along x so that they pass each other; the first leans
  // back, the second reaches forward
  int n_arms = rng.P(0.67) ? 2 : 1;
  int parent = body;
  V3 pivot(0, 0.03 + post_h, 0);
  double x = aw / 2 + kGap;
  for (int i = 0; i < n_arms; ++i) {
    // direction angle from -z towards +y
    double angle = i == 0 ? rng.U(55, 80) * kPi / 180 : kPi - rng.U(10, 35) * kPi / 180;
    double len = rng.U(0.25, 0.4);
    // the arms rest against a stop: the range goes one way or the other (Finalize picks the
    // side gravity pushes into); the first arm stays above 25 degrees, the second above 190
    double span = i == 0 ? std::min(45.0, angle * 180 / kPi - 25) : 20;
    int arm = b.Hinge(parent, "rotation_bar", pivot + V3(x, 0, 0), V3::UnitX(), 0, span);
    b.RestOnLimit(arm);
    b.Dynamics(arm, 0.5, 0.1);
    V3 dir(0, std::sin(angle), -std::cos(angle));
    V3 end = pivot + dir * len;
    int ap = b.Part(arm, "bar");
    b.Add(ap,
          Bar(pivot + V3(x + aw / 2, 0, 0) - 0.012 * dir, end + V3(x + aw / 2, 0, 0) + 0.012 * dir,
              0.02, aw, V3::UnitX().cross(dir)),
          metal);
    parent = arm;
    pivot = end;
    x += aw + kGap;
  }
  // head: a shade beside the last arm, turning about x at the arm's end
  int head = b.Hinge(parent, "head", pivot + V3(x, 0, 0), V3::UnitX(), 0, 60);
  b.RestOnLimit(head);
  b.Dynamics(head, 0.3, 0.05);
  int hp = b.Part(head, "head");
  double sr = rng.U(0.06, 0.1);
  b.Add(hp, Box(pivot + V3(x + 0.01, 0, 0), V3(0.02, 0.025, 0.025)), metal);
  V3 sc = pivot + V3(x + 0.02 + sr + 0.005, 0, 0);
  Frame sf = FrameZ(sc, -V3::UnitY());
  b.Add(hp, Frustum(sf, 0.35 * sr, sr, -0.02, 0.6 * sr, 32), shade);
  b.Add(hp, Rod(pivot + V3(x + 0.01, 0, 0), sc + V3(-0.3 * sr, 0, 0), 0.006), metal);
}

void BuildDisplay(ObjectBuilder& b, Rng& rng) {
  Material dark = DarkPlastic(rng);
  Material skin = rng.P(0.7) ? dark : LightPlastic(rng);
  int body = b.Fixed(-1, "heavy", "base");
  int bp = b.Part(body, "base");
  double sw = rng.U(0.45, 0.7), sh = sw * rng.U(0.56, 0.65), st = rng.U(0.02, 0.05);
  double bw = rng.U(0.18, 0.28), bd = rng.U(0.15, 0.22);
  b.Add(bp, RoundedSlab(FrameZ(V3(0, 0, 0), V3::UnitY(), V3::UnitX()), bw, bd, 0.015, 0.03, 0.004),
        skin);
  double nt = 0.03;
  double axis_y = rng.U(0.08, 0.14) + sh / 2, axis_z = -0.04;
  double hub_r = 0.02;
  b.Add(
      bp,
      BoxLoHi(V3(-0.03, 0.014, axis_z - nt / 2), V3(0.03, axis_y - hub_r - kGap, axis_z + nt / 2)),
      skin);
  // screen: hub on the axis, bracket, panel; tilts about x
  int screen = b.Hinge(body, "rotation_screen", V3(0, axis_y, axis_z), -V3::UnitX(), 0, 25);
  b.RestOnLimit(screen);
  b.Dynamics(screen, 1.0, 0.2);
  int sp = b.Part(screen, "screen");
  b.Add(sp, Cylinder(FrameZ(V3(-0.03, axis_y, axis_z), V3::UnitX()), hub_r, 0.0, 0.06, 24), skin);
  double back = axis_z + nt / 2 + 0.03;
  b.Add(sp, BoxLoHi(V3(-0.025, axis_y - 0.015, axis_z), V3(0.025, axis_y + 0.015, back + 0.001)),
        skin);
  b.Add(sp,
        RoundedSlab(FrameZ(V3(0, axis_y + 0.02, back), V3::UnitZ(), V3::UnitX()), sw, sh, st, 0.01,
                    0.003),
        skin);
  b.AddPart(screen, "glass",
            BoxLoHi(V3(-sw / 2 + 0.015, axis_y + 0.02 - sh / 2 + 0.015, back + st - 0.001),
                    V3(sw / 2 - 0.015, axis_y + 0.02 + sh / 2 - 0.025, back + st + 0.0005)),
            Material{"screen", V3(0.03, 0.03, 0.04), 2500});
  if (rng.P(0.25)) {
    for (int i = 0; i < 2; ++i) {
      V3 c(sw / 2 - 0.03 - 0.025 * i, axis_y + 0.02 - sh / 2, back + st / 2);
      Button(b, screen, c, -V3::UnitY(), V3::UnitX(), RoundRect(0.015, 0.008, 0.002, 2), 0.003,
             0.0015, dark);
    }
  }
}

void BuildKettle(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? Steel(rng).WithDensity(900) : Plastic(rng).WithDensity(600);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  int bp = b.Part(body, "body");
  double r = rng.U(0.07, 0.1), h = rng.U(0.16, 0.24);
  Frame fy = FrameZ(V3::Zero(), V3::UnitY());
  double rt = r * rng.U(0.7, 0.85);  // top opening
  b.Add(bp,
        Loft(Circle(1.0, 40), {Ring{0.0, 0.95 * r}, Ring{0.01, r}, Ring{0.6 * h, r}, Ring{h, rt}},
             fy),
        skin);
  // spout at the front
  b.Add(bp,
        Frustum(FrameZ(V3(0, 0.45 * h, 0.6 * r), V3(0, 0.7, 1)), 0.025, 0.012, 0.0, 0.8 * r, 16),
        skin);
  bool jug = rng.P(0.6);
  double lr = rt - 0.01;
  if (jug) {
    // side handle at the back, lid hinged towards it
    double zb = -r - 0.03;
    Polyline(b, b.Part(body, "handle"),
             {V3(0, 0.15 * h, -0.9 * r), V3(0, 0.2 * h, zb), V3(0, 0.8 * h, zb),
              V3(0, h - 0.03, -(rt + 0.3 * (r - rt)) - 0.005)},
             0.012, dark);
    int lid = b.Hinge(body, "lid", V3(0, h + kGap, -lr), -V3::UnitX(), 0, rng.U(70, 90));
    b.AddPart(lid, "lid",
              Loft(Circle(1.0, 32), {Ring{0.0, lr}, Ring{0.01, lr}, Ring{0.018, 0.7 * lr}},
                   FrameZ(V3(0, h + kGap, 0), V3::UnitY())),
              skin);
    b.Dynamics(lid, 0.02, 0.01);
    if (rng.P(0.5)) {
      // power switch at the handle's foot
      // power switch at the handle's foot: a button pushed into the handle (along +z)
      Button(b, body, V3(0, 0.22 * h, zb - 0.012), -V3::UnitZ(), V3::UnitX(),
             RoundRect(0.014, 0.01, 0.003, 2), 0.006, 0.002, dark);
    }
  } else {
    // stove kettle: arch handle above, lid lifts off
    double hh = rng.U(0.09, 0.13);
    double ar = std::max(0.75 * rt, 0.5 * rt + 0.028);  // arch radius
    Polyline(b, b.Part(body, "handle"), Arc(V3(0, h, 0), V3::UnitX(), V3::UnitY(), ar, 0.0, kPi, 8),
             0.008, dark);
    b.Add(bp, Box(V3(ar, h - 0.01, 0), V3(0.02, 0.03, 0.02)), skin);
    b.Add(bp, Box(V3(-ar, h - 0.01, 0), V3(0.02, 0.03, 0.02)), skin);
    (void)hh;
    double travel =
        std::max(0.003, std::min(ar - 0.053, std::sqrt(ar * ar - 0.25 * rt * rt) - 0.035));
    int lid = b.Slider(body, "lid", V3(0, h + kGap, 0), V3::UnitY(), 0, travel);
    int lp = b.Part(lid, "lid");
    b.Add(
        lp,
        Loft(Circle(1.0, 32), {Ring{0.0, 0.5 * rt}, Ring{0.008, 0.5 * rt}, Ring{0.015, 0.32 * rt}},
             FrameZ(V3(0, h + kGap, 0), V3::UnitY())),
        skin);
    b.Add(lp, Sphere(V3(0, h + kGap + 0.022, 0), 0.01, 6, 12), dark);
  }
}

void BuildKitchenPot(ObjectBuilder& b, Rng& rng) {
  Material metal = rng.P(0.7) ? Steel(rng) : Aluminium(rng);
  Material dark = DarkPlastic(rng);
  int body = b.Fixed(-1, "heavy", "body");
  int bp = b.Part(body, "body");
  double r = rng.U(0.08, 0.15), h = rng.U(0.08, 0.2), wt = 0.004;
  Frame fy = FrameZ(V3::Zero(), V3::UnitY());
  b.Add(bp, Cylinder(fy, r, 0.0, 0.006, 48), metal);
  Annulus(b, bp, fy, r - wt, r, 0.0, h, 16, metal);
  // side handles
  for (int s : {-1, 1})
    b.Add(bp, Box(V3(s * (r + 0.025), 0.8 * h, 0), V3(0.05, 0.012, 0.05)), dark);
  // lid resting on the rim, lifted straight up
  int lid = b.Slider(body, "lid", V3(0, h + kGap, 0), V3::UnitY(), 0, rng.U(0.08, 0.15));
  int lp = b.Part(lid, "lid");
  b.Add(lp,
        Loft(Circle(1.0, 40),
             {Ring{0.0, r + 0.004}, Ring{0.004, r + 0.004}, Ring{0.012 + 0.05 * r, 0.5 * r}},
             FrameZ(V3(0, h + kGap, 0), V3::UnitY())),
        rng.P(0.5) ? Glass() : metal);
  double top = h + kGap + 0.012 + 0.05 * r;
  b.Add(lp, Cylinder(FrameZ(V3(0, top - 0.002, 0), V3::UnitY()), 0.008, 0.0, 0.015, 12), dark);
  b.Add(lp,
        Loft(Circle(1.0, 20), {Ring{0.0, 0.02}, Ring{0.01, 0.022}, Ring{0.014, 0.018}},
             FrameZ(V3(0, top + 0.012, 0), V3::UnitY())),
        dark);
  b.Dynamics(lid, 0.1, 0.1);
}

void BuildDispenser(ObjectBuilder& b, Rng& rng) {
  Material skin = rng.P(0.5) ? Plastic(rng) : LightPlastic(rng);
  Material dark = rng.P(0.5) ? DarkPlastic(rng) : Steel(rng).WithDensity(2000);
  int body = b.Fixed(-1, "heavy", "body");
  int bp = b.Part(body, "body");
  double r = rng.U(0.03, 0.05), h = rng.U(0.1, 0.18);
  Frame fy = FrameZ(V3::Zero(), V3::UnitY());
  bool square = rng.P(0.4);
  std::vector<V2> poly = square ? RoundRect(2.0, 1.4, 0.4, 4) : Circle(1.0, 40);
  b.Add(bp, Loft(poly, {Ring{0.0, r}, Ring{0.8 * h, r}, Ring{h, 0.55 * r}}, fy),
        skin.WithDensity(700));
  b.Add(bp, Cylinder(fy, 0.4 * r, h - 0.001, h + 0.015, 24), skin);
  double y0 = h + 0.015;
  // screw collar (turns), then the pump head (pressed down, turns to lock)
  int parent = body;
  if (rng.P(0.84)) {
    int collar = b.Continuous(body, "lid", V3(0, y0 + kGap, 0), V3::UnitY());
    b.AddPart(collar, "collar",
              Cylinder(FrameZ(V3(0, y0 + kGap, 0), V3::UnitY()), 0.45 * r, 0.0, 0.015, 24), dark);
    b.Dynamics(collar, 0.05, 0.01);
    y0 += kGap + 0.015;
  }
  // the pump head rests locked down and lifts (and turns) to unlock
  double travel = 0.012;
  int pump = b.ScrewSlider(parent, "pump", V3(0, y0 + kGap, 0), V3::UnitY(), 0, travel);
  int pp = b.Part(pump, "pump_head");
  double py = y0 + kGap;
  b.Add(pp, Cylinder(FrameZ(V3(0, py, 0), V3::UnitY()), 0.006, 0.0, 0.03, 12), dark);
  b.Add(pp,
        Loft(RoundRect(1.0, 0.6, 0.2, 3), {Ring{0.0, 0.04}, Ring{0.02, 0.04}, Ring{0.026, 0.034}},
             FrameZ(V3(0, py + 0.03, 0), V3::UnitY(), V3::UnitX())),
        dark);
  b.Add(pp, Rod(V3(0.015, py + 0.04, 0), V3(0.055, py + 0.038, 0), 0.005, 12), dark);
  b.Dynamics(pump, 0.5, 0.1);
}

void BuildFaucet(ObjectBuilder& b, Rng& rng) {
  Material chrome = Steel(rng);
  chrome.kd = V3(0.8, 0.81, 0.83);
  int body = b.Fixed(-1, "heavy", "base");
  int bp = b.Part(body, "base");
  Frame fy = FrameZ(V3::Zero(), V3::UnitY());
  if (rng.P(0.7)) {
    // single-lever mixer: column, swivel spout collar, lever cartridge on top
    double rc = rng.U(0.022, 0.03), y1 = rng.U(0.08, 0.2);
    b.Add(bp, Cylinder(fy, rc + 0.01, 0.0, 0.01, 32), chrome);
    b.Add(bp, Cylinder(fy, rc, 0.009, y1, 32), chrome);
    bool swivel = rng.P(0.6);
    int spout = body;
    double cy0 = y1 + (swivel ? kGap : 0.0), hc = 0.05;
    if (swivel) {
      spout = b.Hinge(body, "spout", V3(0, cy0, 0), V3::UnitY(), -60, 60);
      b.Dynamics(spout, 0.3, 0.05);
    }
    int sp = b.Part(spout, "spout");
    b.Add(sp, Cylinder(FrameZ(V3(0, cy0, 0), V3::UnitY()), rc, 0.0, hc, 32), chrome);
    double reach = rng.U(0.12, 0.22);
    if (rng.P(0.5)) {
      // gooseneck
      double z0 = rc + 0.03;
      std::vector<V3> pts = Arc(V3(0, cy0 + hc / 2, z0 + reach / 2), V3(0, 0, -1), V3::UnitY(),
                                reach / 2, 0.0, kPi, 8);
      pts.push_back(pts.back() - V3(0, 0.04, 0));
      b.Add(sp, Rod(V3(0, cy0 + hc / 2, 0), V3(0, cy0 + hc / 2, z0), 0.011), chrome);
      Polyline(b, sp, pts, 0.011, chrome);
    } else {
      b.Add(sp, Rod(V3(0, cy0 + 0.02, 0), V3(0, cy0 + 0.03, reach), 0.014), chrome);
      b.Add(sp, Rod(V3(0, cy0 + 0.03, reach), V3(0, cy0 + 0.005, reach + 0.01), 0.014), chrome);
    }
    // lever on top
    double ly = cy0 + hc + (swivel ? kGap : kGap);
    int lever = b.Hinge(spout, "switch", V3(0, ly, 0.6 * rc), V3::UnitX(), 0, 30);
    int lp = b.Part(lever, "switch");
    b.Add(lp, Cylinder(FrameZ(V3(0, ly, 0), V3::UnitY()), 0.6 * rc, 0.0, 0.025, 24), chrome);
    b.Add(
        lp,
        Bar(V3(0, ly + 0.02, 0), V3(0, ly + 0.028, -rng.U(0.07, 0.11)), 0.016, 0.008, V3::UnitX()),
        chrome);
    b.Dynamics(lever, 0.05, 0.01);
    // the lever's hanging side must clear the spout's gooseneck: the lever points back, the
    // spout forward
  } else {
    // two-handle faucet on a deck plate
    double span = rng.U(0.09, 0.12);
    b.Add(bp,
          RoundedSlab(FrameZ(V3::Zero(), V3::UnitY(), V3::UnitX()), 2 * span + 0.08, 0.06, 0.02,
                      0.02, 0.005),
          chrome);
    bool swivel = rng.P(0.3);
    int spout = body;
    double y1 = 0.02 + 0.04;
    b.Add(bp, Cylinder(fy, 0.02, 0.019, y1, 24), chrome);
    if (swivel) {
      spout = b.Hinge(body, "spout", V3(0, y1 + kGap, 0), V3::UnitY(), -45, 45);
      b.Dynamics(spout, 0.2, 0.05);
    }
    double sy = y1 + (swivel ? kGap : 0.0);
    int sp = b.Part(spout, "spout");
    b.Add(sp, Cylinder(FrameZ(V3(0, sy, 0), V3::UnitY()), 0.02, 0.0, 0.03, 24), chrome);
    b.Add(sp, Rod(V3(0, sy + 0.02, 0), V3(0, sy + 0.03, 0.15), 0.013), chrome);
    for (int s : {-1, 1}) {
      V3 c(s * span, 0.02, 0);
      b.Add(bp, Cylinder(FrameZ(c, V3::UnitY()), 0.018, -0.001, 0.02, 24), chrome);
      int handle = b.Hinge(body, "switch", c + V3(0, 0.02 + kGap, 0), s * V3::UnitY(), 0, 90);
      int hp = b.Part(handle, "switch");
      V3 hc = c + V3(0, 0.02 + kGap, 0);
      b.Add(hp, Cylinder(FrameZ(hc, V3::UnitY()), 0.015, 0.0, 0.03, 20), chrome);
      if (rng.P(0.5)) {
        b.Add(hp, Bar(hc + V3(0, 0.03, 0.0), hc + V3(0, 0.035, 0.05), 0.014, 0.008, V3::UnitX()),
              chrome);
      } else {
        for (int k = 0; k < 2; ++k) {
          V3 d = k == 0 ? V3(1, 0, 0) : V3(0, 0, 1);
          b.Add(hp, Rod(hc + V3(0, 0.025, 0) - 0.045 * d, hc + V3(0, 0.025, 0) + 0.045 * d, 0.006),
                chrome);
        }
      }
      b.Dynamics(handle, 0.1, 0.01);
    }
  }
}

}  // namespace partsim::internal::gen
