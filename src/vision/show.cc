// ShowDatasetImage: a dataset's picture with its annotations drawn (partsim/vision/show.h).
#include "partsim/vision/show.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <utility>

#include "core/number_text.h"
#include "partsim/core/error.h"
#include "partsim/render/image_io.h"
#include "partsim/render/image_read.h"
#include "partsim/vision/coco.h"
#include "partsim/vision/coco_dataset.h"
#include "vision/json_fields.h"

namespace partsim::vision {

namespace fs = std::filesystem;
using internal::json;

namespace {

using Color = std::array<std::uint8_t, 3>;

// ---------------------------------------------------------------------------------------------
// a 5 x 7 bitmap font: printable ASCII letters, digits and a few signs, one string per row,
// '#' for a lit pixel

struct Glyph {
  char c;
  const char* rows[7];
};

constexpr Glyph kFont[] = {
    {' ', {".....", ".....", ".....", ".....", ".....", ".....", "....."}},
    {'0', {".###.", "#...#", "#..##", "#.#.#", "##..#", "#...#", ".###."}},
    {'1', {"..#..", ".##..", "..#..", "..#..", "..#..", "..#..", ".###."}},
    {'2', {".###.", "#...#", "....#", "...#.", "..#..", ".#...", "#####"}},
    {'3', {"#####", "...#.", "..#..", "...#.", "....#", "#...#", ".###."}},
    {'4', {"...#.", "..##.", ".#.#.", "#..#.", "#####", "...#.", "...#."}},
    {'5', {"#####", "#....", "####.", "....#", "....#", "#...#", ".###."}},
    {'6', {"..##.", ".#...", "#....", "####.", "#...#", "#...#", ".###."}},
    {'7', {"#####", "....#", "...#.", "..#..", ".#...", ".#...", ".#..."}},
    {'8', {".###.", "#...#", "#...#", ".###.", "#...#", "#...#", ".###."}},
    {'9', {".###.", "#...#", "#...#", ".####", "....#", "...#.", ".##.."}},
    {'A', {".###.", "#...#", "#...#", "#####", "#...#", "#...#", "#...#"}},
    {'B', {"####.", "#...#", "#...#", "####.", "#...#", "#...#", "####."}},
    {'C', {".###.", "#...#", "#....", "#....", "#....", "#...#", ".###."}},
    {'D', {"###..", "#..#.", "#...#", "#...#", "#...#", "#..#.", "###.."}},
    {'E', {"#####", "#....", "#....", "####.", "#....", "#....", "#####"}},
    {'F', {"#####", "#....", "#....", "####.", "#....", "#....", "#...."}},
    {'G', {".###.", "#...#", "#....", "#.###", "#...#", "#...#", ".####"}},
    {'H', {"#...#", "#...#", "#...#", "#####", "#...#", "#...#", "#...#"}},
    {'I', {".###.", "..#..", "..#..", "..#..", "..#..", "..#..", ".###."}},
    {'J', {"..###", "...#.", "...#.", "...#.", "...#.", "#..#.", ".##.."}},
    {'K', {"#...#", "#..#.", "#.#..", "##...", "#.#..", "#..#.", "#...#"}},
    {'L', {"#....", "#....", "#....", "#....", "#....", "#....", "#####"}},
    {'M', {"#...#", "##.##", "#.#.#", "#.#.#", "#...#", "#...#", "#...#"}},
    {'N', {"#...#", "#...#", "##..#", "#.#.#", "#..##", "#...#", "#...#"}},
    {'O', {".###.", "#...#", "#...#", "#...#", "#...#", "#...#", ".###."}},
    {'P', {"####.", "#...#", "#...#", "####.", "#....", "#....", "#...."}},
    {'Q', {".###.", "#...#", "#...#", "#...#", "#.#.#", "#..#.", ".##.#"}},
    {'R', {"####.", "#...#", "#...#", "####.", "#.#..", "#..#.", "#...#"}},
    {'S', {".####", "#....", "#....", ".###.", "....#", "....#", "####."}},
    {'T', {"#####", "..#..", "..#..", "..#..", "..#..", "..#..", "..#.."}},
    {'U', {"#...#", "#...#", "#...#", "#...#", "#...#", "#...#", ".###."}},
    {'V', {"#...#", "#...#", "#...#", "#...#", "#...#", ".#.#.", "..#.."}},
    {'W', {"#...#", "#...#", "#...#", "#.#.#", "#.#.#", "#.#.#", ".#.#."}},
    {'X', {"#...#", "#...#", ".#.#.", "..#..", ".#.#.", "#...#", "#...#"}},
    {'Y', {"#...#", "#...#", ".#.#.", "..#..", "..#..", "..#..", "..#.."}},
    {'Z', {"#####", "....#", "...#.", "..#..", ".#...", "#....", "#####"}},
    {'a', {".....", ".....", ".###.", "....#", ".####", "#...#", ".####"}},
    {'b', {"#....", "#....", "#.##.", "##..#", "#...#", "#...#", "####."}},
    {'c', {".....", ".....", ".###.", "#....", "#....", "#...#", ".###."}},
    {'d', {"....#", "....#", ".##.#", "#..##", "#...#", "#...#", ".####"}},
    {'e', {".....", ".....", ".###.", "#...#", "#####", "#....", ".###."}},
    {'f', {"..##.", ".#..#", ".#...", "###..", ".#...", ".#...", ".#..."}},
    {'g', {".....", ".####", "#...#", "#...#", ".####", "....#", ".###."}},
    {'h', {"#....", "#....", "#.##.", "##..#", "#...#", "#...#", "#...#"}},
    {'i', {"..#..", ".....", ".##..", "..#..", "..#..", "..#..", ".###."}},
    {'j', {"...#.", ".....", "..##.", "...#.", "...#.", "#..#.", ".##.."}},
    {'k', {"#....", "#....", "#..#.", "#.#..", "##...", "#.#..", "#..#."}},
    {'l', {".##..", "..#..", "..#..", "..#..", "..#..", "..#..", ".###."}},
    {'m', {".....", ".....", "##.#.", "#.#.#", "#.#.#", "#...#", "#...#"}},
    {'n', {".....", ".....", "#.##.", "##..#", "#...#", "#...#", "#...#"}},
    {'o', {".....", ".....", ".###.", "#...#", "#...#", "#...#", ".###."}},
    {'p', {".....", ".....", "####.", "#...#", "####.", "#....", "#...."}},
    {'q', {".....", ".....", ".##.#", "#..##", ".####", "....#", "....#"}},
    {'r', {".....", ".....", "#.##.", "##..#", "#....", "#....", "#...."}},
    {'s', {".....", ".....", ".###.", "#....", ".###.", "....#", "####."}},
    {'t', {".#...", ".#...", "###..", ".#...", ".#...", ".#..#", "..##."}},
    {'u', {".....", ".....", "#...#", "#...#", "#...#", "#..##", ".##.#"}},
    {'v', {".....", ".....", "#...#", "#...#", "#...#", ".#.#.", "..#.."}},
    {'w', {".....", ".....", "#...#", "#...#", "#.#.#", "#.#.#", ".#.#."}},
    {'x', {".....", ".....", "#...#", ".#.#.", "..#..", ".#.#.", "#...#"}},
    {'y', {".....", ".....", "#...#", "#...#", ".####", "....#", ".###."}},
    {'z', {".....", ".....", "#####", "...#.", "..#..", ".#...", "#####"}},
    {'/', {".....", "....#", "...#.", "..#..", ".#...", "#....", "....."}},
    {'_', {".....", ".....", ".....", ".....", ".....", ".....", "#####"}},
    {'-', {".....", ".....", ".....", "#####", ".....", ".....", "....."}},
    {'.', {".....", ".....", ".....", ".....", ".....", ".##..", ".##.."}},
    {',', {".....", ".....", ".....", ".....", ".##..", "..#..", ".#..."}},
    {':', {".....", ".##..", ".##..", ".....", ".##..", ".##..", "....."}},
    {'=', {".....", ".....", "#####", ".....", "#####", ".....", "....."}},
    {'+', {".....", "..#..", "..#..", "#####", "..#..", "..#..", "....."}},
    {'(', {"...#.", "..#..", ".#...", ".#...", ".#...", "..#..", "...#."}},
    {')', {".#...", "..#..", "...#.", "...#.", "...#.", "..#..", ".#..."}},
    {'%', {"##...", "##..#", "...#.", "..#..", ".#...", "#..##", "...##"}},
    {'?', {".###.", "#...#", "....#", "...#.", "..#..", ".....", "..#.."}},
};

constexpr int kGlyphWidth = 5, kGlyphHeight = 7;

// the glyph of `c`; '?' for a character the font lacks
const Glyph& GlyphOf(char c) {
  static const std::map<char, const Glyph*> table = [] {
    std::map<char, const Glyph*> t;
    for (const Glyph& g : kFont) t[g.c] = &g;
    return t;
  }();
  auto it = table.find(c);
  return it != table.end() ? *it->second : *table.at('?');
}

// ---------------------------------------------------------------------------------------------
// drawing on an RGB picture

class Canvas {
 public:
  Canvas(int width, int height, std::vector<std::uint8_t> rgb)
      : width_(width), height_(height), rgb_(std::move(rgb)) {}

