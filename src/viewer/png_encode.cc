#include "viewer/png_encode.h"

#include <zlib.h>

#include <vector>

#include "partsim/core/error.h"

namespace partsim::internal {

namespace {

void PutU32(std::string* out, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8)
    out->push_back(static_cast<char>((v >> shift) & 255));
}

// a chunk: length, type, data, and the CRC of type and data
void PutChunk(std::string* out, const char* type, const std::string& data) {
  PutU32(out, static_cast<uint32_t>(data.size()));
  const size_t at = out->size();
  out->append(type, 4);
  out->append(data);
  const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(out->data() + at), 4 + data.size());
  PutU32(out, static_cast<uint32_t>(crc));
}

}  // namespace

std::string EncodePng(int width, int height, int channels, const uint8_t* pixels) {
  if (width < 1 || height < 1)
    throw Error("EncodePng: size must be at least 1 x 1, got " + std::to_string(width) + " x " +
                std::to_string(height));
  if (channels != 1 && channels != 3 && channels != 4)
    throw Error("EncodePng: channels must be 1, 3 or 4, got " + std::to_string(channels));
  // each row: filter byte 0 (None), then its samples
  const size_t row = static_cast<size_t>(width) * channels;
  std::vector<uint8_t> raw((row + 1) * height);
  for (int y = 0; y < height; ++y) {
    raw[y * (row + 1)] = 0;
    std::copy(pixels + y * row, pixels + (y + 1) * row, raw.begin() + y * (row + 1) + 1);
  }
  uLongf packed_size = compressBound(raw.size());
  std::string packed(packed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(&packed[0]), &packed_size, raw.data(), raw.size(), 1) !=
      Z_OK)
    throw Error("EncodePng: zlib failed");
  packed.resize(packed_size);

  std::string out("\x89PNG\r\n\x1a\n", 8);
  std::string ihdr;
  PutU32(&ihdr, static_cast<uint32_t>(width));
  PutU32(&ihdr, static_cast<uint32_t>(height));
  const char color_type = channels == 1 ? 0 : channels == 3 ? 2 : 6;
  ihdr += std::string{8, color_type, 0, 0, 0};  // depth, colour type, deflate, filter, no interlace
  PutChunk(&out, "IHDR", ihdr);
  PutChunk(&out, "IDAT", packed);
  PutChunk(&out, "IEND", "");
  return out;
}

}  // namespace partsim::internal
