#include "partsim/render/image_io.h"

#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "partsim/render/camera.h"
#include "partsim/render/scene_render.h"
#include "render/render_test_util.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

struct PngImage {
  int width = 0, height = 0, bit_depth = 0, color_type = -1;
  std::vector<uint8_t> bytes;  // rows as stored, 16-bit samples big-endian
};

// reads a PNG back with libpng's classic API, no transformations
PngImage ReadPng(const std::string& path) {
  PngImage img;
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return img;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(f);
    return PngImage();
  }
  png_init_io(png, f);
  png_read_info(png, info);
  img.width = png_get_image_width(png, info);
  img.height = png_get_image_height(png, info);
  img.bit_depth = png_get_bit_depth(png, info);
  img.color_type = png_get_color_type(png, info);
  size_t rowbytes = png_get_rowbytes(png, info);
  img.bytes.resize(rowbytes * img.height);
  std::vector<png_bytep> rows(img.height);
  for (int r = 0; r < img.height; ++r) rows[r] = img.bytes.data() + r * rowbytes;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(f);
  return img;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class ImageIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("partsim_image_io_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // a picture from the plane backend: depth 2 m, colour 0.5, left column empty
  Picture PlanePicture(int w, int h) {
    SetRenderBackend(scene_, std::make_unique<testing::PlaneBackend>(2.0, 0.5f));
    camera_ = AddCamera(scene_, "c", w, h, 1.0, 0.1, 10.0);
    camera_.TakePicture();
    return camera_.GetPictureData();
  }

  fs::path dir_;
  Scene scene_;
  Camera camera_;
};

TEST_F(ImageIoTest, Png8RoundTrip) {
  const int w = 5, h = 3;
  std::vector<uint8_t> rgba(w * h * 4);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = static_cast<uint8_t>(i * 7);
  WritePng(Path("a.png"), w, h, 4, rgba.data());
  PngImage img = ReadPng(Path("a.png"));
  EXPECT_EQ(img.width, w);
  EXPECT_EQ(img.height, h);
  EXPECT_EQ(img.bit_depth, 8);
  EXPECT_EQ(img.color_type, PNG_COLOR_TYPE_RGBA);
  EXPECT_EQ(img.bytes, rgba);
  // grey
  std::vector<uint8_t> grey = {0, 50, 100, 150, 200, 250};
  WritePng(Path("g.png"), 3, 2, 1, grey.data());
  PngImage g = ReadPng(Path("g.png"));
  EXPECT_EQ(g.color_type, PNG_COLOR_TYPE_GRAY);
  EXPECT_EQ(g.bytes, grey);
}

// EncodePng gives the bytes WritePng writes, and with kFastPngCompression (the viewer's camera
// pictures) other bytes of the same pixels, for every channel count; sizes below 1 x 1 and other
// channel counts are refused.
TEST_F(ImageIoTest, EncodedPngDecodesToTheSamePixels) {
  const int w = 7, h = 5;
  const int types[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                       PNG_COLOR_TYPE_RGBA};
  for (int channels : {1, 2, 3, 4}) {
    std::vector<uint8_t> px(static_cast<size_t>(w) * h * channels);
    for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<uint8_t>(37 * i + channels);
    WritePng(Path("w.png"), w, h, channels, px.data());
    EXPECT_EQ(ReadFile(Path("w.png")), EncodePng(w, h, channels, px.data())) << channels;
    std::ofstream(Path("fast.png"), std::ios::binary)
        << EncodePng(w, h, channels, px.data(), kFastPngCompression);
    const PngImage back = ReadPng(Path("fast.png"));
    EXPECT_EQ(back.width, w);
    EXPECT_EQ(back.height, h);
    EXPECT_EQ(back.bit_depth, 8);
    EXPECT_EQ(back.color_type, types[channels - 1]);
    EXPECT_EQ(back.bytes, px) << channels << " channels";
  }
  const uint8_t one = 0;
  EXPECT_THROW(EncodePng(0, 1, 1, &one), Error);
  EXPECT_THROW(EncodePng(1, 1, 5, &one), Error);
  EXPECT_THROW(EncodePng(1, 1, 1, &one, PngCompression{10, 0}), Error);
}

