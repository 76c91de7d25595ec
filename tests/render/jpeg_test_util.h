// Writes small JPEG files for texture tests.
#pragma once

#include <jpeglib.h>

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace partsim::testing {

/// A width x height JPEG of one sRGB colour at quality 100; false if the file cannot be opened.
inline bool WriteSolidJpeg(const std::string& path, int width, int height, uint8_t r, uint8_t g,
                           uint8_t b) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  jpeg_compress_struct cinfo;
  jpeg_error_mgr err;
  cinfo.err = jpeg_std_error(&err);
  jpeg_create_compress(&cinfo);
  jpeg_stdio_dest(&cinfo, f);
  cinfo.image_width = width;
  cinfo.image_height = height;
  cinfo.input_components = 3;
  cinfo.in_color_space = JCS_RGB;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, 100, TRUE);
  jpeg_start_compress(&cinfo, TRUE);
  std::vector<uint8_t> row;
  for (int x = 0; x < width; ++x) row.insert(row.end(), {r, g, b});
  while (cinfo.next_scanline < static_cast<JDIMENSION>(height)) {
    JSAMPROW p = row.data();
    jpeg_write_scanlines(&cinfo, &p, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  std::fclose(f);
  return true;
}

}  // namespace partsim::testing
