// `partsim vision show`'s pictures: on datasets generated from a cabinet, every mask tinted
// toward its colour and outlined, every other pixel the dataset's RGB, the labels by their
// masks, the motion axis where K projects it; and the errors.
#include "partsim/vision/show.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "error_of.h"
#include "partsim/assets/generator.h"
#include "partsim/core/error.h"
#include "partsim/render/image_io.h"
#include "partsim/render/image_read.h"
#include "partsim/vision/coco.h"
#include "partsim/vision/coco_dataset.h"
#include "partsim/vision/dataset.h"

namespace partsim::vision {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Color = std::array<std::uint8_t, 3>;

// Removes this process's folders when it ends.
struct RemoveTempFolders {
  ~RemoveTempFolders() {
    const std::string prefix = "partsim_show_test_" + std::to_string(::getpid()) + "_";
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fs::temp_directory_path(), ec))
      if (e.path().filename().string().rfind(prefix, 0) == 0) fs::remove_all(e.path(), ec);
  }
} remove_temp_folders;

// A fresh folder of this process (ctest runs the tests of this file in parallel processes).
std::string Temp(const std::string& name) {
  const std::string dir =
      (fs::temp_directory_path() / ("partsim_show_test_" + std::to_string(::getpid()) + "_" + name))
          .string();
  fs::remove_all(dir);
  return dir;
}

// A generated tree of two cabinets, one with drawers, one with doors,, rendered into a dataset of
// `kind`, every object in the training split.
std::string MakeDataset(DatasetKind kind) {
  static const std::string tree = [] {
    const std::string dir = Temp("tree");
    for (int i : {0, 2}) {  // drawers, doors
      const GeneratedObject o = GenerateObject("StorageFurniture", i, 3);
      WriteObject(o, dir + "/" + o.anno_id);
    }
    return dir;
  }();
  DatasetOptions o;
  o.dataset_root = tree;
  o.out = Temp(kind == DatasetKind::kDetection ? "detection" : "motion");
  o.kind = kind;
  o.views = 2;
  o.size = 128;
  o.seed = 7;
  o.split = 1.0;
  o.point_clouds = false;
  o.progress = false;
  const DatasetSummary s = GenerateDataset(o);
  EXPECT_EQ(s.failed, 0) << (s.errors.empty() ? "" : s.errors.front());
  return o.out;
}

const std::string& DetectionDataset() {
  static const std::string dir = MakeDataset(DatasetKind::kDetection);
  return dir;
}

const std::string& MotionDataset() {
  static const std::string dir = MakeDataset(DatasetKind::kMotion);
  return dir;
}

std::vector<std::uint8_t> ReadRgb(const std::string& path, int width, int height) {
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgb = ReadPng(path, 3, &w, &h);
  EXPECT_EQ(w, width);
  EXPECT_EQ(h, height);
  return rgb;
}

Color At(const std::vector<std::uint8_t>& rgb, int width, int x, int y) {
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
  return {rgb[i], rgb[i + 1], rgb[i + 2]};
}

// whether a pixel within `d` pixels (any direction) of (x, y) is inside the picture and outside
// the mask
bool NearEdge(const Mask& m, int x, int y, int d) {
  for (int dy = -d; dy <= d; ++dy)
    for (int dx = -d; dx <= d; ++dx) {
      const int px = x + dx, py = y + dy;
      if (px >= 0 && py >= 0 && px < m.width && py < m.height && !m(px, py)) return true;
    }
  return false;
}

// whether (x, y) lies in the label box of an instance or in the caption box
bool InAnyBox(const ShownImage& s, int x, int y) {
  if (s.caption_box.Contains(x, y)) return true;
  for (const ShownInstance& i : s.instances)
    if (i.label_box.Contains(x, y)) return true;
  return false;
}

// Checks one mask on a shown picture against the plain RGB: its outline (a 4-neighbour outside
// the mask) in full colour, its inside (nothing outside within 3 pixels) the rounded half-way
// blend, moved toward the colour; label and caption boxes and `skip` pixels left out. Returns
// the number of inside pixels checked.
template <typename Skip>
int CheckMask(const ShownImage& s, const std::vector<std::uint8_t>& plain, const Mask& mask,
              const Color& c, const Skip& skip) {
  int inside = 0;
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      if (!mask(x, y) || InAnyBox(s, x, y) || skip(x, y)) continue;
      const Color got = At(s.rgb, s.width, x, y), was = At(plain, s.width, x, y);
      const bool outline = (x > 0 && !mask(x - 1, y)) || (x + 1 < mask.width && !mask(x + 1, y)) ||
                           (y > 0 && !mask(x, y - 1)) || (y + 1 < mask.height && !mask(x, y + 1));
      if (outline) EXPECT_EQ(got, c) << "outline pixel " << x << ", " << y;
      if (NearEdge(mask, x, y, 3)) continue;
      ++inside;
      int closer = 0, moved = 0;
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(got[k], (was[k] + c[k] + 1) / 2) << x << ", " << y << " channel " << k;
        EXPECT_LE(std::abs(got[k] - c[k]), std::abs(was[k] - c[k]));
        closer += std::abs(got[k] - c[k]);
        moved += std::abs(was[k] - c[k]);
      }
      if (was != c) EXPECT_LT(closer, moved) << x << ", " << y;
    }
  }
  return inside;
}

