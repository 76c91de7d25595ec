// Runs the built `partsim` program through popen and checks its output and exit codes.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <png.h>
#include <sys/wait.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "assets/partnet_test_folder.h"
#include "partsim/assets/default_objects.h"
#include "server/process_util.h"

#ifndef PARTSIM_CLI_PATH
#error "PARTSIM_CLI_PATH must name the partsim executable"
#endif

namespace partsim {
namespace {

namespace fs = std::filesystem;

struct RunResult {
  int code = -1;       // exit code
  std::string output;  // stdout and stderr together
};

/// Runs `partsim ARGS` with stderr folded into stdout (or dropped when `stderr_too` is false).
RunResult RunCli(const std::string& args, bool stderr_too = true) {
  std::string cmd =
      std::string("'") + PARTSIM_CLI_PATH + "' " + args + (stderr_too ? " 2>&1" : " 2>/dev/null");
  RunResult r;
  r.output = RunShell(cmd, &r.code);
  return r;
}

bool Contains(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

/// A scratch folder, removed at the end of the test.
class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("partsim_cli_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    cabinet_ = (dir_ / "cabinet.urdf").string();
    std::ofstream(cabinet_) << MakeCabinetUrdf();
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  std::string cabinet_;
};

TEST_F(CliTest, VersionAndHelp) {
  RunResult v = RunCli("--version");
  EXPECT_EQ(v.code, 0);
  EXPECT_TRUE(Contains(v.output, "partsim ")) << v.output;
  EXPECT_TRUE(Contains(v.output, std::string("(MuJoCo ") + mj_versionString() + ")")) << v.output;
  RunResult h = RunCli("--help");
  EXPECT_EQ(h.code, 0);
  EXPECT_TRUE(Contains(h.output, "partsim info")) << h.output;
  EXPECT_TRUE(Contains(h.output, "--drive-stiffness")) << h.output;
  EXPECT_EQ(RunCli("simulate --help").code, 0);
  // no arguments: usage on stderr, exit code 2
  RunResult none = RunCli("");
  EXPECT_EQ(none.code, 2);
  EXPECT_TRUE(Contains(none.output, "usage")) << none.output;
}

TEST_F(CliTest, BadCommandLinesExitWithCodeTwoAndNameTheCulprit) {
  struct Case {
    std::string args, named;
  };
  const std::vector<Case> cases = {
      {"frobnicate", "frobnicate"},
      {"--frobnicate", "--frobnicate"},
      {"info --bogus", "--bogus"},
      {"info --steps 3", "--steps"},  // simulate's flag
      {"simulate --steps abc", "--steps"},
      {"simulate --steps -3", "--steps"},
      {"simulate --dt 0.0.1 --steps 3", "--dt"},
      {"simulate --dt -1 --steps 3", "--dt"},
      {"simulate --gravity 1,2 --steps 3", "--gravity"},
      {"simulate --gravity 0,0,x --steps 3", "--gravity"},
      {"simulate --format xml --steps 3", "--format"},
      {"simulate --steps", "--steps"},
      {"simulate --target 1,2", "--target"},                               // no stiffness
      {"simulate --drive-stiffness 10 --target 1 --steps 3", "--target"},  // 2 dof
      {"simulate CABINET", "--steps"},                                     // a file needs --steps
      {"info CABINET other.urdf", "other.urdf"},
      {"render", "--out"},  // the folder is required
      {"render --out OUT --views 0", "--views"},
      {"render --out OUT --width 20000", "--width"},
      {"render --out OUT --height x", "--height"},
      {"render --out OUT --backend vulkan", "--backend"},
      {"render --out OUT --spp 4", "--spp"},  // the rasterizer takes no samples
      {"info --backend null", "--backend"},   // render's flag
  };
  for (const Case& c : cases) {
    std::string args = c.args;
    if (size_t at = args.find("CABINET"); at != std::string::npos) args.replace(at, 7, cabinet_);
    if (size_t at = args.find("OUT"); at != std::string::npos)
      args.replace(at, 3, (dir_ / "out").string());
    RunResult r = RunCli(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.output;
    EXPECT_TRUE(Contains(r.output, c.named)) << args << "\n" << r.output;
  }
}

TEST_F(CliTest, MissingOrInvalidFileExitsWithCodeOne) {
  std::string missing = (dir_ / "no_such_cabinet.urdf").string();
  const std::vector<std::string> commands = {
      "info ", "simulate --steps 3 ", "render --backend null --out " + (dir_ / "r").string() + " "};
  for (const std::string& cmd : commands) {
    RunResult r = RunCli(cmd + missing);
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_TRUE(Contains(r.output, "no_such_cabinet.urdf")) << r.output;
  }
  std::string broken = (dir_ / "broken.urdf").string();
  std::ofstream(broken) << "<robot name=\"x\"><link name=\"a\"/><joint name=\"j\" "
                           "type=\"revolute\"><parent link=\"a\"/><child link=\"zz\"/></joint>"
                           "</robot>";
  RunResult r = RunCli("info " + broken);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(Contains(r.output, "broken.urdf")) << r.output;
}

TEST_F(CliTest, InfoOfTheBuiltInCabinet) {
  RunResult r = RunCli("info");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "built-in cabinet")) << r.output;
  for (const char* name : {"body", "drawer_0", "door_0", "drawer_0_joint", "door_0_joint",
                           "prismatic", "revolute", "[0, 0.4] m", "[0, 1.6] rad"}) {
    EXPECT_TRUE(Contains(r.output, name)) << name << "\n" << r.output;
  }
  EXPECT_TRUE(Contains(r.output, "DOF: 2")) << r.output;
}

TEST_F(CliTest, InfoJsonAgreesWithItself) {
  RunResult r = RunCli("info " + cabinet_ + " --json", /*stderr_too=*/false);
  ASSERT_EQ(r.code, 0) << r.output;
  nlohmann::json j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["dof"], 2);
  ASSERT_EQ(j["links"].size(), 3u);
  ASSERT_EQ(j["joints"].size(), 2u);
  double sum = 0.0;
  for (const auto& l : j["links"]) sum += l["mass"].get<double>();
  EXPECT_NEAR(j["total_mass"].get<double>(), sum, 1e-9);
  EXPECT_GT(sum, 10.0);
  EXPECT_TRUE(j["links"][0]["parent"].is_null());
  EXPECT_EQ(j["joints"][0]["name"], "drawer_0_joint");
  EXPECT_EQ(j["joints"][0]["parent"], "body");
  EXPECT_EQ(j["joints"][0]["child"], "drawer_0");
  EXPECT_DOUBLE_EQ(j["joints"][0]["upper"].get<double>(), 0.4);
  EXPECT_EQ(j["joints"][1]["unit"], "rad");

