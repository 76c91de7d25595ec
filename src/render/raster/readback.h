// The rasterizer's read-back: the targets a picture asked for, copied into its Picture.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/worker_pool.h"
#include "partsim/render/backend.h"
#include "render/gl_util.h"
#include "render/raster/passes.h"

namespace partsim::internal::raster {

/// Copies targets into pictures; the forward path's Position is rebuilt from the depth buffer on
/// worker threads.
class ReadBack {
 public:
  /// `xyz_position`: the G-buffer's Position is (x, y, z, -z) as the built-in shader writes it,
  /// so the deferred path reads x, y, z alone (three quarters of the bytes) and sets w here;
  /// false (custom G-buffer shaders) reads all four.
  explicit ReadBack(bool xyz_position = true) : xyz_position_(xyz_position) {}
  ReadBack(const ReadBack&) = delete;
  ReadBack& operator=(const ReadBack&) = delete;

  /// The outputs of the forward path: colour, and Position rebuilt from the depth buffer with
  /// `camera`'s projection. Throws partsim::Error when the GPU is out of memory.
  void Forward(const Targets& targets, const CameraParams& camera, unsigned outputs, Picture* out);
  /// The outputs of the deferred path asked for, from the G-buffer and colour targets. With
  /// `narrow_ids` (every id of the world below 65536) Segmentation comes back as 16-bit numbers,
  /// half the bytes, widened here. Throws partsim::Error when the GPU is out of memory.
  void Deferred(const Targets& targets, unsigned outputs, bool narrow_ids, Picture* out);

  // A run of pictures (RenderMany): each picture's targets are copied into pixel-pack buffers
  // as soon as it is drawn (Queue*), which the GL runs while the next picture is drawn; Collect
  // then copies them into the pictures. The pictures are those Forward and Deferred give.

  /// Forgets the pictures queued (the buffers stay, for the next run).
  void BeginQueue();
  /// Queues the forward path's outputs of the picture just drawn into `targets`.
  void QueueForward(const Targets& targets, const CameraParams& camera, unsigned outputs);
  /// Queues the deferred path's outputs of the picture just drawn into `targets`.
  void QueueDeferred(const Targets& targets, unsigned outputs, bool narrow_ids);
  /// Copies the queued picture `index` (in queue order) into `out`. Throws partsim::Error when
  /// the GPU is out of memory.
  void Collect(size_t index, Picture* out);
  /// Deletes the pixel-pack buffers (with the GL context current).
  void Delete();

 private:
  /// One target an output comes from, and how it is read.
  struct TargetRead {
    unsigned what = 0;  ///< a PictureOutput bit, or 0 for the forward path's depth
    GLuint fbo = 0;
    GLenum attachment = 0, format = 0, type = 0;
    size_t bytes_per_pixel = 0;
    bool narrow = false;  ///< Segmentation as 16-bit numbers, Position as x, y, z
  };
  /// One target of a queued picture, in a pixel-pack buffer.
  struct QueuedRead {
    unsigned what = 0;
    GLuint buffer = 0;
    size_t bytes = 0;
    bool narrow = false;
  };
  struct Queued {
    bool forward = false;
    CameraParams camera;
    unsigned outputs = 0;
    int width = 0, height = 0;
    std::vector<QueuedRead> reads;
  };
  /// The targets the deferred path's `outputs` are read from, in the order they are read.
  std::vector<TargetRead> DeferredReads(const Targets& targets, unsigned outputs,
                                        bool narrow_ids) const;
  /// Where the `n` pixels of output `what` are read to: the picture's buffer (sized here), the
  /// depth buffer, or the 16-bit buffer of narrow ids.
  void* Destination(unsigned what, bool narrow, size_t n, Picture* out);
  /// After a read into Destination: narrow ids widened, x, y, z positions spread to four.
  void Widen(unsigned what, bool narrow, size_t n, Picture* out);
  /// Reads `r` of `targets` into a pixel-pack buffer of the pool and records it in `q`.
  void Queue(const Targets& targets, const TargetRead& r, Queued* q);
  /// Position from the depth in window_depth_ (read back with `camera`), on the workers.
  void ConvertDepth(const CameraParams& camera, int width, int height, Picture* out);
  /// Part `part` of `parts` of the rows of that conversion, with the flipped projection `P`.
  void ConvertRows(const Eigen::Matrix4d& P, int width, int height, int part, int parts,
                   Picture* out) const;
  int ConversionParts(size_t n) const;
  static int ConversionWorkers();

  bool xyz_position_ = true;
  std::vector<float> window_depth_;   // forward path: the depth buffer read back
  std::vector<uint16_t> narrow_ids_;  // Segmentation read as 16-bit numbers
  WorkerPool conversion_workers_{ConversionWorkers()};
  std::vector<Queued> queued_;
  std::vector<std::pair<GLuint, size_t>> pool_;  ///< pixel-pack buffers and their sizes
  size_t pool_used_ = 0;                         ///< buffers of the pool the queue holds
};

}  // namespace partsim::internal::raster
