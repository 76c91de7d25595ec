// The rosbridge JSON codecs without sockets: each message's exact field names and types (what
// roslib and rosbridge_suite read), round trips where partsim reads what it writes, and decoding
// errors that name the field at fault.
#include "server/ros_json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "partsim/core/error.h"
#include "partsim/server/sim_server.h"

namespace partsim::internal {
namespace {

/// The keys of a JSON object, sorted.
std::set<std::string> Keys(const Json& j) {
  std::set<std::string> k;
  for (auto it = j.begin(); it != j.end(); ++it) k.insert(it.key());
  return k;
}

/// Calls `f`, which must throw partsim::Error; returns its message.
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no partsim::Error thrown";
  return "";
}

/// Decodes base64 (the test's own decoder, to check the encoder against).
std::vector<uint8_t> FromBase64(const std::string& s) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::vector<uint8_t> out;
  uint32_t acc = 0;
  int bits = 0;
  for (char c : s) {
    const int v = val(c);
    if (v < 0) break;  // '=' padding
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<uint8_t>((acc >> bits) & 0xff));
    }
  }
  return out;
}

void ExpectHeader(const Json& h, long long secs, long long nsecs, const std::string& frame) {
  EXPECT_EQ(Keys(h), (std::set<std::string>{"seq", "stamp", "frame_id"}));
  EXPECT_TRUE(h["seq"].is_number_integer());
  EXPECT_EQ(Keys(h["stamp"]), (std::set<std::string>{"secs", "nsecs"}));
  EXPECT_TRUE(h["stamp"]["secs"].is_number_integer());
  EXPECT_TRUE(h["stamp"]["nsecs"].is_number_integer());
  EXPECT_EQ(h["stamp"]["secs"], secs);
  EXPECT_EQ(h["stamp"]["nsecs"], nsecs);
  EXPECT_EQ(h["frame_id"], frame);
}

TEST(RosJson, Base64MatchesTheRfcVectorsAndDecodesBack) {
  // RFC 4648, section 10
  const std::vector<std::pair<std::string, std::string>> vectors = {{"", ""},
                                                                    {"f", "Zg=="},
                                                                    {"fo", "Zm8="},
                                                                    {"foo", "Zm9v"},
                                                                    {"foob", "Zm9vYg=="},
                                                                    {"fooba", "Zm9vYmE="},
                                                                    {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, encoded] : vectors)
    EXPECT_EQ(Base64(reinterpret_cast<const uint8_t*>(plain.data()), plain.size()), encoded);
  std::vector<uint8_t> all(256);
  for (int i = 0; i < 256; ++i) all[i] = static_cast<uint8_t>(i);
  EXPECT_EQ(FromBase64(Base64(all.data(), all.size())), all);
}

TEST(RosJson, TextFormTurnsEveryBinaryValueIntoBase64) {
  Json j = {{"data", Json::binary({1, 2, 3})},
            {"nested", {{"more", Json::array({Json::binary({255})})}}},
            {"n", 4}};
  Json t = TextForm(j);
  EXPECT_EQ(t["data"], "AQID");
  EXPECT_EQ(t["nested"]["more"][0], "/w==");
  EXPECT_EQ(t["n"], 4);
  EXPECT_TRUE(j["data"].is_binary());  // the argument is a copy: the binary form stays
}

TEST(RosJson, DumpReplacesInvalidUtf8InsteadOfThrowing) {
  const std::string text =
      DumpJson(Json("a\xff"
                    "b"));
  EXPECT_EQ(text,
            "\"a\xef\xbf\xbd"
            "b\"");  // U+FFFD
}

