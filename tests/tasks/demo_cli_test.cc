// `partsim tasks demo`: the video it writes and the errors of its options, through the program.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "server/process_util.h"

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int code = -1;
  std::string out;  // standard output and error together
};

CliRun Cli(const std::string& args) {
  CliRun r;
  r.out = partsim::RunShell(std::string(PARTSIM_CLI_PATH) + " " + args + " 2>&1", &r.code);
  return r;
}

TEST(TasksDemoCliTest, WritesTheVideoAndSaysWhere) {
  // per process: two test runs at once must not share it
  fs::path dir = fs::temp_directory_path() / ("partsim_demo_cli_test_" + std::to_string(getpid()));
  fs::remove_all(dir);
  CliRun r = Cli("tasks demo --out " + dir.string() + " --size 160x120 --every 10 --frames");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path video = dir / "demo.mp4";
  EXPECT_TRUE(fs::is_regular_file(video)) << r.out;
  EXPECT_NE(r.out.find("video: " + video.string() + " (160x120, 5 fps)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("SUCCESS"), std::string::npos) << r.out;
  int frames = 0;
  for (const auto& e : fs::directory_iterator(dir)) frames += e.path().extension() == ".png";
  EXPECT_GT(frames, 5);
  EXPECT_NE(r.out.find("frames: " + std::to_string(frames) + " PNG"), std::string::npos) << r.out;

  // a second run without --frames leaves no frame of the first beside its video
  r = Cli("tasks demo --out " + dir.string() + " --size 160x120 --every 10");
  ASSERT_EQ(r.code, 0) << r.out;
  frames = 0;
  for (const auto& e : fs::directory_iterator(dir)) frames += e.path().extension() == ".png";
  EXPECT_EQ(frames, 0);
  EXPECT_TRUE(fs::is_regular_file(video));
  fs::remove_all(dir);
}

TEST(TasksDemoCliTest, BadOptionsAreUsageErrors) {
  struct Case {
    const char* args;
    const char* says;
  };
  for (const Case& c :
       {Case{"--object 9999", "StorageFurniture objects (0 to 344)"},
        Case{"--object 345", "out of range"}, Case{"--size 640", "--size expects WxH"},
        Case{"--size 8x8", "16..4096"}, Case{"--video a.mp4 --no-video", "exclude each other"},
        Case{"--video ''", "--video needs a file name"}}) {
    CliRun r = Cli(std::string("tasks demo ") + c.args + " --out /nonexistent/never");
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.says), std::string::npos) << c.args << "\n" << r.out;
  }
  CliRun r = Cli("tasks evaluate --frames");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("go with demo"), std::string::npos) << r.out;
}

}  // namespace