// Files are written under a temporary name and renamed: nothing else is left in the folder, and
// a write that cannot land (the name is taken by a folder) fails naming the path, leaves the
// old content alone and removes its temporary.
TEST_F(ImageIoTest, WritesLandWholeOrNotAtAll) {
  std::vector<uint8_t> grey = {0, 50, 100, 150, 200, 250};
  WritePng(Path("g.png"), 3, 2, 1, grey.data());
  WritePng(Path("g.png"), 3, 2, 1, grey.data());  // over an older one
  fs::create_directories(dir_ / "taken.png" / "inside");
  try {
    WritePng(Path("taken.png"), 3, 2, 1, grey.data());
    ADD_FAILURE() << "a folder was overwritten";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("taken.png"), std::string::npos) << e.what();
  }
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"g.png", "taken.png"}));
  EXPECT_TRUE(fs::exists(dir_ / "taken.png" / "inside"));
  EXPECT_EQ(ReadPng(Path("g.png")).width, 3);
}

// Floats in [0, 1] to bytes: v * 255 rounded to the nearest (0.5 -> 127.5 -> 128), clipped
// outside [0, 1] (infinities too); a NaN is named by its index.
TEST(UnitFloatsToUint8Test, ScalesClipsAndRoundsAndNamesNaN) {
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> in = {0.0f,         0.5f,  1.0f, 0.25f, 1.0f / 255,
                                 127.4f / 255, -3.0f, 7.0f, -inf,  inf};
  EXPECT_EQ(UnitFloatsToUint8(in.data(), in.size()),
            (std::vector<uint8_t>{0, 128, 255, 64, 1, 127, 0, 255, 0, 255}));
  const std::vector<float> nan = {0.1f, 0.2f, std::nanf(""), 0.3f};
  try {
    UnitFloatsToUint8(nan.data(), nan.size());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("value 2 is NaN"), std::string::npos) << e.what();
  }
}

TEST_F(ImageIoTest, DepthPngIsSixteenBitMillimetres) {
  const int w = 4, h = 2;
  std::vector<float> depth = {0.0f, 1.0f, 0.0015f, 2.5004f, 70.0f, -1.0f, 0.25f, 65.535f};
  WriteDepthPng(Path("d.png"), w, h, depth.data());
  PngImage img = ReadPng(Path("d.png"));
  ASSERT_EQ(img.bit_depth, 16);
  EXPECT_EQ(img.color_type, PNG_COLOR_TYPE_GRAY);
  std::vector<int> mm;
  for (size_t i = 0; i < img.bytes.size(); i += 2)
    mm.push_back(img.bytes[i] << 8 | img.bytes[i + 1]);
  std::vector<int> expected = {0, 1000, 2, 2500, 65535, 0, 250, 65535};
  EXPECT_EQ(mm, expected);
}