TEST(RosJson, StampsAndDurationsRoundTrip) {
  for (double t : {0.0, 0.002, 1.5, 12.25, 3600.000000001, 86400.0}) {
    const Json s = StampToJson(t);
    EXPECT_GE(s["nsecs"].get<long long>(), 0);
    EXPECT_LT(s["nsecs"].get<long long>(), 1000000000);
    EXPECT_NEAR(DurationFromJson(s, "d"), t, 1e-9) << t;
  }
  ExpectHeader(HeaderToJson(12.25, "cam"), 12, 250000000, "cam");
  // ROS 2's field names and plain seconds are read too
  EXPECT_DOUBLE_EQ(DurationFromJson(Json{{"sec", 2}, {"nanosec", 500000000}}, "d"), 2.5);
  EXPECT_DOUBLE_EQ(DurationFromJson(Json(0.75), "d"), 0.75);
  EXPECT_DOUBLE_EQ(DurationFromJson(Json::object(), "d"), 0.0);
}

TEST(RosJson, BadDurationsNameTheField) {
  EXPECT_EQ(ErrorOf([] {
              DurationFromJson(Json{{"secs", "1"}}, "p.time_from_start");
            }),
            "p.time_from_start.secs is not a number");
  EXPECT_EQ(ErrorOf([] {
              DurationFromJson(Json{{"sec", 1}, {"nanosec", true}}, "t");
            }),
            "t.nanosec is not a number");
  EXPECT_EQ(ErrorOf([] { DurationFromJson(Json("soon"), "t"); }), "t is not a duration");
  EXPECT_EQ(ErrorOf([] { DurationFromJson(Json(-1), "t"); }),
            "t must be from 0 to 86400 s, got -1.0");
  EXPECT_NE(ErrorOf([] {
              DurationFromJson(Json{{"secs", 86401}}, "t");
            }).find("86400"),
            std::string::npos);
}

TEST(RosJson, NumbersMustBeAnArrayOfFiniteNumbers) {
  EXPECT_EQ(NumbersFromJson(Json{1, 2.5, -3}, "v"), (std::vector<double>{1, 2.5, -3}));
  EXPECT_EQ(ErrorOf([] { NumbersFromJson(Json(1), "cmd data"); }),
            "cmd data is not an array of numbers");
  EXPECT_EQ(ErrorOf([] {
              NumbersFromJson(Json{1, "2"}, "cmd data");
            }),
            "cmd data holds a value that is not a number");
  EXPECT_EQ(ErrorOf([] {
              NumbersFromJson(Json{1.0, HUGE_VAL}, "cmd data");
            }),
            "cmd data holds a value that is not finite");
}

TEST(RosJson, PoseRoundTripsAndMissingFieldsAreNamed) {
  const Pose X(Eigen::Vector3d(0.1, -0.2, 0.3),
               Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())));
  const Json j = PoseToJson(X);
  EXPECT_EQ(Keys(j), (std::set<std::string>{"position", "orientation"}));
  EXPECT_EQ(Keys(j["position"]), (std::set<std::string>{"x", "y", "z"}));
  EXPECT_EQ(Keys(j["orientation"]), (std::set<std::string>{"x", "y", "z", "w"}));
  EXPECT_DOUBLE_EQ(j["orientation"]["w"].get<double>(), X.q.w());
  const Pose Y = PoseFromJson(j, "goal");
  EXPECT_TRUE(Y.p.isApprox(X.p, 1e-15));
  EXPECT_TRUE(Y.q.coeffs().isApprox(X.q.coeffs(), 1e-15));

  Json no_y = j;
  no_y["position"].erase("y");
  EXPECT_EQ(ErrorOf([&] { PoseFromJson(no_y, "/panda/plan: pose_goal"); }),
            "/panda/plan: pose_goal field 'y' is missing or not a number");
  Json text_w = j;
  text_w["orientation"]["w"] = "1";
  EXPECT_EQ(ErrorOf([&] { PoseFromJson(text_w, "goal"); }),
            "goal field 'w' is missing or not a number");
  EXPECT_EQ(ErrorOf([] {
              PoseFromJson(Json{{"position", Json::object()}}, "goal");
            }),
            "goal needs position and orientation");
}