  int Width() const { return width_; }
  int Height() const { return height_; }
  std::vector<std::uint8_t>& Pixels() { return rgb_; }

  void Set(int x, int y, const Color& c) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
    std::uint8_t* p = &rgb_[3 * (static_cast<std::size_t>(y) * width_ + x)];
    for (int k = 0; k < 3; ++k) p[k] = c[k];
  }

  // half the pixel's colour and half `c`, rounded half up
  void Blend(int x, int y, const Color& c) {
    std::uint8_t* p = &rgb_[3 * (static_cast<std::size_t>(y) * width_ + x)];
    for (int k = 0; k < 3; ++k) p[k] = static_cast<std::uint8_t>((p[k] + c[k] + 1) / 2);
  }

  void FillBox(const PixelBox& b, const Color& c) {
    for (int y = b.y; y < b.y + b.h; ++y)
      for (int x = b.x; x < b.x + b.w; ++x) Set(x, y, c);
  }

  void Disc(double cx, double cy, double radius, const Color& c) {
    const int r = static_cast<int>(std::ceil(radius));
    const int ix = static_cast<int>(std::lround(cx)), iy = static_cast<int>(std::lround(cy));
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx)
        if (dx * dx + dy * dy <= radius * radius) Set(ix + dx, iy + dy, c);
  }