// Checks a label box: inside the picture, by the mask's box (touching it or within its own
// height above it), holding the dark background and text in the instance's colour, some of
// each (and where another label or the caption covers it, their colours).
void CheckLabelBox(const ShownImage& s, const ShownInstance& i) {
  const PixelBox& b = i.label_box;
  ASSERT_GT(b.w, 0);
  ASSERT_GT(b.h, 0);
  EXPECT_GE(b.x, 0);
  EXPECT_GE(b.y, 0);
  EXPECT_LE(b.x + b.w, s.width);
  EXPECT_LE(b.y + b.h, s.height);
  const double bx = i.bbox[0], by = i.bbox[1], bw = i.bbox[2], bh = i.bbox[3];
  EXPECT_LT(b.x, bx + bw + 1) << i.label;
  EXPECT_GT(b.x + b.w, bx - b.w) << i.label;
  EXPECT_LE(b.y, by + bh) << i.label;
  EXPECT_GE(b.y + b.h, by - 1) << i.label;
  int dark = 0, text = 0;
  for (int y = b.y; y < b.y + b.h; ++y)
    for (int x = b.x; x < b.x + b.w; ++x) {
      const Color c = At(s.rgb, s.width, x, y);
      bool other = s.caption_box.Contains(x, y) && c == Color{255, 255, 255};
      for (const ShownInstance& j : s.instances)
        other = other || (j.label_box.Contains(x, y) && c == j.color);
      if (c == kShowBoxColor) {
        ++dark;
      } else if (c == i.color) {
        ++text;
      } else if (!other) {
        ADD_FAILURE() << "label box pixel " << x << ", " << y << " is neither background nor text";
        return;
      }
    }
  EXPECT_GT(dark, 0);
  EXPECT_GT(text, 0) << "no text in the label box of " << i.label;
}

TEST(ShowTest, DetectionMasksAreTintedLabelledAndTheRestIsTheRgb) {
  const std::string dir = DetectionDataset();
  const CocoDataset d = LoadCocoDataset(dir + "/instances_train.json");
  ASSERT_EQ(d.images.size(), 4u);
  std::map<std::int64_t, std::string> names;
  for (const CocoCategory& c : d.categories) names[c.id] = c.name;
  int annotations = 0, inside = 0;
  for (std::size_t k = 0; k < d.images.size(); ++k) {
    ShowOptions o;
    o.dir = dir;
    o.index = static_cast<long long>(k);
    const ShownImage s = ShowDatasetImage(o);
    EXPECT_EQ(s.kind, DatasetKind::kDetection);  // from the split files
    EXPECT_EQ(s.rgb_file, d.images[k].file_name);
    ASSERT_EQ(s.width, 128);
    ASSERT_EQ(s.rgb.size(), 128u * 128u * 3u);
    const std::vector<std::uint8_t> plain = ReadRgb(dir + "/" + s.rgb_file, 128, 128);
    // the image's annotations, in file order, are the instances drawn
    std::vector<const CocoAnnotation*> mine;
    for (const CocoAnnotation& a : d.annotations)
      if (a.image_id == d.images[k].id) mine.push_back(&a);
    ASSERT_EQ(s.instances.size(), mine.size());
    Mask any(128, 128, 0);
    for (std::size_t i = 0; i < mine.size(); ++i) {
      const ShownInstance& inst = s.instances[i];
      const std::string& name = names.at(mine[i]->category_id);
      EXPECT_EQ(inst.label, name.substr(name.find('/') + 1));
      EXPECT_EQ(inst.color, ShowInstanceColor(static_cast<int>(i)));
      for (int c = 0; c < 4; ++c) EXPECT_EQ(inst.bbox[c], mine[i]->bbox[c]);
      const Mask mask = DecodeRle(mine[i]->segmentation);
      for (std::size_t p = 0; p < mask.data.size(); ++p) any.data[p] |= mask.data[p];
      inside += CheckMask(s, plain, mask, inst.color, [](int, int) { return false; });
      CheckLabelBox(s, inst);
      ++annotations;
    }
    // everything else is the RGB, exactly
    for (int y = 0; y < 128; ++y)
      for (int x = 0; x < 128; ++x)
        if (!any(x, y) && !InAnyBox(s, x, y))
          ASSERT_EQ(At(s.rgb, 128, x, y), At(plain, 128, x, y)) << x << ", " << y;
  }
  EXPECT_GT(annotations, 0);
  EXPECT_GT(inside, 100);  // mask pixels away from their outlines
}