TEST(RosJson, ClockAndJointState) {
  const Json clock = ClockToJson(3.5);
  EXPECT_EQ(Keys(clock), (std::set<std::string>{"clock"}));
  EXPECT_EQ(clock["clock"], (Json{{"secs", 3}, {"nsecs", 500000000}}));

  JointStateReading r;
  r.names = {"a", "b"};
  r.position = {0.5, -1};
  r.velocity = {0, 2};
  r.effort = {3, 4};
  const Json js = JointStateToJson(r, 0.25);
  EXPECT_EQ(Keys(js), (std::set<std::string>{"header", "name", "position", "velocity", "effort"}));
  ExpectHeader(js["header"], 0, 250000000, "");
  EXPECT_EQ(js["name"], (Json{"a", "b"}));
  for (const char* k : {"position", "velocity", "effort"}) {
    ASSERT_TRUE(js[k].is_array()) << k;
    for (const Json& v : js[k]) EXPECT_TRUE(v.is_number_float()) << k;
  }
  EXPECT_EQ(js["position"][0].get<double>(), 0.5);
  EXPECT_EQ(js["effort"][1].get<double>(), 4.0);
}

TEST(RosJson, TfMessageHoldsOneTransformStampedPerFrameInWorld) {
  const Pose X(Eigen::Vector3d(1, 2, 3), Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5));
  const Json tf = TfToJson({{"link0", Pose()}, {"cam_optical_frame", X}}, 1.0);
  EXPECT_EQ(Keys(tf), (std::set<std::string>{"transforms"}));
  ASSERT_EQ(tf["transforms"].size(), 2u);
  const Json& t = tf["transforms"][1];
  EXPECT_EQ(Keys(t), (std::set<std::string>{"header", "child_frame_id", "transform"}));
  ExpectHeader(t["header"], 1, 0, "world");
  EXPECT_EQ(t["child_frame_id"], "cam_optical_frame");
  EXPECT_EQ(Keys(t["transform"]), (std::set<std::string>{"translation", "rotation"}));
  EXPECT_EQ(t["transform"]["translation"], (Json{{"x", 1.0}, {"y", 2.0}, {"z", 3.0}}));
  EXPECT_EQ(t["transform"]["rotation"], (Json{{"x", 0.5}, {"y", 0.5}, {"z", 0.5}, {"w", 0.5}}));
}

