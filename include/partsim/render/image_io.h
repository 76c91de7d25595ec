// Pictures to files and point clouds: depth images in metres, point clouds in the camera or the
// world frame with colours and segmentation ids, PNG (8-bit colour, 16-bit depth, indexed
// segmentation colours), PLY and NPY. Every writer throws partsim::Error naming the path when the
// file cannot be written.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/render/backend.h"

namespace partsim {

class Camera;

/// Depth image (h x w, row-major, metres along the view axis), 0 where no surface is seen.
std::vector<float> DepthImage(const Picture& picture);

/// Frame of point cloud positions: the OpenGL camera frame (x right, y up, z backward) of the
/// picture, or the world.
enum class PointCloudFrame { kCamera, kWorld };

/// Points seen by a camera: one per pixel that sees a surface, in row-major pixel order.
struct PointCloud {
  std::vector<float> positions;      ///< N x 3 (m)
  std::vector<uint8_t> colors;       ///< N x 4 RGBA, sRGB-encoded colour; empty for none
  std::vector<uint32_t> visual_ids;  ///< N visual ids (segmentation channel 0); empty for none
  std::vector<uint32_t> entity_ids;  ///< N actor or link ids (channel 1); empty for none
  /// Number of points.
  size_t Size() const { return positions.size() / 3; }
};

/// Point cloud of a picture. With kWorld, `X_WC` (partsim camera convention: x forward, y left,
/// z up) places the camera in the world; it is ignored with kCamera.
PointCloud MakePointCloud(const Picture& picture, PointCloudFrame frame = PointCloudFrame::kCamera,
                          const Pose& X_WC = Pose());
/// Point cloud of a camera's last picture, placed with the pose the picture was taken from.
PointCloud MakePointCloud(const Camera& camera, PointCloudFrame frame = PointCloudFrame::kCamera);

/// sRGB 8-bit encoding of linear RGBA floats (clamped to [0, 1]; alpha stays linear).
std::vector<uint8_t> ToRgba8(const std::vector<float>& rgba);

/// 8-bit values of floats in [0, 1] (an image in numpy's float convention): each clipped to
/// [0, 1], times 255, rounded to the nearest; no transfer curve. Throws partsim::Error naming the
/// index of the first NaN.
std::vector<uint8_t> UnitFloatsToUint8(const float* values, size_t count);

/// Colour of a segmentation id: black for 0 (background), else a fixed bright colour that
/// depends only on the id (so images of several views and runs agree).
std::array<uint8_t, 3> SegmentationColor(uint32_t id);

/// How a PNG writer compresses: the same pixels whatever the choice, only the file's size and
/// the time to write it change. The default is libpng's: zlib level 6 and a row filter chosen
/// per row among the five (the smallest files; trying every filter on every row is most of the
/// time of writing a 512 x 512 picture). Level 1 with rows not filtered ({1, 0}) writes a
/// rendered picture about five times faster, in a file 1.5 to 2 times larger.
struct PngCompression {
  int level = -1;  ///< zlib level, 0 (stored) to 9 (smallest); -1: zlib's default (6)
  /// The row filter of every row, by its PNG number (0 None, 1 Sub, 2 Up, 3 Average, 4 Paeth);
  /// -1: libpng's choice per row.
  int filter = -1;
};

/// Fast compression for pictures that go to a browser at once (the viewer's camera pictures):
/// zlib level 1, rows not filtered.
constexpr PngCompression kFastPngCompression{1, 0};

/// The bytes of an 8-bit PNG, the file WritePng writes: `channels` 1 (grey), 2 (grey, alpha),
/// 3 (RGB) or 4 (RGBA), row-major pixels, top row first, width x height x channels bytes. Throws
/// partsim::Error for a size below 1 x 1, other channel counts, and a `compression` level
/// outside [-1, 9] or filter outside [-1, 4].
std::string EncodePng(int width, int height, int channels, const uint8_t* pixels,
                      const PngCompression& compression = PngCompression());

/// 8-bit PNG with `channels` 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA): row-major pixels,
/// top row first, width x height x channels bytes. Throws partsim::Error for a `compression`
/// level outside [-1, 9] or filter outside [-1, 4].
void WritePng(const std::string& path, int width, int height, int channels, const uint8_t* pixels,
              const PngCompression& compression = PngCompression());
/// 16-bit greyscale PNG (width x height values).
void WritePng16(const std::string& path, int width, int height, const uint16_t* pixels,
                const PngCompression& compression = PngCompression());

/// The picture's colour as an 8-bit sRGB RGBA PNG.
void WriteColorPng(const std::string& path, const Picture& picture);
/// Depth (width x height, metres, 0 = nothing) as a 16-bit PNG in millimetres, rounded and
/// clamped to 65535; 0 stays 0.
void WriteDepthPng(const std::string& path, int width, int height, const float* depth,
                   const PngCompression& compression = PngCompression());
void WriteDepthPng(const std::string& path, const Picture& picture);
/// The picture's camera-frame normals as an RGB PNG: (n + 1) / 2 per channel; black where
/// nothing is seen.
void WriteNormalPng(const std::string& path, const Picture& picture);
/// Segmentation ids (width x height values, `stride` apart) in the colours of
/// SegmentationColor; background black.
void WriteSegmentationPng(const std::string& path, int width, int height, const uint32_t* ids,
                          int stride = 1);
/// One channel of the picture's segmentation: 0 visual ids, 1 actor / link ids.
void WriteSegmentationPng(const std::string& path, const Picture& picture, int channel = 1);

/// PLY with vertex properties x y z (float), red green blue alpha (uchar), visual_id and
/// entity_id (uint); binary little-endian or ASCII. Missing colours are written white, missing
/// ids 0. Throws if the arrays of `cloud` disagree in length.
void WritePly(const std::string& path, const PointCloud& cloud, bool binary = true);

/// NumPy .npy (format 1.0, C order) of float32 or uint32 values with the given shape; the
/// product of `shape` must equal the number of values.
void WriteNpy(const std::string& path, const float* data, const std::vector<size_t>& shape);
void WriteNpy(const std::string& path, const uint32_t* data, const std::vector<size_t>& shape);

}  // namespace partsim
