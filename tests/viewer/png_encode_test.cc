// The viewer's PNG encoder, read back with libpng (ReadPng).
#include "viewer/png_encode.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "partsim/core/error.h"
#include "partsim/render/image_read.h"

namespace partsim::internal {
namespace {

TEST(ViewerPngTest, EncodedPixelsDecodeToTheSame) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("partsim_png_encode_" + std::to_string(getpid()) + ".png"))
                               .string();
  for (int channels : {1, 3, 4}) {
    const int w = 7, h = 5;
    std::vector<uint8_t> px(static_cast<size_t>(w) * h * channels);
    for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<uint8_t>(37 * i + channels);
    std::ofstream(path, std::ios::binary) << EncodePng(w, h, channels, px.data());
    int rw = 0, rh = 0;
    const std::vector<uint8_t> back = ReadPng(path, channels == 1 ? 1 : channels, &rw, &rh);
    EXPECT_EQ(rw, w);
    EXPECT_EQ(rh, h);
    EXPECT_EQ(back, px) << channels << " channels";
  }
  std::filesystem::remove(path);
  const uint8_t one = 0;
  EXPECT_THROW(EncodePng(0, 1, 1, &one), Error);
  EXPECT_THROW(EncodePng(1, 1, 2, &one), Error);
}

}  // namespace
}  // namespace partsim::internal