TEST(RosJson, ImageCarriesRgb8RowsAsBinaryThatTextFormSendsAsBase64) {
  const int w = 3, h = 2;
  std::vector<uint8_t> rgb(w * h * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<uint8_t>(i * 7);
  const Json img = ImageToJson(w, h, rgb, 2.0, "cam_optical_frame");
  EXPECT_EQ(Keys(img), (std::set<std::string>{"header", "height", "width", "encoding",
                                              "is_bigendian", "step", "data"}));
  ExpectHeader(img["header"], 2, 0, "cam_optical_frame");
  EXPECT_EQ(img["height"], h);
  EXPECT_EQ(img["width"], w);
  EXPECT_EQ(img["encoding"], "rgb8");
  EXPECT_TRUE(img["is_bigendian"].is_number_integer());
  EXPECT_EQ(img["step"], 3 * w);
  ASSERT_TRUE(img["data"].is_binary());
  EXPECT_EQ(static_cast<const std::vector<uint8_t>&>(img["data"].get_binary()), rgb);
  const Json text = TextForm(img);
  ASSERT_TRUE(text["data"].is_string());
  EXPECT_EQ(FromBase64(text["data"].get<std::string>()), rgb);
}

TEST(RosJson, CameraInfoTakesKFromTheProjection) {
  const std::vector<double> P = {500, 0, 320, 0, 0, 510, 240, 0, 0, 0, 1, 0};
  const Json info = CameraInfoToJson(640, 480, P, 0.5, "f");
  EXPECT_EQ(Keys(info), (std::set<std::string>{"header", "height", "width", "distortion_model", "D",
                                               "K", "R", "P", "binning_x", "binning_y", "roi"}));
  ExpectHeader(info["header"], 0, 500000000, "f");
  EXPECT_EQ(info["height"], 480);
  EXPECT_EQ(info["width"], 640);
  EXPECT_EQ(info["distortion_model"], "plumb_bob");
  EXPECT_EQ(info["D"], (Json{0.0, 0.0, 0.0, 0.0, 0.0}));
  EXPECT_EQ(info["K"], (Json{500.0, 0.0, 320.0, 0.0, 510.0, 240.0, 0.0, 0.0, 1.0}));
  EXPECT_EQ(info["R"], (Json{1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}));
  EXPECT_EQ(info["P"], Json(P));
  EXPECT_EQ(Keys(info["roi"]),
            (std::set<std::string>{"x_offset", "y_offset", "height", "width", "do_rectify"}));
  EXPECT_TRUE(info["roi"]["do_rectify"].is_boolean());
  EXPECT_NE(ErrorOf([] {
              CameraInfoToJson(1, 1, {1, 2, 3}, 0, "f");
            }).find("not 12"),
            std::string::npos);
}

TEST(RosJson, PointCloud2HoldsFloat32XyzPoints) {
  const std::vector<float> xyz = {0.f, 1.f, 2.f, -0.5f, 0.25f, 3.f};
  const Json pc = PointCloudToJson(xyz, 0, "f");
  EXPECT_EQ(Keys(pc), (std::set<std::string>{"header", "height", "width", "fields", "is_bigendian",
                                             "point_step", "row_step", "data", "is_dense"}));
  EXPECT_EQ(pc["height"], 1);
  EXPECT_EQ(pc["width"], 2);
  EXPECT_EQ(pc["point_step"], 12);
  EXPECT_EQ(pc["row_step"], 24);
  EXPECT_TRUE(pc["is_bigendian"].is_boolean());
  EXPECT_TRUE(pc["is_dense"].is_boolean());
  ASSERT_EQ(pc["fields"].size(), 3u);
  const char* names[] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    const Json& f = pc["fields"][k];
    EXPECT_EQ(Keys(f), (std::set<std::string>{"name", "offset", "datatype", "count"}));
    EXPECT_EQ(f["name"], names[k]);
    EXPECT_EQ(f["offset"], 4 * k);
    EXPECT_EQ(f["datatype"], 7);  // sensor_msgs/PointField FLOAT32
    EXPECT_EQ(f["count"], 1);
  }
  // the bytes read back as the same floats
  const auto& bytes = pc["data"].get_binary();
  ASSERT_EQ(bytes.size(), xyz.size() * 4);
  std::vector<float> back(xyz.size());
  std::memcpy(back.data(), bytes.data(), bytes.size());
  EXPECT_EQ(back, xyz);
}

TEST(RosJson, ImuOrientationIsXyzwFromTheReadingsWxyz) {
  ImuReading r;
  r.orientation = Eigen::Vector4d(0.1, 0.2, 0.3, 0.4);  // w, x, y, z
  r.angular_velocity = Eigen::Vector3d(1, 2, 3);
  r.linear_acceleration = Eigen::Vector3d(0, 0, 9.81);
  const Json m = ImuToJson(r, 1.0, "hand");
  EXPECT_EQ(Keys(m),
            (std::set<std::string>{"header", "orientation", "orientation_covariance",
                                   "angular_velocity", "angular_velocity_covariance",
                                   "linear_acceleration", "linear_acceleration_covariance"}));
  ExpectHeader(m["header"], 1, 0, "hand");
  EXPECT_EQ(m["orientation"], (Json{{"x", 0.2}, {"y", 0.3}, {"z", 0.4}, {"w", 0.1}}));
  EXPECT_EQ(m["angular_velocity"], (Json{{"x", 1.0}, {"y", 2.0}, {"z", 3.0}}));
  EXPECT_EQ(m["linear_acceleration"]["z"], 9.81);
  for (const char* k :
       {"orientation_covariance", "angular_velocity_covariance", "linear_acceleration_covariance"})
    EXPECT_EQ(m[k], Json(std::vector<double>(9, 0.0))) << k;
}