  // a segment `thickness` pixels wide: every pixel whose centre is within thickness / 2 of it
  void Line(double x0, double y0, double x1, double y1, double thickness, const Color& c) {
    const double half = 0.5 * thickness;
    const int lo_x = std::max(0, static_cast<int>(std::floor(std::min(x0, x1) - half)));
    const int hi_x = std::min(width_ - 1, static_cast<int>(std::ceil(std::max(x0, x1) + half)));
    const int lo_y = std::max(0, static_cast<int>(std::floor(std::min(y0, y1) - half)));
    const int hi_y = std::min(height_ - 1, static_cast<int>(std::ceil(std::max(y0, y1) + half)));
    const Eigen::Vector2d a(x0, y0), d = Eigen::Vector2d(x1, y1) - a;
    const double length2 = d.squaredNorm();
    for (int y = lo_y; y <= hi_y; ++y) {
      for (int x = lo_x; x <= hi_x; ++x) {
        const Eigen::Vector2d p(x, y);
        const double t = length2 > 0 ? std::clamp((p - a).dot(d) / length2, 0.0, 1.0) : 0.0;
        if ((p - (a + t * d)).squaredNorm() <= half * half) Set(x, y, c);
      }
    }
  }

  // `text` in the 5 x 7 font at `scale`, its top-left at (x, y), the pixels outside `clip` left
  // alone
  void Text(int x, int y, const std::string& text, int scale, const Color& c,
            const PixelBox& clip) {
    for (std::size_t i = 0; i < text.size(); ++i) {
      const Glyph& g = GlyphOf(text[i]);
      const int gx = x + static_cast<int>(i) * (kGlyphWidth + 1) * scale;
      for (int row = 0; row < kGlyphHeight; ++row)
        for (int col = 0; col < kGlyphWidth; ++col) {
          if (g.rows[row][col] != '#') continue;
          for (int sy = 0; sy < scale; ++sy)
            for (int sx = 0; sx < scale; ++sx) {
              const int px = gx + col * scale + sx, py = y + row * scale + sy;
              if (clip.Contains(px, py)) Set(px, py, c);
            }
        }
    }
  }

