// ReadPng: 8-bit PNG files read with libpng's simplified API; ReadImageRgba8: PNG or JPEG through
// the texture loader (partsim/render/image_read.h).
#include "partsim/render/image_read.h"

#include <png.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <utility>

#include "partsim/core/error.h"
#include "render/gl_util.h"

namespace partsim {

std::vector<std::uint8_t> ReadPng(const std::string& path, int channels, int* width, int* height) {
  const std::string what = "read_png '" + path + "'";
  png_uint_32 format = 0;
  switch (channels) {
    case 1:
      format = PNG_FORMAT_GRAY;
      break;
    case 3:
      format = PNG_FORMAT_RGB;
      break;
    case 4:
      format = PNG_FORMAT_RGBA;
      break;
    default:
      throw Error(what + ": channels must be 1, 3 or 4, got " + std::to_string(channels));
  }
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) throw Error(what + ": cannot open the file: " + std::strerror(errno));
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_stdio(&image, file.get()))
    throw Error(what + ": not a PNG picture libpng can read (" + image.message + ")");
  // 16-bit samples would be read as linear light and re-encoded; the header's size is checked
  // before the pixels are allocated (a tiny file can claim 2^31 x 2^31)
  const bool linear = (image.format & PNG_FORMAT_FLAG_LINEAR) != 0;
  const long long pixels = static_cast<long long>(image.width) * image.height;
  if (linear || pixels > kMaxReadPngPixels) {
    png_image_free(&image);
    throw Error(what + (linear ? ": 16-bit samples; read_png reads 8-bit PNGs"
                               : ": " + std::to_string(image.width) + " x " +
                                     std::to_string(image.height) + " pixels is more than " +
                                     std::to_string(kMaxReadPngPixels) + " pixels"));
  }
  image.format = format;
  std::vector<std::uint8_t> out(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.data(), 0, nullptr)) {
    const std::string message = image.message;
    png_image_free(&image);
    throw Error(what + ": cannot decode: " + message);
  }
  *width = static_cast<int>(image.width);
  *height = static_cast<int>(image.height);
  return out;
}

std::vector<std::uint8_t> ReadImageRgba8(const std::string& path, int* width, int* height) {
  internal::Image8 image = internal::LoadImageRgba8(path);
  *width = image.width;
  *height = image.height;
  return std::move(image.rgba);
}

}  // namespace partsim
