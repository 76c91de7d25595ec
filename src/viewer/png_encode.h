// PNG files in memory (the viewer's camera pictures), written with zlib alone.
#pragma once

#include <cstdint>
#include <string>

namespace partsim::internal {

/// The bytes of a PNG of `width` x `height` pixels with `channels` 1 (grey), 3 (RGB) or 4 (RGBA)
/// 8-bit samples: row-major, top row first. Rows are not filtered and deflated at zlib level 1
/// (fast: pictures go to a browser on this machine or a nearby one). Throws partsim::Error for a
/// size < 1 or other channel counts.
std::string EncodePng(int width, int height, int channels, const uint8_t* pixels);

}  // namespace partsim::internal