 private:
  int width_, height_;
  std::vector<std::uint8_t> rgb_;
};

// font scale: 2 on pictures of 256 pixels or more a side, else 1
int FontScale(int width, int height) { return std::min(width, height) >= 256 ? 2 : 1; }

// size of `text`'s box at `scale`: the glyphs and a margin of `scale` + 1 pixels around them
PixelBox TextBox(const std::string& text, int scale) {
  const int pad = scale + 1;
  const int n = static_cast<int>(text.size());
  return {0, 0, std::max(0, n * (kGlyphWidth + 1) * scale - scale) + 2 * pad,
          kGlyphHeight * scale + 2 * pad};
}

// `box` moved to (x, y), then shifted inside the picture where it fits, and clipped
PixelBox PlaceBox(PixelBox box, int x, int y, int width, int height) {
  box.x = std::max(0, std::min(x, width - box.w));
  box.y = std::max(0, std::min(y, height - box.h));
  box.w = std::min(box.w, width - box.x);
  box.h = std::min(box.h, height - box.y);
  return box;
}

// a dark box with `text` in colour `c`, both clipped to the box
void DrawLabel(Canvas* canvas, const PixelBox& box, const std::string& text, int scale,
               const Color& c) {
  canvas->FillBox(box, kShowBoxColor);
  const int pad = scale + 1;
  canvas->Text(box.x + pad, box.y + pad, text, scale, c, box);
}

// the mask blended over the picture in `c` and outlined in full colour: a mask pixel is on the
// outline when a pixel within `outline` pixels left, right, above or below is inside the
// picture and outside the mask
void DrawMask(Canvas* canvas, const Mask& mask, const Color& c, int outline) {
  auto in = [&](int x, int y) {
    return x < 0 || y < 0 || x >= mask.width || y >= mask.height || mask(x, y) != 0;
  };
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      if (!mask(x, y)) continue;
      bool edge = false;
      for (int d = 1; d <= outline && !edge; ++d)
        edge = !in(x - d, y) || !in(x + d, y) || !in(x, y - d) || !in(x, y + d);
      if (edge)
        canvas->Set(x, y, c);
      else
        canvas->Blend(x, y, c);
    }
  }
}

// the label's box above the top-left corner of the mask's box, or inside its top when there is
// no room above
PixelBox LabelBoxFor(const std::array<double, 4>& bbox, const std::string& text, int scale,
                     int width, int height) {
  const PixelBox size = TextBox(text, scale);
  const int x = static_cast<int>(bbox[0]);
  int y = static_cast<int>(bbox[1]) - size.h;
  if (y < 0) y = static_cast<int>(bbox[1]);
  return PlaceBox(size, x, y, width, height);
}

// the bounding box of a mask's pixels, [x, y, w, h]; zeros when empty
std::array<double, 4> MaskBox(const Mask& mask) {
  int x0 = mask.width, y0 = mask.height, x1 = -1, y1 = -1;
  for (int y = 0; y < mask.height; ++y)
    for (int x = 0; x < mask.width; ++x)
      if (mask(x, y)) {
        x0 = std::min(x0, x);
        y0 = std::min(y0, y);
        x1 = std::max(x1, x);
        y1 = std::max(y1, y);
      }
  if (x1 < 0) return {0, 0, 0, 0};
  return {static_cast<double>(x0), static_cast<double>(y0), static_cast<double>(x1 - x0 + 1),
          static_cast<double>(y1 - y0 + 1)};
}