TEST_F(ImageIoTest, PictureImagesAndSegmentationColours) {
  Picture p = PlanePicture(6, 4);
  WriteColorPng(Path("c.png"), p);
  WriteDepthPng(Path("d.png"), p);
  WriteNormalPng(Path("n.png"), p);
  WriteSegmentationPng(Path("s.png"), p, 1);
  PngImage c = ReadPng(Path("c.png"));
  ASSERT_EQ(c.bytes.size(), 6u * 4 * 4);
  EXPECT_EQ(c.bytes[4], 188);  // pixel (1, 0): sRGB of 0.5
  EXPECT_EQ(c.bytes[0], 0);    // pixel (0, 0): nothing
  PngImage d = ReadPng(Path("d.png"));
  EXPECT_EQ(d.bytes[2] << 8 | d.bytes[3], 2000);
  PngImage n = ReadPng(Path("n.png"));
  EXPECT_EQ(n.color_type, PNG_COLOR_TYPE_RGB);
  EXPECT_EQ(n.bytes[3 + 2], 255);  // +z normal
  EXPECT_EQ(n.bytes[3 + 0], 128);
  PngImage s = ReadPng(Path("s.png"));
  std::array<uint8_t, 3> three = SegmentationColor(3);
  EXPECT_EQ(s.bytes[3], three[0]);
  EXPECT_EQ(s.bytes[4], three[1]);
  EXPECT_EQ(s.bytes[5], three[2]);
  EXPECT_EQ(s.bytes[0] + s.bytes[1] + s.bytes[2], 0);  // background black
  // colours are deterministic, visible, and tell small ids apart
  EXPECT_EQ(SegmentationColor(0), (std::array<uint8_t, 3>{0, 0, 0}));
  std::set<std::array<uint8_t, 3>> seen;
  for (uint32_t id = 1; id <= 64; ++id) {
    std::array<uint8_t, 3> col = SegmentationColor(id);
    EXPECT_EQ(col, SegmentationColor(id));
    EXPECT_GE(std::max({col[0], col[1], col[2]}), 150);
    seen.insert(col);
  }
  EXPECT_EQ(seen.size(), 64u);
}

TEST_F(ImageIoTest, PointCloudInWorldProjectsBackToItsPixels) {
  Pose X_WC(Eigen::Vector3d(1, -1, 2),
            Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 1, 0.3).normalized())));
  SetRenderBackend(scene_, std::make_unique<testing::PlaneBackend>(2.0, 0.5f));
  Camera cam = AddCamera(scene_, "c", 8, 6, 1.0, 0.1, 10.0);
  cam.SetLocalPose(X_WC);
  cam.TakePicture();
  PointCloud camera_frame = MakePointCloud(cam, PointCloudFrame::kCamera);
  PointCloud world = MakePointCloud(cam, PointCloudFrame::kWorld);
  // one point per pixel that sees something: all but the left column
  ASSERT_EQ(world.Size(), 7u * 6);
  ASSERT_EQ(world.colors.size(), 4 * world.Size());
  ASSERT_EQ(world.entity_ids.size(), world.Size());
  EXPECT_EQ(camera_frame.Size(), world.Size());
  Eigen::Matrix3d K = cam.GetIntrinsicMatrix();
  Eigen::Matrix<double, 3, 4> Rt = cam.GetExtrinsicMatrix();
  size_t k = 0;
  for (int v = 0; v < 6; ++v) {
    for (int u = 1; u < 8; ++u, ++k) {
      Eigen::Vector3d p(world.positions[3 * k], world.positions[3 * k + 1],
                        world.positions[3 * k + 2]);
      Eigen::Vector3d uvw = K * Rt * p.homogeneous();
      EXPECT_NEAR(uvw.x() / uvw.z(), u, 1e-4);
      EXPECT_NEAR(uvw.y() / uvw.z(), v, 1e-4);
      EXPECT_NEAR(uvw.z(), 2.0, 1e-5);  // OpenCV depth = the picture's depth
      EXPECT_NEAR(camera_frame.positions[3 * k + 2], -2.0f, 1e-6f);
      EXPECT_EQ(world.visual_ids[k], 7u);
      EXPECT_EQ(world.entity_ids[k], 3u);
      EXPECT_EQ(world.colors[4 * k], 188);
    }
  }
  std::vector<float> depth = DepthImage(cam.GetPictureData());
  EXPECT_EQ(depth[0], 0.0f);
  EXPECT_EQ(depth[1], 2.0f);
}