// distance from pixel centre p to the segment a-b
double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double t =
      d.squaredNorm() > 0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p - (a + t * d)).norm();
}

TEST(ShowTest, MotionSamplesShowTheMaskTheProjectedAxisAndThePivot) {
  const std::string dir = MotionDataset();
  std::ifstream f(dir + "/motion_train.json");
  std::stringstream text;
  text << f.rdbuf();
  const json doc = json::parse(text.str());
  const json& samples = doc.at("samples");
  ASSERT_GT(samples.size(), 0u);
  int hinges = 0, sliders = 0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const json& smp = samples[k];
    ShowOptions o;
    o.dir = dir;
    o.index = static_cast<long long>(k);
    const ShownImage s = ShowDatasetImage(o);
    EXPECT_EQ(s.kind, DatasetKind::kMotion);
    const int w = s.width, h = s.height;
    const std::vector<std::uint8_t> plain =
        ReadRgb(dir + "/" + smp.at("rgb").get<std::string>(), w, h);
    int mw = 0, mh = 0;
    const std::vector<std::uint8_t> mask_pixels =
        ReadPng(dir + "/" + smp.at("mask").get<std::string>(), 1, &mw, &mh);
    Mask mask(w, h);
    mask.data = mask_pixels;
    const std::vector<double> m = smp.at("m");
    const bool hinge = m[0] == 1;
    (hinge ? hinges : sliders)++;
    Eigen::Matrix3d K;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) K(r, c) = smp.at("camera").at("K")[r][c].get<double>();
    ASSERT_EQ(s.instances.size(), 1u);
    EXPECT_EQ(s.instances[0].label, smp.at("label").get<std::string>());
    EXPECT_NE(s.caption.find(hinge ? "hinge" : "slider"), std::string::npos) << s.caption;
    EXPECT_GT(s.caption_box.w, 0);
    ASSERT_TRUE(s.has_axis) << s.caption;
    const Eigen::Vector2d a(s.axis_segment[0], s.axis_segment[1]);
    const Eigen::Vector2d b(s.axis_segment[2], s.axis_segment[3]);
    // the segment lies on the image of the axis, as K projects it
    if (hinge) {
      ASSERT_TRUE(s.has_pivot);
      const Eigen::Vector3d pivot(m[2], m[3], m[4]), axis(m[5], m[6], m[7]);
      const Eigen::Vector3d p0 = K * pivot, p1 = K * (pivot + 0.2 * axis);
      const Eigen::Vector2d q0 = p0.head<2>() / p0.z(), q1 = p1.head<2>() / p1.z();
      EXPECT_NEAR(s.pivot_pixel[0], q0.x(), 1e-9);
      EXPECT_NEAR(s.pivot_pixel[1], q0.y(), 1e-9);
      const Eigen::Vector2d n = Eigen::Vector2d(-(q1 - q0).y(), (q1 - q0).x()).normalized();
      EXPECT_NEAR((a - q0).dot(n), 0.0, 1e-6);
      EXPECT_NEAR((b - q0).dot(n), 0.0, 1e-6);
      // long enough to cross the part: every mask pixel projects onto the segment
      const Eigen::Vector2d d = (b - a).normalized();
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          if (mask(x, y)) {
            const double t = (Eigen::Vector2d(x, y) - a).dot(d);
            EXPECT_GE(t, 0.0);
            EXPECT_LE(t, (b - a).norm());
          }
    } else {
      EXPECT_FALSE(s.has_pivot);
      // from the mask's centroid toward where K sends a step along the slider axis from a point
      // of the part (its depth only scales the step)
      Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
      int count = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          if (mask(x, y)) {
            centroid += Eigen::Vector2d(x, y);
            ++count;
          }
      centroid /= count;
      EXPECT_NEAR((a - centroid).norm(), 0.0, 1e-9);
      const Eigen::Vector3d axis(m[8], m[9], m[10]);
      const Eigen::Vector3d X = 1.5 * K.inverse() * Eigen::Vector3d(centroid.x(), centroid.y(), 1);
      const Eigen::Vector3d p1 = K * (X + 1e-4 * axis);
      const Eigen::Vector2d step = p1.head<2>() / p1.z() - centroid;
      EXPECT_GT(step.normalized().dot((b - a).normalized()), 1 - 1e-6);
    }
    // pixels along the axis have the axis colour (boxes and the pivot's dot aside)
    const double pivot_r = 6;
    auto near_pivot = [&](double x, double y) {
      return s.has_pivot && std::hypot(x - s.pivot_pixel[0], y - s.pivot_pixel[1]) <= pivot_r;
    };
    int on_line = 0;
    for (int i = 1; i < 100; ++i) {
      const Eigen::Vector2d p = a + (b - a) * (i / 100.0);
      const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
      if (x < 0 || y < 0 || x >= w || y >= h || InAnyBox(s, x, y) || near_pivot(x, y)) continue;
      EXPECT_EQ(At(s.rgb, w, x, y), kShowAxisColor) << x << ", " << y;
      ++on_line;
    }
    EXPECT_GT(on_line, 10);
    if (hinge) {
      const int px = static_cast<int>(std::lround(s.pivot_pixel[0]));
      const int py = static_cast<int>(std::lround(s.pivot_pixel[1]));
      if (px >= 0 && py >= 0 && px < w && py < h && !InAnyBox(s, px, py))
        EXPECT_EQ(At(s.rgb, w, px, py), kShowPivotColor);
    }
    // the mask tinted away from the axis drawing; the rest the RGB
    auto drawn = [&](int x, int y) {
      const Eigen::Vector2d p(x, y);
      return SegmentDistance(p, a, b) <= 4 || (b - p).norm() <= 12 || near_pivot(x, y);
    };
    CheckMask(s, plain, mask, s.instances[0].color, drawn);
    CheckLabelBox(s, s.instances[0]);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (!mask(x, y) && !InAnyBox(s, x, y) && !drawn(x, y))
          ASSERT_EQ(At(s.rgb, w, x, y), At(plain, w, x, y)) << x << ", " << y;
  }
  EXPECT_GT(hinges, 0);
  EXPECT_GT(sliders, 0);
}

