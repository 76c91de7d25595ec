// `partsim serve` against a client nobody here wrote: roslib (npm) in Node.js runs
// tests/server/roslib_client.js, which lists topics through rosapi, measures the /clock and
// /joint_states rates and sends a JointTrajectory that the Panda must execute. The test script
// installs roslib and ws into build/node (or PARTSIM_NODE_DIR); without node or that folder the
// test is skipped.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#ifndef PARTSIM_CLI_PATH
#error "PARTSIM_CLI_PATH must name the partsim executable"
#endif
#include "server/process_util.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

TEST(ServeTest, RoslibClientListsTopicsReceivesStatesAndDrivesATrajectory) {
  int code = 0;
  std::string node = RunShell("command -v node 2>/dev/null", &code);
  while (!node.empty() && (node.back() == '\n' || node.back() == ' ')) node.pop_back();
  if (node.empty()) GTEST_SKIP() << "node is not installed (scripts/test.sh installs it)";
  const char* env = std::getenv("PARTSIM_NODE_DIR");
  fs::path dir = env ? fs::path(env) : fs::path(PARTSIM_SOURCE_DIR) / "build" / "node";
  if (!fs::exists(dir / "node_modules" / "roslib" / "package.json") ||
      !fs::exists(dir / "node_modules" / "ws" / "package.json"))
    GTEST_SKIP() << "roslib and ws are not installed in " << dir
                 << " (scripts/test.sh runs npm install --prefix build/node roslib ws)";
  // the client is an ES module that imports roslib: it runs from the folder that holds it
  fs::path client = dir / "partsim_roslib_client.mjs";
  fs::copy_file(fs::path(PARTSIM_SOURCE_DIR) / "tests" / "server" / "roslib_client.js", client,
                fs::copy_options::overwrite_existing);

  ServeProcess serve("--port 0 --robot panda --duration 120");
  ASSERT_GT(serve.Port(), 0) << "partsim serve printed: " << serve.FirstLine();
  std::string out = RunShell(
      "'" + node + "' '" + client.string() + "' " + std::to_string(serve.Port()) + " panda", &code);
  // the client prints one JSON line (the last line)
  std::string last = out.substr(0, out.find_last_not_of('\n') + 1);
  last = last.substr(last.rfind('\n') == std::string::npos ? 0 : last.rfind('\n') + 1);
  json r = json::parse(last, nullptr, false);
  ASSERT_FALSE(r.is_discarded()) << out;
  EXPECT_EQ(code, 0) << out;
  EXPECT_TRUE(r.value("connected", false)) << out;
  ASSERT_TRUE(r.contains("joint_states_hz")) << out;
  // 500 Hz physics in real time: one message per step, counted per simulated second (a loaded
  // machine steps more slowly, but publishes as much for each step)
  std::printf(
      "roslib client: /clock %.1f Hz, /joint_states %.1f Hz, %.2f sim s per wall s, "
      "trajectory error %.2g, command latency %.2f steps (max %lld)\n",
      r["clock_hz"].get<double>(), r["joint_states_hz"].get<double>(),
      r["sim_seconds_per_wall_second"].get<double>(), r["trajectory_final_error"].get<double>(),
      r["stats"]["mean_latency_steps"].get<double>(),
      r["stats"]["max_latency_steps"].get<long long>());
  RecordProperty("joint_states_hz", std::to_string(r["joint_states_hz"].get<double>()));
  EXPECT_GT(r["joint_states_per_sim_second"].get<double>(), 50.0);
  EXPECT_GT(r["clock_per_sim_second"].get<double>(), 50.0);
  EXPECT_LE(r["joint_states_per_sim_second"].get<double>(), 520.0);  // one per step at most
  EXPECT_LT(r["trajectory_final_error"].get<double>(), 0.01);
  EXPECT_TRUE(r["cbor_image"]["is_bytes"].get<bool>()) << out;
  EXPECT_EQ(r["cbor_image"]["bytes"].get<int>(), 640 * 480 * 3) << out;
  EXPECT_TRUE(r["plan"]["success"].get<bool>()) << out;
  EXPECT_LT(r["plan_final_error"].get<double>(), 0.01) << out;
  // the trajectory and the planned motion
  EXPECT_EQ(r["stats"]["commands"].get<long long>(), 2);
}

