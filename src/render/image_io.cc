// PNG (libpng, to memory or a file), PLY and NPY writers, depth images and point clouds.
#include "partsim/render/image_io.h"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "render/render_state.h"

namespace partsim {
namespace {

// writes a whole file through a temporary renamed onto the path (no torn file under the real
// name, and writers at once each land whole); throws naming `what` and the path
void SaveFile(const char* what, const std::string& path, const std::string& bytes) {
  try {
    internal::WriteFileAtomically(path, bytes);
  } catch (const Error& e) {
    throw Error(std::string(what) + ": " + e.what());
  }
}

void CheckSize(const char* what, int width, int height) {
  if (width < 1 || height < 1)
    throw Error(std::string(what) + ": image size must be at least 1 x 1, got " +
                std::to_string(width) + " x " + std::to_string(height));
}

// checks that the picture holds the outputs in `needs` (PictureOutput bits) at its size
void CheckPicture(const char* what, const Picture& p, unsigned needs) {
  CheckSize(what, p.width, p.height);
  if ((p.outputs & needs) != needs)
    throw Error(std::string(what) + ": needs picture output(s) " + PictureOutputNames(needs) +
                ", but the picture was taken with " + PictureOutputNames(p.outputs));
  size_t n = static_cast<size_t>(p.width) * static_cast<size_t>(p.height);
  auto bad = [&](const auto& v, unsigned bit, size_t channels) {
    return (needs & bit) && v.size() != channels * n;
  };
  if (bad(p.color, kColor, 4) || bad(p.normal, kNormal, 4) || bad(p.position, kPosition, 4) ||
      bad(p.segmentation, kSegmentation, 2))
    throw Error(std::string(what) + ": picture buffers do not match its size " +
                std::to_string(p.width) + " x " + std::to_string(p.height));
}

// a PNG's bytes from rows of `bit_depth`-bit samples; 16-bit rows hold native uint16 values;
// `where` (" (writing 'path')" or "") ends messages about the arguments
std::string EncodePngRows(int width, int height, int color_type, int bit_depth, int bytes_per_pixel,
                          const uint8_t* data, const PngCompression& compression, const char* what,
                          const std::string& where) {
  if (compression.level < -1 || compression.level > 9)
    throw Error(std::string(what) + ": compression level must be in [-1, 9], got " +
                std::to_string(compression.level) + where);
  if (compression.filter < -1 || compression.filter > 4)
    throw Error(std::string(what) + ": PNG filter must be in [-1, 4], got " +
                std::to_string(compression.filter) + where);
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw Error(std::string(what) + ": libpng could not start" + where);
  }
  std::vector<png_bytep> rows(static_cast<size_t>(height));
  size_t stride = static_cast<size_t>(width) * bytes_per_pixel;
  for (int r = 0; r < height; ++r)
    rows[r] = const_cast<png_bytep>(data + static_cast<size_t>(r) * stride);
  // libpng reports errors by longjmp; nothing with a destructor is created after this point
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw Error(std::string(what) + ": libpng failed" + where);
  }
  // the file's bytes go to `out`
  png_set_write_fn(
      png, &out,
      [](png_structp p, png_bytep bytes, png_size_t n) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<char*>(bytes), n);
      },
      [](png_structp) {});  // nothing to flush (a null one would fflush the string)
  if (compression.level >= 0) png_set_compression_level(png, compression.level);
  // PNG_FILTER_NONE ... PNG_FILTER_PAETH are the bits 0x08 << filter number
  if (compression.filter >= 0)
    png_set_filter(png, PNG_FILTER_TYPE_BASE, 0x08 << compression.filter);
  png_set_IHDR(png, info, width, height, bit_depth, color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  // PNG stores 16-bit samples big-endian
  if (bit_depth == 16) png_set_swap(png);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

// libpng's colour type of 8-bit pixels with `channels` samples
int PngColorType(int channels, const char* what, const std::string& where) {
  switch (channels) {
    case 1:
      return PNG_COLOR_TYPE_GRAY;
    case 2:
      return PNG_COLOR_TYPE_GRAY_ALPHA;
    case 3:
      return PNG_COLOR_TYPE_RGB;
    case 4:
      return PNG_COLOR_TYPE_RGBA;
    default:
      throw Error(std::string(what) + ": channels must be 1, 2, 3 or 4, got " +
                  std::to_string(channels) + where);
  }
}

// little-endian helpers for binary PLY and NPY (the machines partsim runs on are little-endian;
// checked once here)
bool LittleEndian() {
  uint16_t x = 1;
  uint8_t b;
  std::memcpy(&b, &x, 1);
  return b == 1;
}

template <typename T>
void WriteNpyImpl(const std::string& path, const T* data, const std::vector<size_t>& shape,
                  const char* descr) {
  const char* what = "write_npy";
  size_t count = 1;
  for (size_t s : shape) count *= s;
  if (!data && count > 0) throw Error(std::string(what) + ": no data for '" + path + "'");
  if (!LittleEndian()) throw Error(std::string(what) + ": needs a little-endian machine");
  // header: dict, padded with spaces and a newline to a multiple of 64 bytes
  std::string dims;
  for (size_t i = 0; i < shape.size(); ++i) dims += std::to_string(shape[i]) + ", ";
  if (shape.size() > 1) dims.resize(dims.size() - 2);
  if (shape.size() == 1) dims.resize(dims.size() - 1);
  std::string header =
      std::string("{'descr': '") + descr + "', 'fortran_order': False, 'shape': (" + dims + "), }";
  size_t total = 10 + header.size() + 1;
  header.append((64 - total % 64) % 64, ' ');
  header += '\n';
  std::string bytes("\x93NUMPY\x01\x00", 8);
  const uint16_t len = static_cast<uint16_t>(header.size());
  bytes += static_cast<char>(len & 0xff);
  bytes += static_cast<char>(len >> 8);
  bytes += header;
  if (count > 0) bytes.append(reinterpret_cast<const char*>(data), sizeof(T) * count);
  SaveFile(what, path, bytes);
}

}  // namespace

