// Files a careless or hostile user may hand to partsim: device files, FIFOs, symbolic links to
// them, decompression bombs, JSON nested 100k deep, and physics numbers that overflow. Each gets
// an error naming the file and what it is (or a warning and a safe value), never a hang, a crash
// or an exhausted memory.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/file_read.h"
#include "partsim/assets/mesh.h"
#include "partsim/assets/scene_file.h"
#include "partsim/assets/urdf.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"
#include "partsim/robot/controllers.h"
#include "render/gl_util.h"
#include "render/jpeg_test_util.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

class UntrustedFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("partsim_untrusted_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  std::string Write(const std::string& name, const std::string& bytes) const {
    std::ofstream(Path(name), std::ios::binary) << bytes;
    return Path(name);
  }
  fs::path dir_;
};

template <class F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// ---- files that are not files ----

TEST_F(UntrustedFilesTest, DevicesFifosAndLinksToThemAreRefusedNamingWhatTheyAre) {
  fs::create_symlink("/dev/zero", Path("robot.urdf"));
  ASSERT_EQ(::mkfifo(Path("pipe.urdf").c_str(), 0600), 0);
  UrdfLoader loader;
  std::string e = ErrorOf([&] { loader.ParseFile("/dev/zero"); });
  EXPECT_NE(e.find("URDF /dev/zero: is a character device, not a regular file"), std::string::npos)
      << e;
  e = ErrorOf([&] { loader.ParseFile(Path("robot.urdf")); });
  EXPECT_NE(e.find("is a character device"), std::string::npos) << e;
  e = ErrorOf([&] { loader.ParseFile(Path("pipe.urdf")); });  // would block on open
  EXPECT_NE(e.find("is a FIFO"), std::string::npos) << e;
  e = ErrorOf([&] { loader.ParseFile(dir_.string()); });
  EXPECT_NE(e.find("is a folder"), std::string::npos) << e;
  e = ErrorOf([&] { internal::LoadImageRgba8("/dev/zero"); });
  EXPECT_NE(e.find("texture /dev/zero: is a character device"), std::string::npos) << e;
  e = ErrorOf([&] { internal::LoadImageRgba8(Path("pipe.urdf")); });
  EXPECT_NE(e.find("is a FIFO"), std::string::npos) << e;
  fs::create_symlink("/dev/zero", Path("scene.json"));
  Scene scene;
  e = ErrorOf([&] { AddSceneObjects(&scene, Path("scene.json"), Pose(), true); });
  EXPECT_NE(e.find("is a character device"), std::string::npos) << e;
}

TEST_F(UntrustedFilesTest, MeshPathsThatAreNoFilesSayWhatTheyAreWithoutOpeningThem) {
  fs::create_symlink("/dev/zero", Path("zero.stl"));
  ASSERT_EQ(::mkfifo(Path("pipe.stl").c_str(), 0600), 0);  // opening it would block
  fs::create_symlink(Path("loop_b.stl"), Path("loop_a.stl"));
  fs::create_symlink(Path("loop_a.stl"), Path("loop_b.stl"));
  std::string urdf = "<robot name=\"r\"><link name=\"a\">";
  for (const char* mesh : {"/dev/zero", "zero.stl", "pipe.stl", "loop_a.stl"})
    urdf += std::string("<visual><geometry><mesh filename=\"") + mesh + "\"/></geometry></visual>";
  urdf += "</link></robot>";
  UrdfLoader loader;
  const std::string e = ErrorOf([&] { loader.Parse(urdf, dir_.string()); });
  EXPECT_NE(e.find("'/dev/zero' ('/dev/zero') is a character device, not a mesh file"),
            std::string::npos)
      << e;
  EXPECT_NE(
      e.find("'zero.stl' ('" + Path("zero.stl") + "') is a character device, not a mesh file"),
      std::string::npos)
      << e;
  EXPECT_NE(
      e.find("'pipe.stl' ('" + Path("pipe.stl") + "') is a FIFO (named pipe), not a mesh file"),
      std::string::npos)
      << e;
  EXPECT_NE(e.find("'loop_a.stl' ('" + Path("loop_a.stl") +
                   "') is a symbolic link loop, not a mesh file"),
            std::string::npos)
      << e;
  EXPECT_EQ(e.find("not found"), std::string::npos) << e;
  // the mesh reader itself says the same
  EXPECT_NE(ErrorOf([&] { LoadMeshFile(Path("loop_a.stl")); }).find("is a symbolic link loop"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { LoadMeshFile(Path("pipe.stl")); }).find("is a FIFO"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { LoadMeshFile("/dev/zero"); }).find("is a character device"),
            std::string::npos);
}

