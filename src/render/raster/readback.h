// The rasterizer's read-back: the targets a picture asked for, copied into its Picture.
#pragma once

#include <cstddef>
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
  ReadBack() = default;
  ReadBack(const ReadBack&) = delete;
  ReadBack& operator=(const ReadBack&) = delete;

  /// The outputs of the forward path: colour, and Position rebuilt from the depth buffer with
  /// `camera`'s projection. Throws partsim::Error when the GPU is out of memory.
  void Forward(const Targets& targets, const CameraParams& camera, unsigned outputs, Picture* out);
  /// The outputs of the deferred path asked for, from the G-buffer and colour targets. Throws
  /// partsim::Error when the GPU is out of memory.
  void Deferred(const Targets& targets, unsigned outputs, Picture* out);

 private:
  int ConversionParts(size_t n) const;
  static int ConversionWorkers();

  std::vector<float> window_depth_;  // forward path: the depth buffer read back
  WorkerPool conversion_workers_{ConversionWorkers()};
};

}  // namespace partsim::internal::raster