// ---------------------------------------------------------------------------------------------
// the dataset's files

std::string SplitFileName(DatasetKind kind, const std::string& split) {
  return (kind == DatasetKind::kDetection ? "instances_" : "motion_") + split + ".json";
}

bool HasSplitFiles(const std::string& dir, DatasetKind kind) {
  for (const char* split : {"train", "test"})
    if (fs::is_regular_file(fs::path(dir) / SplitFileName(kind, split))) return true;
  return false;
}

DatasetKind KindOf(const ShowOptions& o) {
  if (o.kind) return *o.kind;
  const bool detection = HasSplitFiles(o.dir, DatasetKind::kDetection);
  const bool motion = HasSplitFiles(o.dir, DatasetKind::kMotion);
  if (detection && motion)
    throw Error("vision show: '" + o.dir +
                "' holds both detection (instances_*.json) and motion (motion_*.json) split "
                "files: say which with kind (--kind detection or motion)");
  if (!detection && !motion)
    throw Error("vision show: '" + o.dir +
                "' holds no dataset files (instances_train.json, instances_test.json, "
                "motion_train.json or motion_test.json)");
  return detection ? DatasetKind::kDetection : DatasetKind::kMotion;
}

// "index 9 is out of range: motion_train.json holds 4 samples (0 to 3)"
[[noreturn]] void OutOfRange(long long index, const std::string& file, std::size_t count,
                             const std::string& thing) {
  std::string range = count == 0 ? std::string("none") : "0 to " + std::to_string(count - 1);
  throw Error("vision show: index " + std::to_string(index) + " is out of range: " + file +
              " holds " + std::to_string(count) + " " + thing + (count == 1 ? "" : "s") + " (" +
              range + ")");
}

// the picture file `relative` (to the dataset folder) as `channels` per pixel, of the size the
// split file gives
std::vector<std::uint8_t> ReadPicture(const std::string& dir, const std::string& relative,
                                      int channels, int width, int height,
                                      const std::string& what) {
  int w = 0, h = 0;
  std::vector<std::uint8_t> pixels;
  try {
    pixels = ReadPng((fs::path(dir) / relative).string(), channels, &w, &h);
  } catch (const Error& e) {
    throw Error("vision show: cannot read the " + what + " '" + relative + "': " + e.what());
  }
  if (w != width || h != height)
    throw Error("vision show: the " + what + " '" + relative + "' is " + std::to_string(w) + " x " +
                std::to_string(h) + " pixels, the split file says " + std::to_string(width) +
                " x " + std::to_string(height));
  return pixels;
}

// the part label of a category "<object category>/<part label>"
std::string PartLabel(const std::string& category) {
  const std::size_t slash = category.find('/');
  return slash == std::string::npos ? category : category.substr(slash + 1);
}

// ---------------------------------------------------------------------------------------------
// detection

ShownImage ShowDetection(const ShowOptions& o, const std::string& split_file) {
  const CocoDataset d = LoadCocoDataset((fs::path(o.dir) / split_file).string());
  if (o.index < 0 || o.index >= static_cast<long long>(d.images.size()))
    OutOfRange(o.index, split_file, d.images.size(), "image");
  const CocoImage& image = d.images[static_cast<std::size_t>(o.index)];
  if (image.file_name.empty())
    throw Error("vision show: " + split_file + ": image " + std::to_string(o.index) + " (id " +
                std::to_string(image.id) + ") has no file_name");
  ShownImage out;
  out.kind = DatasetKind::kDetection;
  out.split_file = split_file;
  out.rgb_file = image.file_name;
  out.title = "image " + std::to_string(o.index) + " (id " + std::to_string(image.id) + ")";
  out.width = image.width;
  out.height = image.height;
  Canvas canvas(image.width, image.height,
                ReadPicture(o.dir, image.file_name, 3, image.width, image.height, "picture"));
  std::map<std::int64_t, std::string> names;
  for (const CocoCategory& c : d.categories) names[c.id] = c.name;
  const int scale = FontScale(image.width, image.height);
  // masks first, then every label over them
  for (const CocoAnnotation& a : d.annotations) {
    if (a.image_id != image.id) continue;
    ShownInstance s;
    s.label = PartLabel(names.at(a.category_id));
    s.color = ShowInstanceColor(static_cast<int>(out.instances.size()));
    const Mask mask = DecodeRle(a.segmentation);
    s.bbox = MaskBox(mask);
    DrawMask(&canvas, mask, s.color, scale);
    s.label_box = LabelBoxFor(s.bbox, s.label, scale, image.width, image.height);
    out.instances.push_back(s);
  }
  for (const ShownInstance& s : out.instances)
    DrawLabel(&canvas, s.label_box, s.label, scale, s.color);
  out.rgb = std::move(canvas.Pixels());
  return out;
}

