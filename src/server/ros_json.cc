#include "server/ros_json.h"

#include <cmath>

#include "partsim/core/error.h"
#include "partsim/server/sim_server.h"

namespace partsim::internal {

namespace {

Json Vector3ToJson(const Eigen::Vector3d& v) { return {{"x", v.x()}, {"y", v.y()}, {"z", v.z()}}; }

Json VectorToJson(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

}  // namespace

Json TextForm(Json j) {
  if (j.is_binary()) return Base64(j.get_binary().data(), j.get_binary().size());
  if (j.is_object() || j.is_array())
    for (auto& v : j) v = TextForm(std::move(v));
  return j;
}

Json StampToJson(double t) {
  double secs = std::floor(t);
  return {{"secs", static_cast<long long>(secs)},
          {"nsecs", static_cast<long long>(std::llround((t - secs) * 1e9)) % 1000000000}};
}

Json HeaderToJson(double t, const std::string& frame) {
  return {{"seq", 0}, {"stamp", StampToJson(t)}, {"frame_id", frame}};
}

double DurationFromJson(const Json& d, const std::string& what) {
  auto field = [&](const char* k) {
    if (!d.contains(k)) return 0.0;
    if (!d[k].is_number()) throw Error(what + "." + k + " is not a number");
    return d[k].get<double>();
  };
  double s = 0.0;
  if (d.is_number())
    s = d.get<double>();
  else if (!d.is_object())
    throw Error(what + " is not a duration");
  else if (d.contains("sec"))
    s = field("sec") + field("nanosec") * 1e-9;
  else
    s = field("secs") + field("nsecs") * 1e-9;
  if (!std::isfinite(s) || s < 0 || s > kMaxTrajectorySeconds)
    throw Error(what + " must be from 0 to 86400 s, got " + DumpJson(s));
  return s;
}

std::vector<double> NumbersFromJson(const Json& a, const std::string& what) {
  if (!a.is_array()) throw Error(what + " is not an array of numbers");
  std::vector<double> v;
  for (const Json& x : a) {
    if (!x.is_number()) throw Error(what + " holds a value that is not a number");
    double d = x.get<double>();
    if (!std::isfinite(d)) throw Error(what + " holds a value that is not finite");
    v.push_back(d);
  }
  return v;
}

Json PoseToJson(const Pose& X) {
  return {{"position", Vector3ToJson(X.p)},
          {"orientation", {{"x", X.q.x()}, {"y", X.q.y()}, {"z", X.q.z()}, {"w", X.q.w()}}}};
}

Pose PoseFromJson(const Json& pose, const std::string& what) {
  if (!pose.is_object() || !pose.contains("position") || !pose.contains("orientation"))
    throw Error(what + " needs position and orientation");
  auto num = [&](const Json& o, const char* k) {
    if (!o.is_object() || !o.contains(k) || !o[k].is_number())
      throw Error(what + " field '" + k + "' is missing or not a number");
    return o[k].get<double>();
  };
  const Json &p = pose["position"], &q = pose["orientation"];
  return Pose(Eigen::Vector3d(num(p, "x"), num(p, "y"), num(p, "z")),
              Eigen::Quaterniond(num(q, "w"), num(q, "x"), num(q, "y"), num(q, "z")));
}

Json ClockToJson(double t) { return {{"clock", StampToJson(t)}}; }

Json JointStateToJson(const JointStateReading& r, double t) {
  return {{"header", HeaderToJson(t, "")},
          {"name", r.names},
          {"position", r.position},
          {"velocity", r.velocity},
          {"effort", r.effort}};
}

Json TfToJson(const std::vector<FrameReading>& frames, double t) {
  Json tfs = Json::array();
  for (const FrameReading& f : frames) {
    const Pose& X = f.pose;
    tfs.push_back(
        {{"header", HeaderToJson(t, "world")},
         {"child_frame_id", f.child},
         {"transform",
          {{"translation", Vector3ToJson(X.p)},
           {"rotation", {{"x", X.q.x()}, {"y", X.q.y()}, {"z", X.q.z()}, {"w", X.q.w()}}}}}});
  }
  return {{"transforms", tfs}};
}

Json ImageToJson(int width, int height, std::vector<uint8_t> rgb, double t,
                 const std::string& frame) {
  return {{"header", HeaderToJson(t, frame)},
          {"height", height},
          {"width", width},
          {"encoding", "rgb8"},
          {"is_bigendian", 0},
          {"step", width * 3},
          {"data", Json::binary(std::move(rgb))}};
}

Json CameraInfoToJson(int width, int height, const std::vector<double>& P, double t,
                      const std::string& frame) {
  if (P.size() != 12)
    throw Error("CameraInfoToJson: P has " + std::to_string(P.size()) + " values, not 12 (3x4)");
  Json k = {P[0], P[1], P[2], P[4], P[5], P[6], P[8], P[9], P[10]};
  return {{"header", HeaderToJson(t, frame)},
          {"height", height},
          {"width", width},
          {"distortion_model", "plumb_bob"},
          {"D", {0.0, 0.0, 0.0, 0.0, 0.0}},
          {"K", k},
          {"R", {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}},
          {"P", P},
          {"binning_x", 0},
          {"binning_y", 0},
          {"roi",
           {{"x_offset", 0}, {"y_offset", 0}, {"height", 0}, {"width", 0}, {"do_rectify", false}}}};
}

Json PointCloudToJson(const std::vector<float>& xyz, double t, const std::string& frame) {
  static_assert(sizeof(float) == 4, "float32 points");
  // PointField datatype 7 is FLOAT32
  Json fields = Json::array();
  const char* names[] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k)
    fields.push_back({{"name", names[k]}, {"offset", 4 * k}, {"datatype", 7}, {"count", 1}});
  const size_t n = xyz.size() / 3;
  const uint8_t* bytes = reinterpret_cast<const uint8_t*>(xyz.data());
  return {{"header", HeaderToJson(t, frame)},
          {"height", 1},
          {"width", n},
          {"fields", fields},
          {"is_bigendian", false},
          {"point_step", 12},
          {"row_step", 12 * n},
          {"data", Json::binary(std::vector<uint8_t>(bytes, bytes + n * 12))},
          {"is_dense", true}};
}

Json ImuToJson(const ImuReading& r, double t, const std::string& frame) {
  const Json zeros = std::vector<double>(9, 0.0);
  return {{"header", HeaderToJson(t, frame)},
          {"orientation",
           {{"x", r.orientation[1]},
            {"y", r.orientation[2]},
            {"z", r.orientation[3]},
            {"w", r.orientation[0]}}},
          {"orientation_covariance", zeros},
          {"angular_velocity", Vector3ToJson(r.angular_velocity)},
          {"angular_velocity_covariance", zeros},
          {"linear_acceleration", Vector3ToJson(r.linear_acceleration)},
          {"linear_acceleration_covariance", zeros}};
}

std::vector<double> Float64MultiArrayFromJson(const Json& msg, const std::string& topic) {
  if (!msg.is_object() || !msg.contains("data"))
    throw Error(topic + ": std_msgs/Float64MultiArray needs 'data'");
  return NumbersFromJson(msg["data"], topic + " data");
}

TrajectoryCommand JointTrajectoryFromJson(const Json& msg, const std::string& what) {
  if (!msg.is_object() || !msg.contains("joint_names") || !msg["joint_names"].is_array() ||
      !msg.contains("points") || !msg["points"].is_array())
    throw Error(what + ": trajectory_msgs/JointTrajectory needs joint_names and points");
  TrajectoryCommand cmd;
  for (const Json& name : msg["joint_names"]) {
    if (!name.is_string()) throw Error(what + ": joint_names holds a non-string");
    cmd.joint_names.push_back(name.get<std::string>());
  }
  const Json& points = msg["points"];
  if (points.empty()) throw Error(what + ": no points");
  if (points.size() > kMaxTrajectoryPoints)
    throw Error(what + ": " + std::to_string(points.size()) + " points, more than the " +
                std::to_string(kMaxTrajectoryPoints) + " a trajectory may have");
  cmd.positions.reserve(points.size());
  cmd.times.reserve(points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    const Json& p = points[k];
    std::string where = what + " points[" + std::to_string(k) + "]";
    if (!p.is_object() || !p.contains("positions")) throw Error(where + " has no positions");
    cmd.positions.push_back(NumbersFromJson(p["positions"], where + ".positions"));
    if (p.contains("velocities") && p["velocities"].is_array() && !p["velocities"].empty())
      cmd.velocities.push_back(NumbersFromJson(p["velocities"], where + ".velocities"));
    cmd.times.push_back(p.contains("time_from_start")
                            ? DurationFromJson(p["time_from_start"], where + ".time_from_start")
                            : 0.0);
  }
  if (!cmd.velocities.empty() && cmd.velocities.size() != cmd.positions.size())
    cmd.velocities.clear();  // velocities on some points only: interpolate positions alone
  return cmd;
}

Json JointTrajectoryToJson(const JointTrajectory& t, const std::vector<std::string>& joint_names) {
  Json points = Json::array();
  for (size_t k = 0; k < t.times.size(); ++k) {
    Json p = {{"positions", VectorToJson(t.positions[k])},
              {"time_from_start", StampToJson(t.times[k])}};
    if (!t.velocities.empty()) p["velocities"] = VectorToJson(t.velocities[k]);
    points.push_back(p);
  }
  return {{"joint_names", joint_names}, {"points", points}};
}

PlanRequest PlanRequestFromJson(const Json& args, const std::string& service) {
  if (!args.is_object()) throw Error(service + ": args must be an object");
  PlanRequest req;
  if (args.contains("joint_goal"))
    req.joint_goal = NumbersFromJson(args["joint_goal"], service + " joint_goal");
  else if (args.contains("pose_goal") && args["pose_goal"].is_object())
    req.pose_goal = PoseFromJson(args["pose_goal"], service + ": pose_goal");
  else
    throw Error(service + ": args need joint_goal (one value per joint) or pose_goal");
  if (args.contains("execute")) {
    if (!args["execute"].is_boolean()) throw Error(service + ": execute must be a boolean");
    req.execute = args["execute"].get<bool>();
  }
  for (const char* k : {"time_limit", "clearance"})
    if (args.contains(k)) {
      if (!args[k].is_number()) throw Error(service + ": " + k + " must be a number");
      (k[0] == 't' ? req.options.time_limit : req.options.clearance) = args[k].get<double>();
    }
  if (args.contains("algorithm")) {
    if (!args["algorithm"].is_string())
      throw Error("op '" + service + "' needs a string 'algorithm'");
    req.options.algorithm = args["algorithm"].get<std::string>();
  }
  return req;
}

Json PlanResultToJson(const PlanResult& r, const std::vector<std::string>& joint_names) {
  return {{"success", r.success},
          {"message", r.message},
          {"planning_time", r.planning_time},
          {"trajectory", JointTrajectoryToJson(r.trajectory, joint_names)}};
}

long long StepCountFromJson(const Json& args) {
  if (!args.is_object() || !args.contains("n")) return 1;
  // the whole range is checked: no integer is truncated into a valid one
  const Json& a = args["n"];
  const bool in_range = a.is_number_unsigned()
                            ? a.get<uint64_t>() <= static_cast<uint64_t>(SimServer::kMaxStepRequest)
                            : a.is_number_integer();
  if (!in_range || a.get<long long>() < 1)
    throw Error("/partsim/step: n must be an integer from 1 to " +
                std::to_string(SimServer::kMaxStepRequest) + ", got " + DumpJson(a));
  return a.get<long long>();
}

Json TopicsToJson(const std::map<std::string, std::string>& topics) {
  Json names = Json::array(), types = Json::array();
  for (const auto& [topic, type] : topics) {
    names.push_back(topic);
    types.push_back(type);
  }
  return {{"topics", names}, {"types", types}};
}

Json StatusToJson(const std::string& level, const std::string& msg, const Json& id) {
  Json j = {{"op", "status"}, {"level", level}, {"msg", msg}};
  if (!id.is_null()) j["id"] = id;
  return j;
}

Json ServiceResponseToJson(const std::string& service, const Json& values, bool result,
                           const Json& id) {
  Json r = {
      {"op", "service_response"}, {"service", service}, {"values", values}, {"result", result}};
  if (!id.is_null()) r["id"] = id;
  return r;
}

Json PublishToJson(const std::string& topic, Json msg) {
  return {{"op", "publish"}, {"topic", topic}, {"msg", std::move(msg)}};
}

}  // namespace partsim::internal