  // a free root adds no counted dof but is reported
  RunResult f = RunCli("info " + cabinet_ + " --free-root --json", false);
  ASSERT_EQ(f.code, 0) << f.output;
  EXPECT_EQ(nlohmann::json::parse(f.output)["fix_root"], false);
}

TEST_F(CliTest, DemoOpensTheDrawerAndTheDoor) {
  RunResult r = RunCli("simulate", /*stderr_too=*/false);
  ASSERT_EQ(r.code, 0) << r.output;
  // "  drawer_0_joint   0.2992 m"
  double drawer = -1, door = -1;
  std::istringstream in(r.output);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string name;
    double value;
    if (!(words >> name >> value)) continue;
    if (name == "drawer_0_joint") drawer = value;
    if (name == "door_0_joint") door = value;
  }
  EXPECT_GT(drawer, 0.25) << r.output;
  EXPECT_GT(door, 1.0) << r.output;
  EXPECT_TRUE(Contains(r.output, "steps/s")) << r.output;
}

TEST_F(CliTest, SimulateWritesCsvTrajectory) {
  std::string out = (dir_ / "traj.csv").string();
  RunResult r = RunCli("simulate " + cabinet_ +
                       " --steps 50 --dt 0.004 --drive-stiffness 100 --drive-damping 20 "
                       "--target 0.2,0.5 --out " +
                       out);
  ASSERT_EQ(r.code, 0) << r.output;
  std::ifstream in(out);
  std::string header, line, last;
  std::getline(in, header);
  EXPECT_EQ(header,
            "time,qpos:drawer_0_joint,qpos:door_0_joint,qvel:drawer_0_joint,qvel:door_0_joint");
  int rows = 0;
  while (std::getline(in, line)) {
    ++rows;
    last = line;
  }
  EXPECT_EQ(rows, 51);  // the initial state and one row per step
  // the last row is at 50 steps of 4 ms, and the drawer has moved towards its target
  std::vector<double> v;
  std::istringstream cells(last);
  std::string cell;
  while (std::getline(cells, cell, ',')) v.push_back(std::stod(cell));
  ASSERT_EQ(v.size(), 5u);
  EXPECT_NEAR(v[0], 0.2, 1e-9);
  EXPECT_GT(v[1], 0.01);
  EXPECT_GT(v[3], 0.0);
}

