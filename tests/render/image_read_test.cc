// ReadPng reads back what WritePng wrote, converts between channel counts, and names the file
// in its errors.
#include "partsim/render/image_read.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

#include "partsim/core/error.h"
#include "partsim/render/image_io.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

class ImageReadTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("partsim_image_read_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

// partsim's own reader gives back what WritePng wrote, converting between channel counts.
TEST_F(ImageReadTest, ReadsWhatWritePngWrote) {
  const int w = 5, h = 3;
  std::vector<uint8_t> rgb(w * h * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<uint8_t>(i * 11);
  WritePng(Path("rgb.png"), w, h, 3, rgb.data());
  int rw = 0, rh = 0;
  EXPECT_EQ(ReadPng(Path("rgb.png"), 3, &rw, &rh), rgb);
  EXPECT_EQ(rw, w);
  EXPECT_EQ(rh, h);
  // an opaque alpha added
  const std::vector<uint8_t> rgba = ReadPng(Path("rgb.png"), 4, &rw, &rh);
  ASSERT_EQ(rgba.size(), static_cast<size_t>(w * h * 4));
  for (int i = 0; i < w * h; ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(rgba[4 * i + c], rgb[3 * i + c]);
    EXPECT_EQ(rgba[4 * i + 3], 255);
  }
  // grey, as it is and repeated into RGB
  const std::vector<uint8_t> grey = {0, 50, 100, 150, 200, 250};
  WritePng(Path("g.png"), 3, 2, 1, grey.data());
  EXPECT_EQ(ReadPng(Path("g.png"), 1, &rw, &rh), grey);
  const std::vector<uint8_t> grey_rgb = ReadPng(Path("g.png"), 3, &rw, &rh);
  for (size_t i = 0; i < grey.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(grey_rgb[3 * i + c], grey[i]);
  // a transparent pixel composited over black, an opaque one kept
  const std::vector<uint8_t> two = {200, 100, 50, 0, 10, 20, 30, 255};
  WritePng(Path("a.png"), 2, 1, 4, two.data());
  EXPECT_EQ(ReadPng(Path("a.png"), 3, &rw, &rh), (std::vector<uint8_t>{0, 0, 0, 10, 20, 30}));
  // errors name the file
  const std::vector<uint16_t> deep = {1, 2};
  WritePng16(Path("deep.png"), 2, 1, deep.data());
  std::ofstream(Path("text.png")) << "not a picture";
  for (const auto& [name, channels, what] : std::vector<std::tuple<std::string, int, std::string>>{
           {"missing.png", 3, "cannot open the file"},
           {"text.png", 3, "not a PNG"},
           {"deep.png", 1, "16-bit samples"},
           {"rgb.png", 2, "channels must be 1, 3 or 4"}}) {
    try {
      ReadPng(Path(name), channels, &rw, &rh);
      ADD_FAILURE() << name << ": no error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("read_png '" + Path(name) + "': " + what),
                std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace partsim
