// `partsim assets`: unknown categories and flags are a bad command line with a suggestion;
// progress in a log file or a pipe is plain lines.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>

#include "server/process_util.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

struct RunResult {
  int code = -1;
  std::string err;  // standard error, read through a pipe (not a terminal)
};

/// Runs `partsim assets ARGS` with stderr to a pipe and stdout dropped.
RunResult RunAssets(const std::string& args) {
  const std::string cmd =
      std::string("'") + PARTSIM_CLI_PATH + "' assets " + args + " 2>&1 >/dev/null";
  RunResult r;
  r.err = RunShell(cmd, &r.code);
  return r;
}

bool Contains(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

class AssetsCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("partsim_assets_command_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(AssetsCommandTest, AnUnknownCategoryIsABadCommandLineWithASuggestion) {
  RunResult r = RunAssets("generate --categories Bottle,Faucett --out '" + dir_.string() + "'");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err, "unknown category 'Faucett'")) << r.err;
  EXPECT_TRUE(Contains(r.err, "did you mean 'Faucet'?")) << r.err;
  EXPECT_FALSE(fs::exists(dir_)) << "nothing is written for a bad command line";
  // the case of a known name is a typo too; a name far from all has no suggestion
  r = RunAssets("generate --categories faucet --out '" + dir_.string() + "'");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err, "did you mean 'Faucet'?")) << r.err;
  r = RunAssets("generate --categories Zeppelin --out '" + dir_.string() + "'");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err, "unknown category 'Zeppelin'")) << r.err;
  EXPECT_FALSE(Contains(r.err, "did you mean")) << r.err;
  // sub-commands too
  r = RunAssets("generte --out x");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err, "did you mean 'generate'?")) << r.err;
}

// check and decompose read their flags with the commands' parser: a typo is a bad command line
// (exit code 2) with the closest flag or value as suggestion and the command's usage
TEST_F(AssetsCommandTest, CheckAndDecomposeRefuseUnknownOptionsWithASuggestion) {
  const std::string dir = "'" + dir_.string() + "'";
  RunResult r = RunAssets("check " + dir + " --no-visibilty");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err,
                       "partsim assets check: unknown option '--no-visibilty' (did you "
                       "mean '--no-visibility'?)"))
      << r.err;
  EXPECT_TRUE(Contains(r.err, "usage: partsim assets check DIR")) << r.err;
  r = RunAssets("check " + dir + " --backend rasterzer");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err, "did you mean 'rasterizer'?")) << r.err;
  r = RunAssets("check " + dir + " --jobs 0");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err, "--jobs expects an integer from 1")) << r.err;
  r = RunAssets("check " + dir + " other");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err, "unexpected argument 'other'")) << r.err;

  r = RunAssets("decompose mesh.obj --out " + dir + " --max-piece 4");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err,
                       "partsim assets decompose: unknown option '--max-piece' (did you "
                       "mean '--max-pieces'?)"))
      << r.err;
  EXPECT_TRUE(Contains(r.err, "usage: partsim assets decompose MESH")) << r.err;
  r = RunAssets("decompose mesh.obj --out " + dir + " --concavity -1");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err, "--concavity expects a number > 0, got '-1'")) << r.err;
  r = RunAssets("decompose mesh.obj --out " + dir + " --min-pieces 5 --max-pieces 4");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(Contains(r.err, "--min-pieces must not exceed --max-pieces")) << r.err;
  EXPECT_FALSE(fs::exists(dir_)) << "nothing is written for a bad command line";
}

TEST_F(AssetsCommandTest, ProgressInAPipeIsPlainLinesAtABoundedRate) {
  // 24 objects: no '\r', and a line per tenth of the work, not one per object
  RunResult r = RunAssets("generate --categories Bottle,Knife --per-category 12 --out '" +
                          dir_.string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  const long progress_lines =
      std::count(r.err.begin(), r.err.end(), '\n') - 1;  // all but "wrote 24 objects"
  EXPECT_GE(progress_lines, 2) << r.err;
  EXPECT_LE(progress_lines, 12) << r.err;
  EXPECT_TRUE(Contains(r.err, "[24/24]")) << r.err;
  EXPECT_TRUE(Contains(r.err, "wrote 24 objects")) << r.err;

  // check's progress, between its failure reports
  fs::create_directories(dir_ / "0broken" / "textured_objs");
  r = RunAssets("check '" + dir_.string() + "' --no-visibility --limit 3 --jobs 2");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  EXPECT_TRUE(Contains(r.err, "checked 3/3 objects")) << r.err;
}

}  // namespace
}  // namespace partsim