TEST_F(CliTest, SimulateWritesJsonTrajectoryAndHonoursGravity) {
  // the cabinet on a free root falls under gravity; with no gravity it stays
  std::string out = (dir_ / "traj.json").string();
  RunResult r =
      RunCli("simulate " + cabinet_ + " --free-root --steps 20 --gravity 0,0,0 --out " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  nlohmann::json j;
  std::ifstream(out) >> j;
  ASSERT_EQ(j["time"].size(), 21u);
  ASSERT_EQ(j["qpos"].size(), 21u);
  EXPECT_EQ(j["joints"].size(), 2u);
  EXPECT_DOUBLE_EQ(j["dt"].get<double>(), 0.002);
  for (const auto& row : j["qvel"])
    for (const auto& v : row) EXPECT_NEAR(v.get<double>(), 0.0, 1e-9);

  // --format overrides the extension; '-' writes to stdout, the summary then goes to stderr
  RunResult s = RunCli("simulate " + cabinet_ + " --steps 3 --format json --out -",
                       /*stderr_too=*/false);
  ASSERT_EQ(s.code, 0) << s.output;
  nlohmann::json k = nlohmann::json::parse(s.output);
  EXPECT_EQ(k["time"].size(), 4u);
}

/// PNG width, height, bit depth and colour type, from the IHDR chunk.
std::array<int, 4> PngHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char b[26] = {};
  in.read(reinterpret_cast<char*>(b), sizeof(b));
  if (!in || std::memcmp(b, "\x89PNG", 4) != 0) return {-1, -1, -1, -1};
  auto be32 = [&](int at) { return b[at] << 24 | b[at + 1] << 16 | b[at + 2] << 8 | b[at + 3]; };
  return {be32(16), be32(20), b[24], b[25]};
}

/// An 8-bit grey PNG's pixels (row-major, top row first); empty when it cannot be read as one.
std::vector<uint8_t> ReadGreyPng(const std::string& path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return {};
  image.format = PNG_FORMAT_GRAY;
  std::vector<uint8_t> pixels(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) return {};
  return pixels;
}

/// Points of a binary PLY written by partsim: position and entity id.
struct PlyPoint {
  Eigen::Vector3f p;
  uint32_t entity;
};
std::vector<PlyPoint> ReadPly(const std::string& path, std::string* header) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  std::string data = s.str();
  size_t end = data.find("end_header\n");
  std::vector<PlyPoint> points;
  if (end == std::string::npos) return points;
  *header = data.substr(0, end);
  for (size_t at = end + 11; at + 24 <= data.size(); at += 24) {
    PlyPoint pt;
    std::memcpy(pt.p.data(), data.data() + at, 12);
    std::memcpy(&pt.entity, data.data() + at + 20, 4);
    points.push_back(pt);
  }
  return points;
}

