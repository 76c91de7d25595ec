// ROS messages as rosbridge v2 JSON: pure functions between partsim's readings and commands and
// the `msg` (or service `args` / `values`) objects of rosbridge, with no socket or server state.
// Field names and types are ROS 1's (rosbridge_suite's JSON form): stamps {secs, nsecs}, uint8[]
// fields as json::binary values (base64 strings in JSON text, byte strings in CBOR; see
// TextForm). Decoders throw partsim::Error whose message names `what` and the field at fault.
#pragma once

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/json_parse.h"
#include "partsim/planning/planner.h"
#include "partsim/robot/controllers.h"
#include "partsim/server/served_robot.h"

namespace partsim::internal {

using Json = nlohmann::json;

// ---- message type names ----
constexpr const char* kClockType = "rosgraph_msgs/Clock";
constexpr const char* kJointStateType = "sensor_msgs/JointState";
constexpr const char* kTfType = "tf2_msgs/TFMessage";
constexpr const char* kFloat64ArrayType = "std_msgs/Float64MultiArray";
constexpr const char* kTrajectoryType = "trajectory_msgs/JointTrajectory";
constexpr const char* kImageType = "sensor_msgs/Image";
constexpr const char* kCameraInfoType = "sensor_msgs/CameraInfo";
constexpr const char* kPointCloud2Type = "sensor_msgs/PointCloud2";
constexpr const char* kImuType = "sensor_msgs/Imu";

// ---- text ----
// DumpJson and Base64: core/json_parse.h
/// The message as JSON text carries it: every binary value becomes its base64 string.
Json TextForm(Json j);

// ---- primitives ----
/// std_msgs/Time {secs, nsecs} of `t` s (t >= 0).
Json StampToJson(double t);
/// std_msgs/Header {seq: 0, stamp, frame_id}.
Json HeaderToJson(double t, const std::string& frame);
/// Seconds of a ROS duration {secs, nsecs} ({sec, nanosec} in ROS 2, or a number of seconds)
/// of `what`; it must be finite and within [0, kMaxTrajectorySeconds].
double DurationFromJson(const Json& d, const std::string& what);
/// Finite numbers of a JSON array `what`.
std::vector<double> NumbersFromJson(const Json& a, const std::string& what);
/// geometry_msgs/Pose {position {x, y, z}, orientation {x, y, z, w}}.
Json PoseToJson(const Pose& X);
/// Reads a geometry_msgs/Pose named `what` (errors: "<what> needs position and orientation",
/// "<what> field 'x' is missing or not a number").
Pose PoseFromJson(const Json& pose, const std::string& what);

// ---- messages the simulation publishes (t: simulation time, s) ----
/// rosgraph_msgs/Clock {clock}.
Json ClockToJson(double t);
/// sensor_msgs/JointState {header, name, position, velocity, effort}.
Json JointStateToJson(const JointStateReading& r, double t);
/// tf2_msgs/TFMessage {transforms: [geometry_msgs/TransformStamped]}, each in frame "world".
Json TfToJson(const std::vector<FrameReading>& frames, double t);
/// sensor_msgs/Image "rgb8" of `width` x `height` pixels, `rgb` packed rows (3 bytes a pixel).
Json ImageToJson(int width, int height, std::vector<uint8_t> rgb, double t,
                 const std::string& frame);
/// sensor_msgs/CameraInfo of a pinhole camera without distortion: `P` the 3x4 projection
/// [K | 0] row-major (12 values), K its left 3x3, R identity.
Json CameraInfoToJson(int width, int height, const std::vector<double>& P, double t,
                      const std::string& frame);
/// sensor_msgs/PointCloud2 of one row: x, y, z float32 fields (`xyz` triples, metres).
Json PointCloudToJson(const std::vector<float>& xyz, double t, const std::string& frame);
/// sensor_msgs/Imu of a reading (orientation wxyz becomes {x, y, z, w}), zero covariances.
Json ImuToJson(const ImuReading& r, double t, const std::string& frame);

// ---- commands ----
/// The data of a std_msgs/Float64MultiArray sent to `topic`.
std::vector<double> Float64MultiArrayFromJson(const Json& msg, const std::string& topic);
/// trajectory_msgs/JointTrajectory {joint_names, points: [{positions, velocities,
/// time_from_start}]}: velocities are kept only when every point has them; from 1 to
/// kMaxTrajectoryPoints points.
TrajectoryCommand JointTrajectoryFromJson(const Json& msg, const std::string& what);
/// trajectory_msgs/JointTrajectory of a timed trajectory over `joint_names`.
Json JointTrajectoryToJson(const JointTrajectory& t, const std::vector<std::string>& joint_names);

// ---- partsim's services ----
/// Args of /<robot>/plan named `service`: {joint_goal: [..]} or {pose_goal: geometry_msgs/Pose},
/// optional execute (bool), time_limit, clearance (numbers) and algorithm (string).
PlanRequest PlanRequestFromJson(const Json& args, const std::string& service);
/// Values of /<robot>/plan: {success, message, planning_time, trajectory}.
Json PlanResultToJson(const PlanResult& r, const std::vector<std::string>& joint_names);
/// Steps asked of /partsim/step by args {n} (default 1), from 1 to SimServer::kMaxStepRequest.
long long StepCountFromJson(const Json& args);
/// Values of /rosapi/topics: {topics, types}, from topic -> type.
Json TopicsToJson(const std::map<std::string, std::string>& topics);

// ---- protocol messages ----
/// {op: status, level, msg[, id]}: the id is left out when null.
Json StatusToJson(const std::string& level, const std::string& msg, const Json& id);
/// {op: service_response, service, values, result[, id]}.
Json ServiceResponseToJson(const std::string& service, const Json& values, bool result,
                           const Json& id);
/// {op: publish, topic, msg}.
Json PublishToJson(const std::string& topic, Json msg);

}  // namespace partsim::internal