TEST(RosJson, Float64MultiArrayNeedsFiniteData) {
  EXPECT_EQ(Float64MultiArrayFromJson(Json{{"data", {1, 2}}, {"layout", Json::object()}}, "/c"),
            (std::vector<double>{1, 2}));
  EXPECT_EQ(ErrorOf([] {
              Float64MultiArrayFromJson(Json{{"values", {1}}}, "/r/cmd");
            }),
            "/r/cmd: std_msgs/Float64MultiArray needs 'data'");
  EXPECT_EQ(ErrorOf([] {
              Float64MultiArrayFromJson(Json{{"data", {1, nullptr}}}, "/r/cmd");
            }),
            "/r/cmd data holds a value that is not a number");
}

TEST(RosJson, JointTrajectoryRoundTrips) {
  JointTrajectory t;
  t.times = {0.0, 0.5, 1.25};
  for (int k = 0; k < 3; ++k) {
    t.positions.push_back(Eigen::Vector2d(0.1 * k, -0.2 * k));
    t.velocities.push_back(Eigen::Vector2d(k, -k));
  }
  const std::vector<std::string> names = {"j1", "j2"};
  const Json j = JointTrajectoryToJson(t, names);
  EXPECT_EQ(Keys(j), (std::set<std::string>{"joint_names", "points"}));
  EXPECT_EQ(Keys(j["points"][1]),
            (std::set<std::string>{"positions", "velocities", "time_from_start"}));
  EXPECT_EQ(j["points"][2]["time_from_start"], (Json{{"secs", 1}, {"nsecs", 250000000}}));

  const TrajectoryCommand c = JointTrajectoryFromJson(j, "traj");
  EXPECT_EQ(c.joint_names, names);
  ASSERT_EQ(c.times.size(), 3u);
  ASSERT_EQ(c.velocities.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(c.times[k], t.times[k], 1e-9);
    EXPECT_EQ(c.positions[k], (std::vector<double>{0.1 * k, -0.2 * k}));
    EXPECT_EQ(c.velocities[k], (std::vector<double>{double(k), double(-k)}));
  }

  // no velocities written when the trajectory has none; read back as none
  t.velocities.clear();
  const Json bare = JointTrajectoryToJson(t, names);
  EXPECT_FALSE(bare["points"][0].contains("velocities"));
  EXPECT_TRUE(JointTrajectoryFromJson(bare, "traj").velocities.empty());
}

TEST(RosJson, JointTrajectoryWithVelocitiesOnSomePointsInterpolatesPositionsAlone) {
  const Json j = {{"joint_names", {"a"}},
                  {"points",
                   {{{"positions", {0}}, {"velocities", {1}}},
                    {{"positions", {1}}, {"time_from_start", {{"secs", 1}, {"nsecs", 0}}}}}}};
  const TrajectoryCommand c = JointTrajectoryFromJson(j, "t");
  EXPECT_TRUE(c.velocities.empty());
  EXPECT_EQ(c.times, (std::vector<double>{0.0, 1.0}));
}