/// Renders the built-in cabinet from `views` views with `backend` and checks the files: images
/// of the asked size, and world-frame points on the cabinet (inside its box: depth 0.5 m along
/// x, width 0.6 m, height 0.8 m, origin at the bottom centre) or on the ground (z = 0).
void CheckRender(const fs::path& dir, const std::string& backend, int views, bool expect_points) {
  std::string out = (dir / backend).string();
  RunResult r =
      RunCli("render --backend " + backend + " --views " + std::to_string(views) +
             " --width 64 --height 48 --out " + out + (backend == "pathtracer" ? " --spp 2" : ""));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "with " + backend)) << r.output;

  // the legend names the ground and the cabinet's links, with their colours
  nlohmann::json legend;
  std::ifstream(fs::path(out) / "segmentation.json") >> legend;
  std::map<std::string, nlohmann::json> by_name;
  for (const auto& e : legend["entities"]) by_name[e["name"].get<std::string>()] = e;
  ASSERT_EQ(by_name.size(), 4u) << legend.dump();
  EXPECT_EQ(by_name["ground"]["kind"], "actor");
  for (const char* link : {"body", "drawer_0", "door_0"}) {
    EXPECT_EQ(by_name[link]["kind"], "link") << link;
    EXPECT_EQ(by_name[link]["articulation"], "cabinet") << link;
    EXPECT_EQ(by_name[link]["color"].size(), 3u);
  }
  // part labels in semantics.txt's vocabulary, as generated objects have
  EXPECT_EQ(by_name["drawer_0"]["semantic_label"], "drawer");
  EXPECT_EQ(by_name["door_0"]["semantic_label"], "rotation_door");
  EXPECT_EQ(by_name["body"]["semantic_label"], "furniture_body");
  EXPECT_EQ(by_name["ground"]["semantic_label"], "");
  EXPECT_FALSE(legend["visuals"].empty());
  uint32_t ground_id = by_name["ground"]["id"].get<uint32_t>();
  nlohmann::json cams;
  std::ifstream(fs::path(out) / "cameras.json") >> cams;
  ASSERT_EQ(cams["views"].size(), static_cast<size_t>(views));
  EXPECT_EQ(cams["backend"], backend);

  for (int k = 0; k < views; ++k) {
    std::string n = std::to_string(k);
    EXPECT_EQ(PngHeader(out + "/color_" + n + ".png"), (std::array<int, 4>{64, 48, 8, 6}));
    EXPECT_EQ(PngHeader(out + "/depth_" + n + ".png"), (std::array<int, 4>{64, 48, 16, 0}));
    EXPECT_EQ(PngHeader(out + "/depth_preview_" + n + ".png"), (std::array<int, 4>{64, 48, 8, 0}));
    EXPECT_EQ(PngHeader(out + "/normal_" + n + ".png"), (std::array<int, 4>{64, 48, 8, 2}));
    EXPECT_EQ(PngHeader(out + "/segmentation_" + n + ".png"), (std::array<int, 4>{64, 48, 8, 2}));
    std::string header;
    std::vector<PlyPoint> points = ReadPly(out + "/cloud_" + n + ".ply", &header);
    EXPECT_TRUE(Contains(header, "element vertex " + std::to_string(points.size()))) << header;
    EXPECT_EQ(cams["views"][k]["points"].get<size_t>(), points.size());
    if (!expect_points) {
      EXPECT_TRUE(points.empty());
      continue;
    }
    // most of the picture sees something, and every point lies on what it names
    EXPECT_GT(points.size(), 64u * 48 / 2);
    size_t on_cabinet = 0;
    for (const PlyPoint& pt : points) {
      if (pt.entity == ground_id) {
        EXPECT_NEAR(pt.p.z(), 0.0f, 2e-3f);
        continue;
      }
      ++on_cabinet;
      // the open-able parts may stick out in front (+x) a little: handles
      EXPECT_GT(pt.p.x(), -0.25f - 2e-3f);
      EXPECT_LT(pt.p.x(), 0.25f + 0.1f);
      EXPECT_LT(std::abs(pt.p.y()), 0.3f + 2e-3f);
      EXPECT_GT(pt.p.z(), -2e-3f);
      EXPECT_LT(pt.p.z(), 0.8f + 2e-3f);
    }
    EXPECT_GT(on_cabinet, 64u * 48 / 10) << "view " << k;

    // the depth preview spans its grey scale: the nearest surface white, the farthest 48, what
    // sees nothing black; one pixel per point of the cloud is not black
    std::vector<uint8_t> preview = ReadGreyPng(out + "/depth_preview_" + n + ".png");
    ASSERT_EQ(preview.size(), 64u * 48);
    std::set<uint8_t> greys;
    size_t lit = 0;
    for (uint8_t g : preview) {
      if (g == 0) continue;
      greys.insert(g);
      ++lit;
    }
    EXPECT_EQ(lit, points.size()) << "view " << k;
    EXPECT_EQ(*greys.rbegin(), 255) << "view " << k;
    EXPECT_EQ(*greys.begin(), 48) << "view " << k;
    EXPECT_GT(greys.size(), 20u) << "view " << k;
  }
}

/// The world bounds of the object that a render into `out` framed (cameras.json).
std::array<double, 6> ObjectBounds(const fs::path& out) {
  nlohmann::json cams;
  std::ifstream(out / "cameras.json") >> cams;
  const nlohmann::json& b = cams["object_bounds"];
  if (!b.contains("min")) return {};
  return {b["min"][0], b["min"][1], b["min"][2], b["max"][0], b["max"][1], b["max"][2]};
}