std::vector<float> DepthImage(const Picture& picture) {
  std::vector<float> depth(picture.position.size() / 4);
  for (size_t i = 0; i < depth.size(); ++i) depth[i] = picture.position[4 * i + 3];
  return depth;
}

PointCloud MakePointCloud(const Picture& picture, PointCloudFrame frame, const Pose& X_WC) {
  CheckPicture("point_cloud", picture, kPosition);
  // colours and ids when the picture has them
  bool has_color = (picture.outputs & kColor) && !picture.color.empty();
  bool has_ids = (picture.outputs & kSegmentation) && !picture.segmentation.empty();
  // world from OpenGL camera frame
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t = Eigen::Vector3f::Zero();
  if (frame == PointCloudFrame::kWorld) {
    CheckPose("point_cloud: X_WC", X_WC);
    R = (X_WC.q.toRotationMatrix() * RotationCameraToGl()).cast<float>();
    t = X_WC.p.cast<float>();
  }
  size_t n = static_cast<size_t>(picture.width) * static_cast<size_t>(picture.height);
  std::vector<uint8_t> rgba = has_color ? ToRgba8(picture.color) : std::vector<uint8_t>();
  if (has_color && rgba.size() != 4 * n) has_color = false;
  if (has_ids && picture.segmentation.size() != 2 * n) has_ids = false;
  PointCloud cloud;
  // pixels that see a surface have a depth > 0
  for (size_t i = 0; i < n; ++i) {
    if (!(picture.position[4 * i + 3] > 0)) continue;
    Eigen::Vector3f p(picture.position[4 * i], picture.position[4 * i + 1],
                      picture.position[4 * i + 2]);
    p = R * p + t;
    cloud.positions.insert(cloud.positions.end(), {p.x(), p.y(), p.z()});
    if (has_color)
      cloud.colors.insert(cloud.colors.end(), rgba.begin() + 4 * i, rgba.begin() + 4 * i + 4);
    if (has_ids) {
      cloud.visual_ids.push_back(picture.segmentation[2 * i]);
      cloud.entity_ids.push_back(picture.segmentation[2 * i + 1]);
    }
  }
  return cloud;
}