TEST(RosJson, BadJointTrajectoriesNameTheField) {
  EXPECT_EQ(ErrorOf([] {
              JointTrajectoryFromJson(Json{{"points", Json::array()}}, "/r/traj");
            }),
            "/r/traj: trajectory_msgs/JointTrajectory needs joint_names and points");
  EXPECT_EQ(
      ErrorOf([] {
        JointTrajectoryFromJson(Json{{"joint_names", {"a"}}, {"points", Json::array()}}, "/r/traj");
      }),
      "/r/traj: no points");
  EXPECT_EQ(ErrorOf([] {
              JointTrajectoryFromJson(Json{{"joint_names", {1}}, {"points", {Json::object()}}},
                                      "/r/traj");
            }),
            "/r/traj: joint_names holds a non-string");
  const Json second_bad = {{"joint_names", {"a"}},
                           {"points", {{{"positions", {0}}}, {{"velocities", {0}}}}}};
  EXPECT_EQ(ErrorOf([&] { JointTrajectoryFromJson(second_bad, "/r/traj"); }),
            "/r/traj points[1] has no positions");
  const Json far = {{"joint_names", {"a"}},
                    {"points", {{{"positions", {0}}, {"time_from_start", {{"secs", 1e9}}}}}}};
  EXPECT_NE(ErrorOf([&] {
              JointTrajectoryFromJson(far, "/r/traj");
            }).find("/r/traj points[0].time_from_start must be from 0 to 86400 s"),
            std::string::npos);
  const Json text_position = {{"joint_names", {"a"}}, {"points", {{{"positions", {"0"}}}}}};
  EXPECT_EQ(ErrorOf([&] { JointTrajectoryFromJson(text_position, "/r/traj"); }),
            "/r/traj points[0].positions holds a value that is not a number");
}

TEST(RosJson, JointTrajectoriesAboveTheBoundAreRefusedNamingTheCount) {
  auto trajectory = [](size_t n) {
    Json points = Json::array();
    for (size_t k = 0; k < n; ++k)
      points.push_back({{"positions", {0.1}}, {"time_from_start", 0.01 * (k + 1)}});
    return Json{{"joint_names", {"a"}}, {"points", points}};
  };
  EXPECT_EQ(JointTrajectoryFromJson(trajectory(kMaxTrajectoryPoints), "/r/traj").times.size(),
            kMaxTrajectoryPoints);
  EXPECT_EQ(
      ErrorOf([&] { JointTrajectoryFromJson(trajectory(kMaxTrajectoryPoints + 1), "/r/traj"); }),
      "/r/traj: 10001 points, more than the 10000 a trajectory may have");
}

TEST(RosJson, PlanRequestReadsJointAndPoseGoalsAndOptions) {
  PlanRequest joint = PlanRequestFromJson(Json{{"joint_goal", {0.1, 0.2}},
                                               {"execute", false},
                                               {"time_limit", 3},
                                               {"clearance", 0.01},
                                               {"algorithm", "PRM"}},
                                          "/r/plan");
  EXPECT_EQ(joint.joint_goal, (std::vector<double>{0.1, 0.2}));
  EXPECT_FALSE(joint.execute);
  EXPECT_EQ(joint.options.time_limit, 3.0);
  EXPECT_EQ(joint.options.clearance, 0.01);
  EXPECT_EQ(joint.options.algorithm, "PRM");

  const Pose X(Eigen::Vector3d(0.4, 0, 0.5), Eigen::Quaterniond(0, 1, 0, 0));
  PlanRequest pose = PlanRequestFromJson(Json{{"pose_goal", PoseToJson(X)}}, "/r/plan");
  EXPECT_TRUE(pose.joint_goal.empty());
  EXPECT_TRUE(pose.execute);  // the default
  EXPECT_TRUE(pose.pose_goal.p.isApprox(X.p));
  EXPECT_TRUE(pose.pose_goal.q.coeffs().isApprox(X.q.coeffs()));
}

TEST(RosJson, BadPlanRequestsNameTheField) {
  const std::string s = "/r/plan";
  EXPECT_EQ(ErrorOf([&] { PlanRequestFromJson(Json(1), s); }), "/r/plan: args must be an object");
  EXPECT_EQ(ErrorOf([&] { PlanRequestFromJson(Json::object(), s); }),
            "/r/plan: args need joint_goal (one value per joint) or pose_goal");
  EXPECT_EQ(ErrorOf([&] {
              PlanRequestFromJson(Json{{"joint_goal", "home"}}, s);
            }),
            "/r/plan joint_goal is not an array of numbers");
  EXPECT_EQ(ErrorOf([&] {
              PlanRequestFromJson(
                  Json{{"pose_goal",
                        {{"position", {{"x", 0}, {"y", 0}}}, {"orientation", Json::object()}}}},
                  s);
            }),
            "/r/plan: pose_goal field 'z' is missing or not a number");
  EXPECT_EQ(ErrorOf([&] {
              PlanRequestFromJson(Json{{"joint_goal", {0}}, {"execute", 1}}, s);
            }),
            "/r/plan: execute must be a boolean");
  EXPECT_EQ(ErrorOf([&] {
              PlanRequestFromJson(Json{{"joint_goal", {0}}, {"clearance", "1"}}, s);
            }),
            "/r/plan: clearance must be a number");
  EXPECT_EQ(ErrorOf([&] {
              PlanRequestFromJson(Json{{"joint_goal", {0}}, {"algorithm", 2}}, s);
            }),
            "op '/r/plan' needs a string 'algorithm'");
}

