// Helpers the backends share for pictures rendered with an output mask.
#pragma once

#include "partsim/render/backend.h"

namespace partsim::internal {

/// Empties (size 0, capacity kept) the outputs of `picture` that `outputs` (PictureOutput bits)
/// does not name, and records `outputs` in picture->outputs.
inline void KeepOutputs(unsigned outputs, Picture* picture) {
  if (!(outputs & kColor)) picture->color.clear();
  if (!(outputs & kAlbedo)) picture->albedo.clear();
  if (!(outputs & kNormal)) picture->normal.clear();
  if (!(outputs & kPosition)) picture->position.clear();
  if (!(outputs & kSegmentation)) picture->segmentation.clear();
  picture->outputs = outputs;
}

}  // namespace partsim::internal