PointCloud MakePointCloud(const Camera& camera, PointCloudFrame frame) {
  const Picture& picture = camera.GetPictureData();
  Pose X_WC;
  for (const auto& c : internal::RenderOf(*camera.GetScene()).cameras)
    if (c.id == camera.GetId()) X_WC = c.picture_X_WC;
  return MakePointCloud(picture, frame, X_WC);
}

namespace {

// sRGB encoding to 8 bits by table, the same bytes as lround(255 * encode(x)) without a pow per
// value (it was most of the cost of writing a video frame): `first[b]` is the smallest linear
// value that encodes to byte b, and `start[i]` the byte of i / kBuckets; a bucket spans less
// than one byte of the curve, so at most one step up corrects the start.
struct SrgbTable {
  static constexpr int kBuckets = 4096;
  float first[257];
  uint8_t start[kBuckets + 1];
  SrgbTable() {
    first[0] = 0.0f;
    for (int b = 1; b < 256; ++b) {
      const double s = (b - 0.5) / 255.0;
      first[b] = static_cast<float>(s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4));
    }
    first[256] = 2.0f;  // above every clamped value
    for (int i = 0, b = 0; i <= kBuckets; ++i) {
      const float x = static_cast<float>(i) / kBuckets;
      while (b < 255 && x >= first[b + 1]) ++b;
      start[i] = static_cast<uint8_t>(b);
    }
  }
  uint8_t Encode(float x) const {
    if (!(x > 0.0f)) return 0;  // NaN too
    if (x >= 1.0f) return 255;
    int b = start[static_cast<int>(x * kBuckets)];
    while (x >= first[b + 1]) ++b;
    return static_cast<uint8_t>(b);
  }
};

}  // namespace

std::vector<uint8_t> ToRgba8(const std::vector<float>& rgba) {
  static const SrgbTable table;
  std::vector<uint8_t> out(rgba.size());
  for (size_t i = 0; i + 3 < rgba.size(); i += 4) {
    for (size_t k = 0; k < 3; ++k) out[i + k] = table.Encode(rgba[i + k]);
    // alpha is coverage, not colour: no transfer curve
    const float a = rgba[i + 3];
    out[i + 3] = a > 0.0f ? static_cast<uint8_t>(std::lround(std::min(a, 1.0f) * 255.0f)) : 0;
  }
  return out;
}

std::vector<uint8_t> UnitFloatsToUint8(const float* values, size_t count) {
  std::vector<uint8_t> out(count);
  for (size_t i = 0; i < count; ++i) {
    const float v = values[i];
    if (std::isnan(v))
      throw Error("value " + std::to_string(i) + " is NaN; expected values in [0, 1]");
    out[i] = static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
  }
  return out;
}

std::array<uint8_t, 3> SegmentationColor(uint32_t id) {
  if (id == 0) return {0, 0, 0};
  // hue from the golden-ratio sequence (neighbouring ids get far-apart hues); saturation and
  // value from a hash of the id (murmur3 finaliser), value in [0.6, 1] so that every id is
  // clearly brighter than the background
  uint32_t h = id;
  h ^= h >> 16;
  h *= 0x85ebca6bu;
  h ^= h >> 13;
  h *= 0xc2b2ae35u;
  h ^= h >> 16;
  double hue = std::fmod(id * 0.6180339887498949, 1.0) * 6.0;
  double sat = 0.55 + 0.45 * ((h >> 16) & 0xff) / 255.0;
  double val = 0.6 + 0.4 * ((h >> 24) & 0xff) / 255.0;
  int sector = static_cast<int>(hue);
  double f = hue - sector;
  double p = val * (1 - sat), q = val * (1 - sat * f), t = val * (1 - sat * (1 - f));
  double rgb[6][3] = {{val, t, p}, {q, val, p}, {p, val, t}, {p, q, val}, {t, p, val}, {val, p, q}};
  const double* c = rgb[sector % 6];
  return {static_cast<uint8_t>(std::lround(c[0] * 255)),
          static_cast<uint8_t>(std::lround(c[1] * 255)),
          static_cast<uint8_t>(std::lround(c[2] * 255))};
}

