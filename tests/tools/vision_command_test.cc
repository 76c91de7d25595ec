// `partsim vision` as users run it: the evaluators' tables and files, and what it says on a bad
// command line (exit 2) or a bad file (exit 1).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "partsim/render/image_io.h"
#include "partsim/render/image_read.h"
#include "server/process_util.h"

#ifndef PARTSIM_CLI_PATH
#error "PARTSIM_CLI_PATH must name the partsim executable"
#endif

namespace partsim {
namespace {

namespace fs = std::filesystem;

// one 2x2 image, two categories; a drawer found exactly, a door missed
const char kGroundTruth[] = R"({
  "images": [{"id": 1, "width": 2, "height": 2}],
  "categories": [{"id": 1, "name": "Cabinet/drawer"}, {"id": 2, "name": "Cabinet/rotation_door"}],
  "annotations": [
    {"id": 1, "image_id": 1, "category_id": 1,
     "segmentation": {"size": [2, 2], "counts": [0, 2, 2]}},
    {"id": 2, "image_id": 1, "category_id": 2,
     "segmentation": {"size": [2, 2], "counts": [2, 2]}}]
})";
const char kResults[] = R"([
  {"image_id": 1, "category_id": 1, "score": 0.9,
   "segmentation": {"size": [2, 2], "counts": "022"}}
])";

const char kMotionTruth[] = R"({"slider_range": 0.5, "samples": [
  {"sample_id": 0, "m": [1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0.25, 0]},
  {"sample_id": 1, "m": [0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0.5]}]})";
const char kMotionPredictions[] = R"({"samples": [
  {"sample_id": 0, "m": [0.9, 0.1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0.25, 0]},
  {"sample_id": 1, "m": [0.2, 0.8, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0.3]}]})";

class VisionCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("partsim_vision_command_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    Write("gt.json", kGroundTruth);
    Write("results.json", kResults);
    Write("motion_gt.json", kMotionTruth);
    Write("motion_pred.json", kMotionPredictions);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name)) << text;
  }
  static std::string Read(const std::string& path) {
    std::ifstream f(path);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }
  // `partsim vision ARGS` with stderr folded in
  std::string Run(const std::string& args, int* code) const {
    return RunShell(
        "cd '" + dir_.string() + "' && '" + PARTSIM_CLI_PATH + "' vision " + args + " 2>&1", code);
  }

  fs::path dir_;
};

bool Contains(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

TEST_F(VisionCommandTest, EvaluateDetectionPrintsAndWritesTheTable) {
  int code = -1;
  const std::string out =
      Run("evaluate-detection --gt gt.json --results results.json --out report", &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_TRUE(Contains(out, "| Cabinet | 100.0 | 0.0 | 50.0 |")) << out;
  EXPECT_TRUE(Contains(out, "| **All** | | | **50.0** |")) << out;
  EXPECT_TRUE(Contains(out, "wrote report/metrics.json")) << out;
  EXPECT_EQ(Read(Path("report/table.csv")),
            "object_category,drawer,rotation_door,mAP\nCabinet,100,0,50\nAll,,,50\n");
  EXPECT_TRUE(Contains(Read(Path("report/metrics.json")), "\"map\": 0.5")) << out;
  EXPECT_TRUE(Contains(Read(Path("report/table.md")), "| object category | drawer |"));
}

TEST_F(VisionCommandTest, EvaluateMotionPrintsAndWritesTheTable) {
  int code = -1;
  const std::string out =
      Run("evaluate-motion --gt motion_gt.json --predictions motion_pred.json --out m", &code);
  EXPECT_EQ(code, 0) << out;
  // drawer state off by 0.2 of the 0.5 m range
  EXPECT_TRUE(Contains(out, "| 100.0% | 100.0% | 0 | 0 | 0 | 0 | 0.1 |")) << out;
  EXPECT_TRUE(Contains(Read(Path("m/metrics.json")), "\"hinges\": 1")) << out;
  EXPECT_TRUE(fs::exists(Path("m/table.csv")));
}

TEST_F(VisionCommandTest, BadCommandLinesExitWith2) {
  int code = -1;
  std::string out = Run("", &code);
  EXPECT_EQ(code, 2);
  EXPECT_TRUE(Contains(out,
                       "expected a subcommand (detection-dataset, motion-dataset, "
                       "evaluate-detection, evaluate-motion, show, train, predict, table)"))
      << out;
  out = Run("evaluate-detections --gt gt.json", &code);
  EXPECT_EQ(code, 2);
  EXPECT_TRUE(Contains(out, "did you mean 'evaluate-detection'?")) << out;
  out = Run("evaluate-detection --results results.json", &code);
  EXPECT_EQ(code, 2);
  EXPECT_TRUE(Contains(out, "--gt FILE is required")) << out;
  out = Run("evaluate-motion --gt motion_gt.json", &code);
  EXPECT_EQ(code, 2);
  EXPECT_TRUE(Contains(out, "--predictions FILE is required")) << out;
  out = Run("evaluate-detection --gt gt.json --result results.json", &code);
  EXPECT_EQ(code, 2);
  EXPECT_TRUE(Contains(out, "--results")) << out;
  out = Run("--help", &code);
  EXPECT_EQ(code, 0);
  EXPECT_TRUE(Contains(out, "partsim vision evaluate-motion --gt FILE")) << out;
}

TEST_F(VisionCommandTest, BadFilesExitWith1AndNameTheEntry) {
  Write("bad_results.json", R"([{"image_id": 5, "category_id": 1, "score": 1,
                                 "segmentation": {"size": [2, 2], "counts": [4]}}])");
  int code = -1;
  std::string out = Run("evaluate-detection --gt gt.json --results bad_results.json", &code);
  EXPECT_EQ(code, 1);
  EXPECT_TRUE(Contains(out,
                       "partsim vision: COCO results 'bad_results.json': [0]: image_id 5 is "
                       "not an image of the ground truth"))
      << out;
  out = Run("evaluate-detection --gt missing.json --results results.json", &code);
  EXPECT_EQ(code, 1);
  EXPECT_TRUE(Contains(out, "missing.json")) << out;
}