TEST_F(UntrustedFilesTest, FilesOverTheSizeBoundAreRefusedBeforeReading) {
  const std::string p = Write("big.urdf", std::string(2048, ' '));
  std::string e = ErrorOf([&] { internal::ReadWholeFile(p, "URDF", 1024); });
  EXPECT_NE(e.find("more than the 0 MB partsim reads"), std::string::npos) << e;
  EXPECT_EQ(internal::ReadWholeFile(p, "URDF", 4096).size(), 2048u);
}

// ---- decompression bombs ----

// CRC-32 of PNG chunks (ISO 3309, reflected polynomial 0xEDB88320).
uint32_t Crc32(const std::string& bytes) {
  uint32_t c = 0xFFFFFFFFu;
  for (unsigned char b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return c ^ 0xFFFFFFFFu;
}

// A PNG of a signature and an IHDR chunk claiming width x height, then an empty IDAT and IEND.
std::string PngClaiming(uint32_t width, uint32_t height) {
  auto be32 = [](uint32_t v) {
    return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                       static_cast<char>(v >> 8), static_cast<char>(v)};
  };
  auto chunk = [&](const std::string& type, const std::string& data) {
    std::string body = type + data;
    return be32(static_cast<uint32_t>(data.size())) + body + be32(Crc32(body));
  };
  const std::string ihdr = be32(width) + be32(height) + std::string{8, 6, 0, 0, 0};
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", "") +
         chunk("IEND", "");
}

TEST_F(UntrustedFilesTest, APngClaimingHugeSizeIsRefusedFromItsHeader) {
  const std::string p = Write("bomb.png", PngClaiming(16000, 16000));
  EXPECT_LT(fs::file_size(p), 100u);
  std::string e = ErrorOf([&] { internal::LoadImageRgba8(p); });
  EXPECT_NE(e.find("PNG of 16000x16000 pixels is larger than partsim decodes"), std::string::npos)
      << e;
}

TEST_F(UntrustedFilesTest, AJpegClaimingHugeSizeIsRefusedAndALargeOneComesScaledDown) {
  // a real 16x16 JPEG whose frame header is changed to claim 65000 x 65000
  const std::string small = Path("small.jpg");
  ASSERT_TRUE(testing::WriteSolidJpeg(small, 16, 16, 200, 30, 10));
  std::ifstream in(small, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t sof = bytes.find("\xFF\xC0");
  ASSERT_NE(sof, std::string::npos);
  for (size_t k : {sof + 5, sof + 7}) {  // height, then width, big-endian
    bytes[k] = static_cast<char>(65000 >> 8);
    bytes[k + 1] = static_cast<char>(65000 & 0xff);
  }
  const std::string bomb = Write("bomb.jpg", bytes);
  std::string e = ErrorOf([&] { internal::LoadImageRgba8(bomb); });
  EXPECT_NE(e.find("JPEG of 65000x65000 pixels is larger than partsim decodes"), std::string::npos)
      << e;
  // a genuine 5000 x 40 JPEG decodes at half scale: within the texture side
  const std::string wide = Path("wide.jpg");
  ASSERT_TRUE(testing::WriteSolidJpeg(wide, 5000, 40, 10, 200, 30));
  internal::Image8 img = internal::LoadImageRgba8(wide);
  EXPECT_EQ(img.width, 2500);
  EXPECT_EQ(img.height, 20);
  EXPECT_NEAR(img.rgba[1], 200, 3);
}

TEST(DownscaleToFitTest, AveragesBlocksByTheSmallestWholeFactor) {
  internal::Image8 in;
  in.width = 9;
  in.height = 3;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 9; ++x)
      in.rgba.insert(in.rgba.end(), {static_cast<uint8_t>(x * 10), 0, 0, 255});
  internal::Image8 out = internal::DownscaleToFit(in, 4);  // factor 3
  ASSERT_EQ(out.width, 3);
  ASSERT_EQ(out.height, 1);
  EXPECT_EQ(out.rgba[0], 10);  // mean of 0, 10, 20
  EXPECT_EQ(out.rgba[4], 40);
  EXPECT_EQ(out.rgba[8], 70);
  EXPECT_EQ(internal::DownscaleToFit(in, 9).width, 9);  // fits: unchanged
}

