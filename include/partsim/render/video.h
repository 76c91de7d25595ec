// Videos from pictures: MP4 (H.264 through FFmpeg's libraries) written frame by frame.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>

#include "partsim/render/backend.h"

namespace partsim {

/// Settings of a VideoWriter.
struct VideoOptions {
  double fps = 25.0;  ///< frames per second, in (0, 1000]
  /// Constant rate factor of H.264: 0 lossless, 18 visually lossless, 23 the encoder's default,
  /// 51 worst.
  int quality = 20;
  /// Linear RGB that transparent pixels of a picture are composited over (alpha blending in
  /// sRGB, as a viewer shows a PNG over a background).
  Eigen::Vector3f background = Eigen::Vector3f(0.80f, 0.84f, 0.90f);
};

/// An MP4 file written frame by frame: H.264 in yuv420p (played by browsers, VLC and every
/// desktop player), or MPEG-4 part 2 where the H.264 encoder is missing. Frames are width x
/// height; an odd width or height loses its last column or row (yuv420p needs even sizes).
///
/// The video goes to `path`.partial and is renamed to `path` by Close() (or the destructor), so
/// `path` is there whole or not at all. Throws partsim::Error naming the path on bad arguments
/// and on encoder or file errors.
class VideoWriter {
 public:
  VideoWriter(const std::string& path, int width, int height, const VideoOptions& options = {});
  /// Finishes the file as Close() does; errors are written to stderr (a destructor cannot
  /// throw).
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  /// Appends a frame of 8-bit sRGB pixels, top row first: `channels` 3 (RGB) or 4 (RGBA,
  /// composited over the background), width x height x channels bytes.
  void AddFrame(const uint8_t* pixels, int channels);
  /// Throws partsim::Error unless a frame of width x height fits this video.
  void CheckFrameSize(int width, int height) const;
  /// Appends the picture's Color output (its size must be the video's).
  void AddFrame(const Picture& picture);
  /// Flushes the encoder, writes the index and renames the file into place. Further frames
  /// throw; a second Close does nothing.
  void Close();

  /// Frames added so far.
  int FrameCount() const;
  /// The encoder's name ("libx264" or "mpeg4").
  std::string Codec() const;
  /// Final path of the video.
  const std::string& Path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace partsim