TEST(RosJson, PlanResultValues) {
  PlanResult r;
  r.success = true;
  r.planning_time = 0.125;
  r.trajectory.times = {0, 1};
  r.trajectory.positions = {Eigen::VectorXd::Zero(1), Eigen::VectorXd::Ones(1)};
  const Json v = PlanResultToJson(r, {"j"});
  EXPECT_EQ(Keys(v), (std::set<std::string>{"success", "message", "planning_time", "trajectory"}));
  EXPECT_TRUE(v["success"].is_boolean());
  EXPECT_EQ(v["message"], "");
  EXPECT_EQ(v["planning_time"], 0.125);
  EXPECT_EQ(JointTrajectoryFromJson(v["trajectory"], "t").positions.back(),
            (std::vector<double>{1.0}));
}

TEST(RosJson, StepCountCoversTheWholeRange) {
  EXPECT_EQ(StepCountFromJson(Json::object()), 1);
  EXPECT_EQ(StepCountFromJson(Json(nullptr)), 1);
  EXPECT_EQ(StepCountFromJson(Json{{"n", 7}}), 7);
  EXPECT_EQ(StepCountFromJson(Json{{"n", SimServer::kMaxStepRequest}}), SimServer::kMaxStepRequest);
  const std::string range =
      "/partsim/step: n must be an integer from 1 to " + std::to_string(SimServer::kMaxStepRequest);
  // as the numbers come from the network: positive integers parse as unsigned
  for (const std::string& n :
       {std::string("0"), std::string("-3"), std::string("2.5"), std::string("\"3\""),
        std::to_string(SimServer::kMaxStepRequest + 1), std::string("9223372036854775808")})
    EXPECT_EQ(ErrorOf([&] {
                StepCountFromJson(Json{{"n", Json::parse(n)}});
              }),
              range + ", got " + n)
        << n;
}

TEST(RosJson, TopicsListsNamesAndTypesInTheSameOrder) {
  const Json v = TopicsToJson({{"/b", "std_msgs/String"}, {"/a", kClockType}});
  EXPECT_EQ(
      v, (Json{{"topics", {"/a", "/b"}}, {"types", {"rosgraph_msgs/Clock", "std_msgs/String"}}}));
}

TEST(RosJson, ProtocolMessagesLeaveOutANullId) {
  EXPECT_EQ(StatusToJson("error", "bad", nullptr),
            (Json{{"op", "status"}, {"level", "error"}, {"msg", "bad"}}));
  EXPECT_EQ(StatusToJson("info", "ok", 3)["id"], 3);
  const Json r = ServiceResponseToJson("/s", Json::object(), true, "call1");
  EXPECT_EQ(r, (Json{{"op", "service_response"},
                     {"service", "/s"},
                     {"values", Json::object()},
                     {"result", true},
                     {"id", "call1"}}));
  EXPECT_FALSE(ServiceResponseToJson("/s", "why", false, nullptr).contains("id"));
  EXPECT_EQ(PublishToJson("/t", Json{{"data", 1}}),
            (Json{{"op", "publish"}, {"topic", "/t"}, {"msg", {{"data", 1}}}}));
}

}  // namespace
}  // namespace partsim::internal