TEST_F(ImageIoTest, PlyHeaderAndCounts) {
  Picture p = PlanePicture(5, 3);
  PointCloud cloud = MakePointCloud(p);
  ASSERT_EQ(cloud.Size(), 4u * 3);
  WritePly(Path("b.ply"), cloud, true);
  WritePly(Path("a.ply"), cloud, false);
  std::string b = ReadFile(Path("b.ply"));
  std::string header_end = "end_header\n";
  size_t end = b.find(header_end);
  ASSERT_NE(end, std::string::npos);
  std::string header = b.substr(0, end + header_end.size());
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(header.find("element vertex 12\n"), std::string::npos);
  for (const char* prop : {"float x", "float y", "float z", "uchar red", "uchar green",
                           "uchar blue", "uchar alpha", "uint visual_id", "uint entity_id"})
    EXPECT_NE(header.find(std::string("property ") + prop + "\n"), std::string::npos) << prop;
  // 12 records of 3 floats, 4 bytes and 2 uints
  EXPECT_EQ(b.size() - header.size(), 12u * 24);
  float z;
  std::memcpy(&z, b.data() + header.size() + 8, 4);
  EXPECT_FLOAT_EQ(z, -2.0f);
  uint32_t entity;
  std::memcpy(&entity, b.data() + header.size() + 20, 4);
  EXPECT_EQ(entity, 3u);
  // ASCII: one line per point after the header
  std::string a = ReadFile(Path("a.ply"));
  EXPECT_NE(a.find("format ascii 1.0"), std::string::npos);
  std::string body = a.substr(a.find(header_end) + header_end.size());
  EXPECT_EQ(std::count(body.begin(), body.end(), '\n'), 12);
  std::istringstream first(body);
  double x, y, zz;
  int r, g, bb, al, vid, eid;
  first >> x >> y >> zz >> r >> g >> bb >> al >> vid >> eid;
  EXPECT_DOUBLE_EQ(zz, -2.0);
  EXPECT_EQ(r, 188);
  EXPECT_EQ(al, 255);
  EXPECT_EQ(vid, 7);
  EXPECT_EQ(eid, 3);
  // inconsistent arrays are refused
  cloud.entity_ids.pop_back();
  EXPECT_THROW(WritePly(Path("bad.ply"), cloud), Error);
}

TEST_F(ImageIoTest, NpyHeader) {
  std::vector<float> values = {1, 2, 3, 4, 5, 6};
  WriteNpy(Path("f.npy"), values.data(), {2, 3});
  std::string f = ReadFile(Path("f.npy"));
  ASSERT_GE(f.size(), 10u);
  EXPECT_EQ(f.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
  size_t header_len = static_cast<uint8_t>(f[8]) | static_cast<uint8_t>(f[9]) << 8;
  EXPECT_EQ((10 + header_len) % 64, 0u);
  std::string header = f.substr(10, header_len);
  EXPECT_NE(header.find("'descr': '<f4'"), std::string::npos) << header;
  EXPECT_NE(header.find("'fortran_order': False"), std::string::npos);
  EXPECT_NE(header.find("'shape': (2, 3)"), std::string::npos) << header;
  EXPECT_EQ(header.back(), '\n');
  ASSERT_EQ(f.size(), 10 + header_len + 6 * 4);
  float last;
  std::memcpy(&last, f.data() + f.size() - 4, 4);
  EXPECT_EQ(last, 6.0f);
  // uint32, one dimension
  std::vector<uint32_t> ids = {1, 2, 3};
  WriteNpy(Path("u.npy"), ids.data(), {3});
  std::string u = ReadFile(Path("u.npy"));
  EXPECT_NE(u.find("'descr': '<u4'"), std::string::npos);
  EXPECT_NE(u.find("'shape': (3,)"), std::string::npos);
}

TEST_F(ImageIoTest, ErrorsNameThePath) {
  std::vector<uint8_t> px(4, 0);
  std::string bad = Path("no_such_dir/x.png");
  for (auto f : std::vector<std::function<void()>>{
           [&] { WritePng(bad, 1, 1, 4, px.data()); },
           [&] { WritePly(bad, PointCloud()); },
           [&] { WriteNpy(bad, reinterpret_cast<const float*>(px.data()), {1}); },
       }) {
    try {
      f();
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(WritePng(Path("x.png"), 1, 1, 5, px.data()), Error);
  EXPECT_THROW(WritePng(Path("x.png"), 0, 1, 4, px.data()), Error);
}

}  // namespace
}  // namespace partsim
