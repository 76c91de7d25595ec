// What a RosbridgeServer serves of a ServedRobot: /clock, /joint_states, /tf, the IMU and the
// cameras' topics published after each step, the joint and trajectory command topics, motion
// planning (/<robot>/plan), /partsim/stats and the SimServer's controls, all added to the
// protocol's tables.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "partsim/server/rosbridge.h"
#include "partsim/server/served_robot.h"
#include "server/rosbridge_protocol.h"

namespace partsim::internal {

class RosbridgeRobot {
 public:
  /// Adds the robot's topics and services to `protocol`; `stats` gives what /partsim/stats
  /// answers. The robot and the protocol must outlive this object.
  RosbridgeRobot(ServedRobot* robot, RosbridgeProtocol* protocol,
                 std::function<RosbridgeStats()> stats);

  /// After step `steps` (simulation thread): /clock, /joint_states and /tf, then the sensors
  /// due.
  void OnStep(long long steps);

 private:
  std::string Prefix() const { return "/" + robot_->GetName(); }
  std::optional<Json> CallPlan(const ClientPtr& c, const std::string& service, const Json& args,
                               const Json& id);
  void HandleCommand(const ClientPtr& c, const std::string& topic, const Json& msg, const Json& id);
  ServedRobot::ErrorSink ErrorsTo(const ClientPtr& client, const Json& id);
  const std::string& SensorTopicName(SensorStream stream, size_t camera) const;
  void PublishSensors(double t, WallClock::time_point now);

  ServedRobot* robot_;
  SimServer* sim_;
  RosbridgeProtocol* protocol_;
  std::function<RosbridgeStats()> stats_;
  struct CameraTopics {
    std::string image, points, info;
  };
  std::vector<CameraTopics> camera_topics_;  // one per robot_->GetCameras()
  SensorSchedule sensors_;                   // simulation thread
};

}  // namespace partsim::internal