/// Part labels of the links of a render into `out` (segmentation.json), by link name.
std::map<std::string, std::string> LinkLabels(const fs::path& out) {
  nlohmann::json legend;
  std::ifstream(out / "segmentation.json") >> legend;
  std::map<std::string, std::string> labels;
  for (const auto& e : legend["entities"])
    if (e["kind"] == "link") labels[e["name"]] = e["semantic_label"];
  return labels;
}

// A PartNet-Mobility folder loads through the dataset's loader in info, simulate and render; its
// mobility.urdf named alone loads the same: upright (the y-up height of bounding_box.json is the
// world z extent) and with the labels of semantics.txt.
TEST_F(CliTest, APartNetMobilityFolderAndItsUrdfLoadTheSameUpright) {
  const fs::path gen = dir_ / "gen";
  RunResult g =
      RunCli("assets generate --categories StorageFurniture --seed 3 --out '" + gen.string() + "'");
  ASSERT_EQ(g.code, 0) << g.output;
  fs::path folder;
  for (const auto& e : fs::directory_iterator(gen)) folder = e.path();
  ASSERT_TRUE(fs::exists(folder / "mobility.urdf")) << g.output;

  RunResult info = RunCli("info '" + folder.string() + "' --json", /*stderr_too=*/false);
  ASSERT_EQ(info.code, 0) << info.output;
  nlohmann::json j = nlohmann::json::parse(info.output);
  EXPECT_EQ(j["name"].get<std::string>().rfind("StorageFurniture_", 0), 0u) << j["name"];
  EXPECT_GE(j["dof"].get<int>(), 1);
  EXPECT_EQ(RunCli("simulate '" + folder.string() + "' --steps 5").code, 0);

  nlohmann::json bbox;
  std::ifstream(folder / "bounding_box.json") >> bbox;
  const double height = bbox["max"][1].get<double>() - bbox["min"][1].get<double>();
  std::map<std::string, std::string> labels;
  for (const fs::path& object : {folder, folder / "mobility.urdf"}) {
    const fs::path out = dir_ / ("render_" + object.filename().string());
    RunResult r = RunCli("render --backend null --views 1 --width 16 --height 12 --out '" +
                         out.string() + "' '" + object.string() + "'");
    ASSERT_EQ(r.code, 0) << r.output;
    std::array<double, 6> b = ObjectBounds(out);
    EXPECT_NEAR(b[5] - b[2], height, 1e-3) << object;
    std::map<std::string, std::string> l = LinkLabels(out);
    if (labels.empty()) labels = l;
    EXPECT_EQ(l, labels) << object;
  }
  EXPECT_EQ(labels["link_0"], "furniture_body");

  // the real sample: a bottle with a lid on a screw joint
  const fs::path real =
      fs::path(PARTSIM_SOURCE_DIR) / ".." / "shared" / "realdata" / "partnet-mobility-3763";
  if (!fs::exists(real)) return;
  for (const fs::path& object : {real, real / "mobility.urdf"}) {
    RunResult r = RunCli("info '" + object.string() + "'");
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_TRUE(Contains(r.output, "articulation 'Bottle_")) << r.output;
  }
}

TEST_F(CliTest, TyposGetASuggestion) {
  struct Case {
    std::string args, suggestion;
  };
  const std::vector<Case> cases = {
      {"rendr", "did you mean 'render'?"},
      {"info --jsn", "did you mean '--json'?"},
      {"render --out OUT --backend rasterizr", "did you mean 'rasterizer'?"},
      {"render --out OUT --view 3", "did you mean '--views'?"},
      {"simulate --steps 3 --format jsn", "did you mean 'json'?"},
  };
  for (const Case& c : cases) {
    std::string args = c.args;
    if (size_t at = args.find("OUT"); at != std::string::npos)
      args.replace(at, 3, (dir_ / "out").string());
    RunResult r = RunCli(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.output;
    EXPECT_TRUE(Contains(r.output, c.suggestion)) << args << "\n" << r.output;
  }
  // no suggestion for what is far from every choice
  RunResult r = RunCli("render --out " + (dir_ / "out").string() + " --backend vulkan");
  EXPECT_FALSE(Contains(r.output, "did you mean")) << r.output;
}

TEST_F(CliTest, RenderWritesImagesCloudsAndLegendWithTheNullBackend) {
  CheckRender(dir_, "null", 3, /*expect_points=*/false);
}

// A second render into the same folder with fewer views leaves none of the first's behind; files
// it did not write stay.
TEST_F(CliTest, RenderReplacesItsOwnOutputsAndKeepsOtherFiles) {
  const fs::path out = dir_ / "again";
  RunResult r =
      RunCli("render --backend null --views 3 --width 32 --height 24 --out '" + out.string() + "'");
  ASSERT_EQ(r.code, 0) << r.output;
  ASSERT_TRUE(fs::exists(out / "color_2.png"));
  std::ofstream(out / "mine.txt") << "keep";
  r = RunCli("render --backend null --views 1 --width 32 --height 24 --out '" + out.string() + "'");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(out / "color_0.png"));
  for (const char* stale : {"color_1.png", "color_2.png", "depth_2.png", "cloud_2.ply"})
    EXPECT_FALSE(fs::exists(out / stale)) << stale;
  EXPECT_TRUE(fs::exists(out / "mine.txt"));
}