// a detection dataset of one 8 x 6 picture (every pixel grey 100) whose 2 x 2 part at (3, 2) is a
// drawer
TEST_F(VisionCommandTest, ShowDrawsTheMaskAndRefusesBadIndicesAndFlags) {
  fs::create_directories(Path("data/rgb"));
  const std::vector<uint8_t> grey(8 * 6 * 3, 100);
  WritePng(Path("data/rgb/00.png"), 8, 6, 3, grey.data());
  // column-major runs: columns 0-2 (18 pixels) and rows 0-1 of column 3 background, then 2
  // foreground, ...
  Write("data/instances_train.json", R"({
    "images": [{"id": 1, "width": 8, "height": 6, "file_name": "rgb/00.png"}],
    "categories": [{"id": 1, "name": "Cabinet/drawer"}],
    "annotations": [{"id": 1, "image_id": 1, "category_id": 1,
                     "segmentation": {"size": [6, 8], "counts": [20, 2, 4, 2, 20]}}]})");
  int code = -1;
  std::string out = Run("show data --index 0 --out shown.png", &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_TRUE(Contains(out, "image 0 (id 1) of data/instances_train.json: rgb/00.png, 1 part"))
      << out;
  EXPECT_TRUE(Contains(out, "wrote shown.png")) << out;
  int w = 0, h = 0;
  const std::vector<uint8_t> shown = ReadPng(Path("shown.png"), 3, &w, &h);
  ASSERT_EQ(w, 8);
  ASSERT_EQ(h, 6);
  EXPECT_NE(shown, grey);  // the mask (and its label, on a picture this small) drawn
  out = Run("show data --index 1 --out shown.png", &code);
  EXPECT_EQ(code, 1) << out;
  EXPECT_TRUE(Contains(out, "index 1 is out of range: instances_train.json holds 1 image (0 to 0)"))
      << out;
  out = Run("show data --out shown.png --split test", &code);
  EXPECT_EQ(code, 1) << out;
  EXPECT_TRUE(Contains(out, "has no instances_test.json")) << out;
  out = Run("show . --out shown.png", &code);
  EXPECT_EQ(code, 1) << out;
  EXPECT_TRUE(Contains(out, "holds no dataset files")) << out;
  out = Run("show data --indx 0 --out shown.png", &code);
  EXPECT_EQ(code, 2) << out;
  EXPECT_TRUE(Contains(out, "did you mean '--index'?")) << out;
  out = Run("show data --kind motions --out shown.png", &code);
  EXPECT_EQ(code, 2) << out;
  EXPECT_TRUE(Contains(out, "motion")) << out;
  out = Run("show data", &code);
  EXPECT_EQ(code, 2) << out;
  EXPECT_TRUE(Contains(out, "--out FILE.png is required")) << out;
  out = Run("show data --index -1 --out shown.png", &code);
  EXPECT_EQ(code, 2) << out;
}

}  // namespace
}  // namespace partsim