// ---------------------------------------------------------------------------------------------
// motion

// the pixel of camera-frame point `p` (OpenCV: x right, y down, z forward) through K
Eigen::Vector2d Project(const Eigen::Matrix3d& K, const Eigen::Vector3d& p) {
  const Eigen::Vector3d h = K * p;
  return h.head<2>() / h.z();
}

Eigen::Vector3d Vec3(const json& m, int first) {
  return Eigen::Vector3d(m[first].get<double>(), m[first + 1].get<double>(),
                         m[first + 2].get<double>());
}

// the extent of `mask`'s pixels along the line through `origin` with unit direction `dir`:
// [min, max] of (pixel - origin) . dir
std::pair<double, double> ExtentAlong(const Mask& mask, const Eigen::Vector2d& origin,
                                      const Eigen::Vector2d& dir) {
  double lo = 0, hi = 0;
  bool any = false;
  for (int y = 0; y < mask.height; ++y)
    for (int x = 0; x < mask.width; ++x)
      if (mask(x, y)) {
        const double t = (Eigen::Vector2d(x, y) - origin).dot(dir);
        lo = any ? std::min(lo, t) : t;
        hi = any ? std::max(hi, t) : t;
        any = true;
      }
  return {lo, hi};
}

ShownImage ShowMotion(const ShowOptions& o, const std::string& split_file) {
  const std::string path = (fs::path(o.dir) / split_file).string();
  const std::string source = "motion split file '" + path + "'";
  const json doc =
      internal::ParseDocument(internal::ReadDocument(path, "motion split file"), source);
  const json& samples = internal::ArrayField(doc, "samples", source);
  if (o.index < 0 || o.index >= static_cast<long long>(samples.size()))
    OutOfRange(o.index, split_file, samples.size(), "sample");
  const json& s = samples[static_cast<std::size_t>(o.index)];
  const std::string where = source + ": samples[" + std::to_string(o.index) + "]";
  // the label vector, checked: 13 finite numbers
  const json& m = internal::ArrayField(s, "m", where);
  if (m.size() != 13)
    throw Error(where + ": 'm' must hold 13 numbers, got " + std::to_string(m.size()));
  for (std::size_t k = 0; k < m.size(); ++k)
    internal::AsNumber(m[k], where + ": m[" + std::to_string(k) + "]");
  const bool hinge = m[0].get<double>() >= m[1].get<double>();
  const json& camera = internal::Field(s, "camera", where);
  const std::string cam_where = where + ": camera";
  const json& k_rows = internal::ArrayField(camera, "K", cam_where);
  Eigen::Matrix3d K;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const std::string what =
          cam_where + ": K[" + std::to_string(r) + "][" + std::to_string(c) + "]";
      if (k_rows.size() != 3 || !k_rows[r].is_array() || k_rows[r].size() != 3)
        throw Error(cam_where + ": 'K' must be a 3 x 3 matrix, got " + internal::Describe(k_rows));
      K(r, c) = internal::AsNumber(k_rows[r][c], what);
    }
  const auto size = [&](const char* key) {
    const std::int64_t v =
        internal::AsInteger(internal::Field(camera, key, cam_where), cam_where + ": " + key);
    if (v < 1 || v > 1 << 16)
      throw Error(cam_where + ": " + key + " must be from 1 to 65536, got " + std::to_string(v));
    return static_cast<int>(v);
  };
  const int width = size("width"), height = size("height");

  ShownImage out;
  out.kind = DatasetKind::kMotion;
  out.split_file = split_file;
  out.rgb_file = internal::AsString(internal::Field(s, "rgb", where), where + ": rgb");
  const std::string mask_file =
      internal::AsString(internal::Field(s, "mask", where), where + ": mask");
  std::string id = "sample " + std::to_string(o.index);
  if (s.contains("sample_id"))
    id += " (" +
          (s["sample_id"].is_string() ? s["sample_id"].get<std::string>() : s["sample_id"].dump()) +
          ")";
  out.title = id;
  out.width = width;
  out.height = height;
  Canvas canvas(width, height, ReadPicture(o.dir, out.rgb_file, 3, width, height, "picture"));
  Mask mask(width, height);
  mask.data = ReadPicture(o.dir, mask_file, 1, width, height, "mask");
  const int scale = FontScale(width, height);

  ShownInstance part;
  part.label = s.contains("label") && s["label"].is_string() ? s["label"].get<std::string>()
                                                             : (hinge ? "door" : "drawer");
  part.color = ShowInstanceColor(0);
  part.bbox = MaskBox(mask);
  DrawMask(&canvas, mask, part.color, scale);
  part.label_box = LabelBoxFor(part.bbox, part.label, scale, width, height);

  // the mask's centroid in pixels (the picture's centre for an empty mask)
  Eigen::Vector2d centroid(0.5 * width, 0.5 * height);
  {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    long count = 0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if (mask(x, y)) {
          sum += Eigen::Vector2d(x, y);
          ++count;
        }
    if (count > 0) centroid = sum / static_cast<double>(count);
  }
  const double thickness = 1.0 + 2.0 * scale;
  const double min_length = 0.15 * std::min(width, height);
  if (hinge) {
    // the image of the hinge's axis line: through the pivot's pixel and the pixel of a point
    // further along the axis (a few percent of the pivot's depth, so that both are in front of
    // the camera), drawn across the mask's extent along it plus a margin
    const Eigen::Vector3d pivot = Vec3(m, 2);
    const Eigen::Vector3d axis = Vec3(m, 5);
    if (pivot.z() > 1e-6) {
      out.has_pivot = true;
      const Eigen::Vector2d p0 = Project(K, pivot);
      out.pivot_pixel = {p0.x(), p0.y()};
      const double step = 0.05 * pivot.z() / std::max(axis.norm(), 1e-12);
      Eigen::Vector2d dir = Project(K, pivot + step * axis) - p0;
      if (axis.norm() > 0 && dir.norm() > 1e-9) {
        dir.normalize();
        auto [lo, hi] = ExtentAlong(mask, p0, dir);
        lo = std::min(lo, 0.0);
        hi = std::max(hi, 0.0);
        const double margin = std::max(0.1 * (hi - lo), 0.5 * min_length);
        const Eigen::Vector2d a = p0 + (lo - margin) * dir, b = p0 + (hi + margin) * dir;
        out.has_axis = true;
        out.axis_segment = {a.x(), a.y(), b.x(), b.y()};
      }
    }
  } else {
    // a direction d seen at pixel c moves the pixel along (K d)_xy - c d_z, whatever the
    // depth (the derivative of the projection of X + e d at e = 0, X on c's ray); the arrow
    // runs from the centroid past the mask's far end along it
    const Eigen::Vector3d axis = Vec3(m, 8);
    const Eigen::Vector3d kd = K * axis;
    Eigen::Vector2d dir = kd.head<2>() - centroid * kd.z();
    if (axis.norm() > 0 && dir.norm() > 1e-9) {
      dir.normalize();
      const double reach = ExtentAlong(mask, centroid, dir).second;
      const double length = std::max(1.25 * reach, min_length);
      const Eigen::Vector2d b = centroid + length * dir;
      out.has_axis = true;
      out.axis_segment = {centroid.x(), centroid.y(), b.x(), b.y()};
    }
  }
  if (out.has_axis) {
    const auto& a = out.axis_segment;
    canvas.Line(a[0], a[1], a[2], a[3], thickness, kShowAxisColor);
    if (!hinge) {
      // the arrow's head: two strokes back from the tip at 30 degrees either side
      const Eigen::Vector2d tip(a[2], a[3]);
      const Eigen::Vector2d back = (Eigen::Vector2d(a[0], a[1]) - tip).normalized();
      const double head = 6.0 * scale;
      for (const double angle : {0.5, -0.5}) {
        const Eigen::Vector2d d(std::cos(angle) * back.x() - std::sin(angle) * back.y(),
                                std::sin(angle) * back.x() + std::cos(angle) * back.y());
        const Eigen::Vector2d e = tip + head * d;
        canvas.Line(tip.x(), tip.y(), e.x(), e.y(), thickness, kShowAxisColor);
      }
    }
  }
  if (out.has_pivot) {
    canvas.Disc(out.pivot_pixel[0], out.pivot_pixel[1], 2.0 * scale + 2.0, kShowBoxColor);
    canvas.Disc(out.pivot_pixel[0], out.pivot_pixel[1], 2.0 * scale + 1.0, kShowPivotColor);
  }

  // the caption: type, label and state (hinge: x_door * 360 degrees; slider: x_drawer times the
  // slider range, metres)
  std::string state;
  if (hinge) {
    state = partsim::internal::Fixed(m[11].get<double>() * 360.0, 1) + " deg";
  } else {
    const double range = doc.contains("slider_range") && doc["slider_range"].is_number()
                             ? doc["slider_range"].get<double>()
                             : 0.0;
    state = range > 0 ? partsim::internal::Fixed(m[12].get<double>() * range, 3) + " m"
                      : "x " + partsim::internal::Fixed(m[12].get<double>(), 3);
  }
  out.caption = std::string(hinge ? "hinge " : "slider ") + part.label + " " + state;
  const PixelBox caption_size = TextBox(out.caption, scale);
  out.caption_box = PlaceBox(caption_size, 0, height - caption_size.h, width, height);
  DrawLabel(&canvas, part.label_box, part.label, scale, part.color);
  DrawLabel(&canvas, out.caption_box, out.caption, scale, Color{255, 255, 255});
  out.instances.push_back(part);
  out.rgb = std::move(canvas.Pixels());
  return out;
}

}  // namespace