// ---- JSON nested too deep ----

TEST_F(UntrustedFilesTest, ASceneFileNested100kDeepIsRefused) {
  const std::string deep = std::string(100000, '[') + "0" + std::string(100000, ']');
  const std::string p =
      Write("deep.json",
            "{\"objects\": [{\"path\": \"x.urdf\", \"pose\": {\"position\": " + deep + "}}]}");
  Scene scene;
  std::string e = ErrorOf([&] { AddSceneObjects(&scene, p, Pose(), true); });
  EXPECT_NE(e.find("nested deeper than 64 levels"), std::string::npos) << e.substr(0, 300);
  EXPECT_LT(e.size(), 1000u);  // the message does not dump the value
  EXPECT_TRUE(scene.GetArticulations().empty());
}

// ---- numbers that overflow the physics ----

TEST(UntrustedPhysicsTest, HugeOriginsAndSizesAreRefusedNamingTheElement) {
  const std::string box_1e300 =
      "<robot name=\"r\"><link name=\"a\"><collision><geometry><box size=\"1e300 1 1\"/>"
      "</geometry></collision></link></robot>";
  Scene scene;
  UrdfLoader loader(&scene);
  std::string e = ErrorOf([&] { loader.LoadFromString(box_1e300, "."); });
  EXPECT_NE(e.find("half_size must be > 0 and at most 1e6 m"), std::string::npos) << e;
  const std::string origin_1e308 =
      "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"><collision><geometry>"
      "<sphere radius=\"0.1\"/></geometry></collision></link>"
      "<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>"
      "<origin xyz=\"1e308 0 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>"
      "</joint></robot>";
  e = ErrorOf([&] { loader.LoadFromString(origin_1e308, "."); });
  EXPECT_NE(e.find("beyond 1e6 m"), std::string::npos) << e;
  EXPECT_TRUE(scene.GetArticulations().empty());
  // the scene is still usable
  ActorDesc box;
  box.name = "box";
  CollisionShape s;
  s.type = ShapeType::kBox;
  s.half_size = Eigen::Vector3d(0.1, 0.1, 0.1);
  box.collisions.push_back(s);
  box.pose = Pose(Eigen::Vector3d(2e6, 0, 0));
  e = ErrorOf([&] { scene.AddActor(box); });
  EXPECT_NE(e.find("actor 'box' pose has a position beyond 1e6 m"), std::string::npos) << e;
  box.pose = Pose(Eigen::Vector3d(0, 0, 1));
  scene.AddActor(box);
  scene.Step(10);
  EXPECT_TRUE(scene.GetActors()[0].GetPose().p.allFinite());
}

// A URDF link of mass `mass` and inertia `ixx` about each axis, with a box to land on.
std::string HeavyLinkUrdf(const std::string& mass, const std::string& ixx) {
  return "<robot name=\"r\"><link name=\"heavy\"><inertial><mass value=\"" + mass +
         "\"/><inertia ixx=\"" + ixx + "\" ixy=\"0\" ixz=\"0\" iyy=\"" + ixx +
         "\" iyz=\"0\" izz=\"" + ixx +
         "\"/></inertial><collision><geometry><box size=\"1 1 1\"/></geometry></collision>"
         "</link></robot>";
}

