// Pictures read back from files: 8-bit PNG (libpng), as the dataset tools and tests read what
// WritePng (image_io.h) wrote, and PNG or JPEG as textures are read.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace partsim {

/// Largest picture ReadPng reads, in pixels: 2^26 (8192 x 8192).
constexpr long long kMaxReadPngPixels = 1ll << 26;

/// Reads an 8-bit PNG (grey, grey and alpha, RGB, RGBA or palette, any bit depth up to 8) as
/// `channels` 1 (grey), 3 (RGB) or 4 (RGBA) per pixel: row-major, top row first, width x
/// height x channels bytes; sets *width and *height (pixels). libpng converts between formats
/// (grey repeated into RGB, colour to grey by its luminance, an alpha channel dropped by
/// compositing over black, an opaque alpha added). Throws Error "read_png '<path>': ..." when
/// the file cannot be opened or decoded, is not a PNG, has 16-bit samples, or claims more than
/// kMaxReadPngPixels pixels (checked from its header, before the pixels are allocated), and
/// for `channels` other than 1, 3 or 4.
std::vector<std::uint8_t> ReadPng(const std::string& path, int channels, int* width, int* height);

/// Reads a PNG or JPEG file (recognised by its content, not its extension) as RGBA8 the way
/// textures are read: scaled down to at most 4096 pixels on a side; row-major, top row first,
/// width x height x 4 bytes; sets *width and *height. Throws Error naming the file when it is
/// missing, not a regular file, not a PNG or JPEG, or claims more pixels than partsim decodes
/// (checked from its header before the pixels are allocated).
std::vector<std::uint8_t> ReadImageRgba8(const std::string& path, int* width, int* height);

}  // namespace partsim