std::array<std::uint8_t, 3> ShowInstanceColor(int k) {
  static constexpr Color kPalette[] = {
      {255, 64, 64}, {64, 160, 255}, {64, 255, 96}, {255, 160, 0},   {200, 64, 255},
      {0, 230, 230}, {255, 64, 200}, {160, 255, 0}, {255, 128, 128}, {128, 128, 255},
  };
  constexpr int n = static_cast<int>(sizeof(kPalette) / sizeof(kPalette[0]));
  return kPalette[((k % n) + n) % n];
}

ShownImage ShowDatasetImage(const ShowOptions& options) {
  if (options.dir.empty()) throw Error("vision show: the dataset folder is empty");
  if (options.split != "train" && options.split != "test")
    throw Error("vision show: split must be 'train' or 'test', got '" + options.split + "'");
  if (!fs::is_directory(options.dir))
    throw Error("vision show: '" + options.dir + "' is not a folder");
  const DatasetKind kind = KindOf(options);
  const std::string split_file = SplitFileName(kind, options.split);
  if (!fs::is_regular_file(fs::path(options.dir) / split_file))
    throw Error("vision show: '" + options.dir + "' has no " + split_file);
  return kind == DatasetKind::kDetection ? ShowDetection(options, split_file)
                                         : ShowMotion(options, split_file);
}

ShownImage WriteShowPng(const ShowOptions& options, const std::string& out_png) {
  ShownImage image = ShowDatasetImage(options);
  WritePng(out_png, image.width, image.height, 3, image.rgb.data());
  return image;
}

}  // namespace partsim::vision