TEST(ShowTest, WriteShowPngWritesThePicture) {
  ShowOptions o;
  o.dir = DetectionDataset();
  o.kind = DatasetKind::kDetection;
  o.index = 1;
  const std::string out = Temp("written.png");
  const ShownImage s = WriteShowPng(o, out);
  int w = 0, h = 0;
  EXPECT_EQ(ReadPng(out, 3, &w, &h), s.rgb);
  EXPECT_EQ(w, s.width);
  EXPECT_EQ(h, s.height);
}

using partsim::testing::ErrorOf;

bool Contains(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

TEST(ShowTest, ErrorsNameTheProblem) {
  ShowOptions o;
  o.dir = DetectionDataset();
  o.index = 4;
  std::string e = ErrorOf([&] { ShowDatasetImage(o); });
  EXPECT_TRUE(Contains(e, "index 4 is out of range: instances_train.json holds 4 images (0 to 3)"))
      << e;
  o.index = 0;
  o.split = "test";  // every object is in the training split
  e = ErrorOf([&] { ShowDatasetImage(o); });
  EXPECT_TRUE(Contains(e, "instances_test.json holds 0 images (none)")) << e;
  o.split = "train";
  o.kind = DatasetKind::kMotion;
  e = ErrorOf([&] { ShowDatasetImage(o); });
  EXPECT_TRUE(Contains(e, "has no motion_train.json")) << e;

  ShowOptions m;
  m.dir = MotionDataset();
  m.index = 1000;
  e = ErrorOf([&] { ShowDatasetImage(m); });
  EXPECT_TRUE(Contains(e, "index 1000 is out of range: motion_train.json holds")) << e;

  const std::string empty = Temp("empty");
  fs::create_directories(empty);
  m.dir = empty;
  e = ErrorOf([&] { ShowDatasetImage(m); });
  EXPECT_TRUE(Contains(e, "holds no dataset files (instances_train.json")) << e;
  m.dir = empty + "/missing";
  e = ErrorOf([&] { ShowDatasetImage(m); });
  EXPECT_TRUE(Contains(e, "is not a folder")) << e;

  // a picture that is not a PNG, and one of the wrong size
  const std::string broken = Temp("broken");
  fs::create_directories(broken + "/rgb");
  CocoDataset d;
  d.images.push_back({1, 4, 3, "rgb/a.png"});
  d.categories.push_back({1, "Cabinet/drawer", "Cabinet"});
  std::ofstream(broken + "/instances_train.json") << CocoDatasetToJson(d);
  std::ofstream(broken + "/rgb/a.png") << "not a png";
  m.dir = broken;
  m.index = 0;
  e = ErrorOf([&] { ShowDatasetImage(m); });
  EXPECT_TRUE(Contains(e, "cannot read the picture 'rgb/a.png'")) << e;
  const std::vector<std::uint8_t> pixels(5 * 3 * 3, 9);
  WritePng(broken + "/rgb/a.png", 5, 3, 3, pixels.data());
  e = ErrorOf([&] { ShowDatasetImage(m); });
  EXPECT_TRUE(Contains(e, "'rgb/a.png' is 5 x 3 pixels, the split file says 4 x 3")) << e;
}

}  // namespace
}  // namespace partsim::vision