TEST(ServeTest, RejectsBadArgumentsAndServesForADuration) {
  int code = 0;
  const std::string cli = std::string("'") + PARTSIM_CLI_PATH + "' serve ";
  std::string out = RunShell(cli + "--robot ur5 2>&1", &code);
  EXPECT_EQ(code, 2);
  EXPECT_NE(out.find("--robot expects gripper or panda, got 'ur5'"), std::string::npos) << out;
  RunShell(cli + "--rate -3 2>&1", &code);
  EXPECT_EQ(code, 2);
  RunShell(cli + "--port 70000 2>&1", &code);
  EXPECT_EQ(code, 2);
  out = RunShell(cli + "--max-clients 0 2>&1", &code);
  EXPECT_EQ(code, 2);
  EXPECT_NE(out.find("--max-clients expects"), std::string::npos) << out;
  out = RunShell(cli + "--token '' 2>&1", &code);
  EXPECT_EQ(code, 2);
  // a host name, a token and an origin: served, and no warning for a loopback address
  out = RunShell(cli +
                     "--robot gripper --fast --port 0 --duration 0.3 --address localhost "
                     "--token t0k --allow-origin http://lab.example:8000 --max-clients 4 2>&1",
                 &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_EQ(out.find("warning"), std::string::npos) << out;
  out = RunShell(cli + "/nonexistent/scene.urdf --port 0 2>&1", &code);
  EXPECT_EQ(code, 1);
  EXPECT_NE(out.find("/nonexistent/scene.urdf"), std::string::npos) << out;
  // the flying gripper, as fast as possible, for a short while
  out = RunShell(cli + "--robot gripper --fast --port 0 --duration 0.5 2>&1", &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("robot /flying_gripper"), std::string::npos) << out;
  EXPECT_NE(out.find("stopped after"), std::string::npos) << out;
}

TEST(ServeTest, ServesAPartNetMobilityFolderAndASceneFile) {
  int code = 0;
  const fs::path dir = fs::temp_directory_path() / ("partsim_serve_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::string cli = std::string("'") + PARTSIM_CLI_PATH + "' ";
  std::string out =
      RunShell(cli + "assets generate --categories StorageFurniture --per-category 1 " +
                   "--seed 3 --out '" + dir.string() + "' 2>&1",
               &code);
  ASSERT_EQ(code, 0) << out;
  fs::path folder;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename() == "mobility_v2.json") folder = e.path().parent_path();
  ASSERT_FALSE(folder.empty()) << out;
  // the folder alone: the cabinet and the robot
  out =
      RunShell(cli + "serve '" + folder.string() + "' --fast --port 0 --duration 0.3 2>&1", &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("2 articulations"), std::string::npos) << out;
  // a scene file with the cabinet twice, side by side
  const fs::path scene = dir / "two.json";
  std::FILE* f = std::fopen(scene.string().c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fprintf(f,
               R"({"objects": [{"path": "%s", "name": "left", "pose": {"position": [1.2, 0.8, 0]}},
                               {"path": "%s", "name": "right", "pose": {"position": [1.2, -0.8, 0]}}]})",
               folder.string().c_str(), folder.string().c_str());
  std::fclose(f);
  out = RunShell(cli + "serve '" + scene.string() + "' --fast --port 0 --duration 0.3 2>&1", &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("3 articulations"), std::string::npos) << out;
  // a bad entry: the error names the file and the field
  f = std::fopen(scene.string().c_str(), "w");
  std::fprintf(f, R"({"objects": [{"path": "%s", "pose": {"position": [1, 2]}}]})",
               folder.string().c_str());
  std::fclose(f);
  out = RunShell(cli + "serve '" + scene.string() + "' --fast --port 0 --duration 0.3 2>&1", &code);
  EXPECT_EQ(code, 1) << out;
  EXPECT_NE(out.find("two.json"), std::string::npos) << out;
  EXPECT_NE(out.find("objects[0].pose.position"), std::string::npos) << out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace partsim