std::string EncodePng(int width, int height, int channels, const uint8_t* pixels,
                      const PngCompression& compression) {
  const char* what = "encode_png";
  CheckSize(what, width, height);
  const int type = PngColorType(channels, what, "");
  return EncodePngRows(width, height, type, 8, channels, pixels, compression, what, "");
}

void WritePng(const std::string& path, int width, int height, int channels, const uint8_t* pixels,
              const PngCompression& compression) {
  const char* what = "write_png";
  const std::string where = " (writing '" + path + "')";
  CheckSize(what, width, height);
  const int type = PngColorType(channels, what, where);
  SaveFile(what, path,
           EncodePngRows(width, height, type, 8, channels, pixels, compression, what, where));
}

void WritePng16(const std::string& path, int width, int height, const uint16_t* pixels,
                const PngCompression& compression) {
  const char* what = "write_png16";
  CheckSize(what, width, height);
  SaveFile(what, path,
           EncodePngRows(width, height, PNG_COLOR_TYPE_GRAY, 16, 2,
                         reinterpret_cast<const uint8_t*>(pixels), compression, what,
                         " (writing '" + path + "')"));
}

void WriteColorPng(const std::string& path, const Picture& picture) {
  CheckPicture("write_color_png", picture, kColor);
  std::vector<uint8_t> rgba = ToRgba8(picture.color);
  WritePng(path, picture.width, picture.height, 4, rgba.data());
}

void WriteDepthPng(const std::string& path, int width, int height, const float* depth,
                   const PngCompression& compression) {
  CheckSize("write_depth_png", width, height);
  size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  std::vector<uint16_t> mm(n);
  for (size_t i = 0; i < n; ++i) {
    // millimetres, rounded; NaN and negative depths mean nothing was seen
    double v = depth[i] > 0 ? std::round(1000.0 * depth[i]) : 0.0;
    mm[i] = static_cast<uint16_t>(std::min(v, 65535.0));
  }
  WritePng16(path, width, height, mm.data(), compression);
}

void WriteDepthPng(const std::string& path, const Picture& picture) {
  CheckPicture("write_depth_png", picture, kPosition);
  std::vector<float> depth = DepthImage(picture);
  WriteDepthPng(path, picture.width, picture.height, depth.data());
}

void WriteNormalPng(const std::string& path, const Picture& picture) {
  CheckPicture("write_normal_png", picture, kNormal | kPosition);
  size_t n = static_cast<size_t>(picture.width) * static_cast<size_t>(picture.height);
  std::vector<uint8_t> rgb(3 * n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!(picture.position[4 * i + 3] > 0)) continue;
    for (size_t k = 0; k < 3; ++k) {
      float x = std::min(std::max(0.5f * (picture.normal[4 * i + k] + 1.0f), 0.0f), 1.0f);
      rgb[3 * i + k] = static_cast<uint8_t>(std::lround(x * 255.0f));
    }
  }
  WritePng(path, picture.width, picture.height, 3, rgb.data());
}

void WriteSegmentationPng(const std::string& path, int width, int height, const uint32_t* ids,
                          int stride) {
  CheckSize("write_segmentation_png", width, height);
  if (stride < 1)
    throw Error("write_segmentation_png: stride must be >= 1, got " + std::to_string(stride));
  size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  std::vector<uint8_t> rgb(3 * n);
  for (size_t i = 0; i < n; ++i) {
    std::array<uint8_t, 3> c = SegmentationColor(ids[i * stride]);
    std::copy(c.begin(), c.end(), rgb.begin() + 3 * i);
  }
  WritePng(path, width, height, 3, rgb.data());
}