TEST_F(CliTest, RenderWithThePathTracer) { CheckRender(dir_, "pathtracer", 2, true); }

TEST_F(CliTest, RenderWithTheRasterizer) { CheckRender(dir_, "rasterizer", 2, true); }

}  // namespace
}  // namespace partsim

namespace partsim {
namespace {

TEST_F(CliTest, AssetsCheckPassesAGoodFolderAndFailsABadOneButChecksBoth) {
  testing::Folder good("cli_check/a_good");
  testing::Folder bad("cli_check/b_bad");
  bad.semantics =
      "link_0 slider rotation_door\nlink_1 slider drawer\nlink_2 heavy furniture_body\n";
  bad.WriteAll();
  std::string root = good.dir.parent_path().string();
  RunResult r = RunCli("assets check '" + root + "' --jobs 1 --no-visibility");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(Contains(r.output, "checked 2 objects")) << r.output;
  EXPECT_TRUE(Contains(r.output, "1 passed, 1 failed")) << r.output;
  EXPECT_TRUE(Contains(r.output, "semantics.txt")) << r.output;
  EXPECT_TRUE(Contains(r.output, "StorageFurniture")) << r.output;
  RunResult ok = RunCli("assets check '" + good.Path() + "' --no-visibility");
  EXPECT_EQ(ok.code, 0) << ok.output;
  EXPECT_EQ(RunCli("assets check").code, 2);
  EXPECT_EQ(RunCli("assets check '" + (dir_ / "nothing").string() + "'").code, 1);
}

TEST_F(CliTest, AssetsDecomposeWritesConvexPieces) {
  // an L of two boxes, as one OBJ
  std::string obj = testing::BoxObj({0, 0, 0}, {0.2, 0.05, 0.05});
  std::string second = testing::BoxObj({-0.15, 0, 0.15}, {0.05, 0.05, 0.1});
  // renumber the second box's faces after the first's 8 vertices
  std::string merged = obj;
  std::istringstream in(second);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("f ", 0) == 0) {
      std::istringstream f(line.substr(2));
      merged += "f";
      int i;
      while (f >> i) merged += " " + std::to_string(i + 8);
      merged += "\n";
    } else if (line.rfind("v ", 0) == 0) {
      merged += line + "\n";
    }
  }
  testing::Write(dir_ / "l.obj", merged);
  RunResult r = RunCli("assets decompose '" + (dir_ / "l.obj").string() + "' --out '" +
                       (dir_ / "pieces").string() + "'");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "pieces" / "l_0.obj")) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "pieces" / "l_collision.urdf.xml")) << r.output;
}

TEST_F(CliTest, TasksDemoOpensADrawerAndWritesFrames) {
  fs::path out = dir_ / "demo";
  RunResult r = RunCli("tasks demo --task drawer --every 20 --frames --out '" + out.string() + "'");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "SUCCESS")) << r.output;
  int frames = 0;
  for (const auto& e : fs::directory_iterator(out)) frames += e.path().extension() == ".png";
  EXPECT_GT(frames, 3) << r.output;
  EXPECT_GT(fs::file_size(out / "demo.mp4"), 0u) << r.output;
}