TEST(UntrustedPhysicsTest, HugeMassesAndInertiasAreRefusedNamingTheElement) {
  Scene scene;
  UrdfLoader loader(&scene);
  std::string e = ErrorOf([&] { loader.LoadFromString(HeavyLinkUrdf("1e308", "1"), "."); });
  EXPECT_NE(e.find("link 'heavy' <inertial> <mass value> is 1e+308 kg, beyond the 1e9 kg partsim "
                   "simulates"),
            std::string::npos)
      << e;
  e = ErrorOf([&] { loader.LoadFromString(HeavyLinkUrdf("1", "1e308"), "."); });
  EXPECT_NE(e.find("link 'heavy' <inertial> <inertia> has an entry of 1e+308 kg m^2, beyond the "
                   "1e21 kg m^2"),
            std::string::npos)
      << e;
  // a scale that takes a mass past the bound says so
  loader.scale = 1e3;
  e = ErrorOf([&] { loader.LoadFromString(HeavyLinkUrdf("10", "1"), "."); });
  EXPECT_NE(e.find("<mass value> is 10000000000 kg after scaling"), std::string::npos) << e;
  loader.scale = 1.0;
  EXPECT_TRUE(scene.GetArticulations().empty());
  // descriptions built in code meet the same bound
  ActorDesc box;
  box.name = "box";
  box.inertial = Inertial();
  box.inertial->mass = 1e308;
  box.inertial->inertia = Eigen::Vector3d::Ones();
  e = ErrorOf([&] { scene.AddActor(box); });
  EXPECT_NE(e.find("actor 'box' mass must be at most 1e9 kg, got 1e+308"), std::string::npos) << e;
  // at the bounds the state stays finite
  Articulation art = loader.LoadFromString(HeavyLinkUrdf("1e9", "1e9"), ".");
  scene.Step(10);
  EXPECT_TRUE(art.GetLinks()[0].GetPose().p.allFinite());
}

TEST(UntrustedPhysicsTest, MassZeroWithShapesWarnsAndEffortsAreClampedToTheJointsLimit) {
  const std::string urdf =
      "<robot name=\"r\"><link name=\"a\"><inertial><mass value=\"1\"/>"
      "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>"
      "<link name=\"b\"><inertial><mass value=\"0\"/><inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" "
      "iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial><collision><geometry><box size=\"0.2 0.2 0.2\"/>"
      "</geometry></collision></link>"
      "<joint name=\"j\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/>"
      "<axis xyz=\"0 0 1\"/><limit effort=\"5\" velocity=\"1\"/></joint></robot>";
  Scene scene;
  scene.SetGravity(Eigen::Vector3d::Zero());
  UrdfLoader loader(&scene);
  loader.fix_root_link = true;
  Articulation art = loader.LoadFromString(urdf, ".");
  bool warned = false;
  for (const LoadWarning& w : loader.LastReport().warnings)
    warned |= w.message.find("link 'b' <inertial> has mass 0") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_NEAR(art.GetLinks()[1].GetMass(), 8.0, 1e-9);  // (0.2 m)^3 at 1000 kg/m^3
  EXPECT_EQ(art.GetActiveJoints()[0].GetDesc().effort_limit, 5.0);
  JointControllerOptions o;
  o.gravity_compensation = false;
  JointEffortController c(art, {"j"}, o);
  c.SetTarget(Eigen::VectorXd::Constant(1, 100.0));
  EXPECT_NE(c.GetStatus().message.find("j (100 to +-5)"), std::string::npos)
      << c.GetStatus().message;
  c.Update();
  EXPECT_NEAR(art.GetQf()[0], 5.0, 1e-12);
}

}  // namespace
}  // namespace partsim