void WriteSegmentationPng(const std::string& path, const Picture& picture, int channel) {
  CheckPicture("write_segmentation_png", picture, kSegmentation);
  if (channel != 0 && channel != 1)
    throw Error(
        "write_segmentation_png: channel must be 0 (visual ids) or 1 (actor/link ids), "
        "got " +
        std::to_string(channel));
  WriteSegmentationPng(path, picture.width, picture.height, picture.segmentation.data() + channel,
                       2);
}

void WritePly(const std::string& path, const PointCloud& cloud, bool binary) {
  const char* what = "write_ply";
  size_t n = cloud.Size();
  if (cloud.positions.size() != 3 * n)
    throw Error(std::string(what) + ": positions must hold 3 values per point, got " +
                std::to_string(cloud.positions.size()) + " (writing '" + path + "')");
  if (!cloud.colors.empty() && cloud.colors.size() != 4 * n)
    throw Error(std::string(what) + ": colors must hold 4 values per point (" + std::to_string(n) +
                " points), got " + std::to_string(cloud.colors.size()) + " (writing '" + path +
                "')");
  if (!cloud.visual_ids.empty() && cloud.visual_ids.size() != n)
    throw Error(std::string(what) + ": visual_ids must hold one id per point (" +
                std::to_string(n) + " points), got " + std::to_string(cloud.visual_ids.size()) +
                " (writing '" + path + "')");
  if (!cloud.entity_ids.empty() && cloud.entity_ids.size() != n)
    throw Error(std::string(what) + ": entity_ids must hold one id per point (" +
                std::to_string(n) + " points), got " + std::to_string(cloud.entity_ids.size()) +
                " (writing '" + path + "')");
  if (binary && !LittleEndian())
    throw Error(std::string(what) + ": binary PLY needs a little-endian machine");

  std::string bytes = std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") +
                      " 1.0\ncomment partsim point cloud\nelement vertex " + std::to_string(n) +
                      "\nproperty float x\nproperty float y\nproperty float z\n"
                      "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                      "property uchar alpha\nproperty uint visual_id\nproperty uint entity_id\n"
                      "end_header\n";
  // one record per point: 12 bytes of position, 4 of colour, 8 of ids
  bytes.reserve(bytes.size() + n * (binary ? 24 : 64));
  char record[24];
  for (size_t i = 0; i < n; ++i) {
    const float* p = cloud.positions.data() + 3 * i;
    uint8_t c[4] = {255, 255, 255, 255};
    if (!cloud.colors.empty()) std::memcpy(c, cloud.colors.data() + 4 * i, 4);
    uint32_t ids[2] = {cloud.visual_ids.empty() ? 0u : cloud.visual_ids[i],
                       cloud.entity_ids.empty() ? 0u : cloud.entity_ids[i]};
    if (binary) {
      std::memcpy(record, p, 12);
      std::memcpy(record + 12, c, 4);
      std::memcpy(record + 16, ids, 8);
      bytes.append(record, sizeof(record));
    } else {
      char line[160];
      const int n_chars = std::snprintf(line, sizeof(line), "%.9g %.9g %.9g %u %u %u %u %u %u\n",
                                        p[0], p[1], p[2], c[0], c[1], c[2], c[3], ids[0], ids[1]);
      bytes.append(line, static_cast<size_t>(n_chars));
    }
  }
  SaveFile(what, path, bytes);
}

void WriteNpy(const std::string& path, const float* data, const std::vector<size_t>& shape) {
  WriteNpyImpl(path, data, shape, "<f4");
}

void WriteNpy(const std::string& path, const uint32_t* data, const std::vector<size_t>& shape) {
  WriteNpyImpl(path, data, shape, "<u4");
}

}  // namespace partsim