TEST_F(CliTest, TasksRejectsBadArguments) {
  RunResult r = RunCli("tasks evaluate --task window");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(Contains(r.output, "--task expects drawer or door, got 'window'")) << r.output;
  EXPECT_EQ(RunCli("tasks evaluate --count 0").code, 2);
  EXPECT_EQ(RunCli("tasks fly").code, 2);
  // object 0 of the generator is a cabinet without drawers
  r = RunCli("tasks demo --task drawer --object 0 --out '" + (dir_ / "d").string() + "'");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(Contains(r.output, "has no drawer")) << r.output;
}

// Outputs are never mixed or torn: generate refuses a non-empty folder unless --overwrite, which
// replaces only what partsim generated; objects appear whole (written to <id>.partial, then
// renamed); check fails the leftovers of a stopped run and folders missing their files.
TEST_F(CliTest, GenerateNeverMixesOrTearsAndCheckFindsWhatIsLeftOver) {
  const fs::path out = dir_ / "gen";
  const std::string gen =
      "assets generate --categories Bottle --per-category 2 --out '" + out.string() + "'";
  RunResult r = RunCli(gen);
  ASSERT_EQ(r.code, 0) << r.output;
  std::vector<std::string> ids;
  for (const auto& e : fs::directory_iterator(out)) ids.push_back(e.path().filename().string());
  ASSERT_EQ(ids.size(), 2u);
  for (const std::string& id : ids) EXPECT_EQ(id.find(".partial"), std::string::npos) << id;
  // a second run into the same folder is refused, and writes nothing
  std::ofstream(out / "notes.txt") << "mine";
  r = RunCli(gen);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(Contains(r.output, "is not empty")) << r.output;
  // --overwrite replaces partsim's objects and leftovers, and keeps the rest
  fs::create_directories(out / "123.partial" / "textured_objs");
  std::ofstream(out / ids[0] / "stale.txt") << "old";
  r = RunCli(gen + " --overwrite");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(fs::exists(out / ids[0] / "stale.txt"));
  EXPECT_FALSE(fs::exists(out / "123.partial"));
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
  EXPECT_TRUE(fs::exists(out / ids[1] / "mobility.urdf"));
  // what a stopped run leaves, and a folder holding only meshes: both fail the check
  fs::copy(out / ids[1], out / (ids[1] + "0.partial"), fs::copy_options::recursive);
  fs::create_directories(out / "999" / "textured_objs");
  std::ofstream(out / "999" / "textured_objs" / "original-0.obj") << "v 0 0 0\n";
  r = RunCli("assets check '" + out.string() + "' --no-visibility");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(Contains(r.output, "left by a generate run that was stopped")) << r.output;
  EXPECT_TRUE(Contains(r.output, "999")) << r.output;
  EXPECT_TRUE(Contains(r.output, "checked 4 objects")) << r.output;
}

TEST_F(CliTest, TasksEvaluateRunsOnADatasetFolderTree) {
  // a generated tree in the dataset's flat layout: every drawer of the first two objects
  // that have one, perceived from the meshes
  fs::path tree = dir_ / "tree";
  RunResult g = RunCli("assets generate --categories StorageFurniture --per-category 4 --out '" +
                       tree.string() + "'");
  ASSERT_EQ(g.code, 0) << g.output;
  fs::path csv = dir_ / "episodes.csv";
  RunResult r = RunCli("tasks evaluate --task drawer --dataset '" + tree.string() +
                       "' --count 2 --targets all --no-cameras --csv '" + csv.string() + "'");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "succeeded")) << r.output;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "object,target,success,progress,seconds,stage,message");
  std::set<std::string> objects;
  int rows = 0;
  while (std::getline(in, line)) {
    ++rows;
    std::string object = line.substr(0, line.find(','));
    EXPECT_TRUE(fs::exists(tree / object / "mobility.urdf")) << line;
    objects.insert(object);
  }
  EXPECT_EQ(objects.size(), 2u);
  EXPECT_GE(rows, 2);
  // --ids keeps the named folders; an unknown one is named
  r = RunCli("tasks evaluate --task drawer --dataset '" + tree.string() + "' --ids nope");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(Contains(r.output, "no PartNet-Mobility folder 'nope'")) << r.output;
  EXPECT_EQ(RunCli("tasks evaluate --ids 1").code, 2);
}

// A subset of a dataset as a folder of symbolic links to object folders, the usual way to pick
// one: each command that reads a dataset tree sees the linked objects, by the links' names, and
// refuses a link loop by the link's name (the gallery lists it and shows the rest).
TEST_F(CliTest, DatasetCommandsFollowSymbolicLinksAndRefuseLoops) {
  const fs::path data = dir_ / "data";
  RunResult g = RunCli("assets generate --categories StorageFurniture --per-category 4 --out '" +
                       data.string() + "'");
  ASSERT_EQ(g.code, 0) << g.output;
  std::vector<std::string> ids;
  for (const auto& e : fs::directory_iterator(data))
    if (fs::exists(e.path() / "mobility.urdf")) ids.push_back(e.path().filename().string());
  std::sort(ids.begin(), ids.end());
  ASSERT_EQ(ids.size(), 4u);
  // the subset: two absolute links, and a relative link in a subfolder of plain folders
  const fs::path subset = dir_ / "subset";
  fs::create_directories(subset / "more");
  fs::create_directory_symlink(data / ids[0], subset / "first");
  fs::create_directory_symlink(data / ids[1], subset / "second");
  fs::create_directory_symlink("../../data/" + ids[2], subset / "more" / "third");
  const std::string root = "'" + subset.string() + "'";

  RunResult r = RunCli("assets check " + root + " --no-visibility");
  EXPECT_TRUE(Contains(r.output, "checked 3 objects")) << r.output;

  r = RunCli("view --dataset " + root + " --port 0 --duration 0.2");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "3 objects under")) << r.output;
  EXPECT_TRUE(Contains(r.output, "(0 folders could not be read)")) << r.output;

  r = RunCli("vision detection-dataset --dataset " + root + " --out '" + (dir_ / "det").string() +
             "' --views 1 --size 32 --no-point-clouds --quiet");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "3 objects (3 rendered now")) << r.output;
  // objects are named by their paths under ROOT, through the links
  EXPECT_TRUE(fs::exists(dir_ / "det" / "objects" / "more_third")) << r.output;

  const fs::path csv = dir_ / "episodes.csv";
  r = RunCli("tasks evaluate --task drawer --dataset " + root +
             " --ids first,second,third --no-cameras --jobs 3 --csv '" + csv.string() + "'");
  EXPECT_FALSE(Contains(r.output, "no PartNet-Mobility folder")) << r.output;
  std::ifstream in(csv);
  std::string csv_text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // objects without a drawer are skipped by name; the others have a row
  for (const char* id : {"first", "second", "third"})
    EXPECT_TRUE(Contains(csv_text, std::string("\n") + id + ",") ||
                Contains(r.output, std::string(id) + ": skipped"))
        << id << "\n"
        << r.output << csv_text;

  // a link to a folder above it: refused by name, not followed round and round
  const fs::path loop = subset / "more" / "back_up";
  fs::create_directory_symlink("..", loop);
  for (const std::string& command :
       {"assets check " + root + " --no-visibility",
        "vision detection-dataset --dataset " + root + " --out '" + (dir_ / "det2").string() +
            "' --views 1 --size 32 --quiet",
        "tasks evaluate --task drawer --dataset " + root + " --no-cameras"}) {
    r = RunCli(command);
    EXPECT_EQ(r.code, 1) << command << "\n" << r.output;
    EXPECT_TRUE(Contains(r.output, loop.string())) << command << "\n" << r.output;
    EXPECT_TRUE(Contains(r.output, "loop")) << command << "\n" << r.output;
  }
  r = RunCli("view --dataset " + root + " --port 0 --duration 0.2");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Contains(r.output, "3 objects under")) << r.output;
  EXPECT_TRUE(Contains(r.output, "more/back_up: symbolic link")) << r.output;
}

TEST_F(CliTest, TasksEvaluateOnTheRealSamplesSaysWhatItFound) {
  const fs::path real = fs::path(PARTSIM_SOURCE_DIR) / ".." / "shared" / "realdata";
  if (!fs::exists(real / "partnet-mobility-3763")) GTEST_SKIP() << "no " << real;
  // the real sample is a bottle: it loads, and has no drawer to pull
  RunResult r = RunCli("tasks evaluate --task drawer --dataset '" + real.string() +
                       "' --ids partnet-mobility-3763 --no-cameras");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(Contains(r.output, "partnet-mobility-3763: skipped: no drawer")) << r.output;
  EXPECT_TRUE(Contains(r.output, "has a drawer (a link labelled 'drawer'")) << r.output;
}

}  // namespace
}  // namespace partsim
