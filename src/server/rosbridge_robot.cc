#include "server/rosbridge_robot.h"

#include "partsim/core/error.h"

namespace partsim::internal {

RosbridgeRobot::RosbridgeRobot(ServedRobot* robot, RosbridgeProtocol* protocol,
                               std::function<RosbridgeStats()> stats)
    : robot_(robot),
      sim_(robot->GetSim()),
      protocol_(protocol),
      stats_(std::move(stats)),
      sensors_(robot) {
  for (size_t i = 0; i < robot->GetCameras().size(); ++i)
    camera_topics_.push_back({SensorTopic(*robot, SensorStream::kImage, i),
                              SensorTopic(*robot, SensorStream::kPoints, i),
                              SensorTopic(*robot, SensorStream::kCameraInfo, i)});
  // what the simulation publishes
  for (const auto& [name, type] :
       std::vector<std::pair<std::string, const char*>>{{"/clock", kClockType},
                                                        {"/joint_states", kJointStateType},
                                                        {"/tf", kTfType},
                                                        {"/imu", kImuType}})
    protocol->AddTopic(name, type);
  for (const CameraTopics& c : camera_topics_) {
    protocol->AddTopic(c.image, kImageType);
    protocol->AddTopic(c.info, kCameraInfoType);
    protocol->AddTopic(c.points, kPointCloud2Type);
  }
  // what it takes commands on
  auto command = [this](const ClientPtr& c, const std::string& topic, const Json& msg,
                        const Json& id) { HandleCommand(c, topic, msg, id); };
  for (const char* kind : {"position", "velocity", "effort"})
    protocol->AddTopic(Prefix() + "/joint_" + kind + "_controller/command", kFloat64ArrayType,
                       command);
  protocol->AddTopic(Prefix() + "/joint_trajectory_controller/command", kTrajectoryType, command);
  // the simulation's controls, its counters, and planning
  RosbridgeSimControls controls;
  controls.pause = [this] { sim_->Pause(); };
  controls.resume = [this] { sim_->Resume(); };
  controls.reset = [this] { sim_->Reset(); };
  controls.step = [this](long long n) { sim_->StepN(n); };
  protocol->SetSimControls(controls);
  protocol->AddService("/partsim/stats",
                       [this](const ClientPtr&, const std::string&, const Json&,
                              const Json&) -> std::optional<Json> {
                         const RosbridgeStats s = stats_();
                         return Json{{"clients", s.clients},
                                     {"messages_sent", s.messages_sent},
                                     {"messages_dropped", s.messages_dropped},
                                     {"commands", s.commands},
                                     {"mean_latency_steps", s.mean_latency_steps},
                                     {"max_latency_steps", s.max_latency_steps},
                                     {"peak_buffered_bytes", s.peak_buffered_bytes},
                                     {"clock_steps", sim_->GetClockSteps()},
                                     {"timestep", sim_->GetTimestep()}};
                       });
  protocol->AddService(Prefix() + "/plan",
                       [this](const ClientPtr& c, const std::string& service, const Json& args,
                              const Json& id) { return CallPlan(c, service, args, id); });
  // a client's plans are dropped when it leaves, the one running stopped: nobody waits for the
  // answers
  protocol->AddDisconnectHook([this](const ClientPtr& c) { robot_->CancelPlans(c.get()); });
}

void RosbridgeRobot::OnStep(long long steps) {
  const double t = steps * sim_->GetTimestep();
  const WallClock::time_point now = WallClock::now();
  if (protocol_->ClientCount() == 0) return;
  protocol_->Publish(
      "/clock", [&] { return ClockToJson(t); }, now);
  protocol_->Publish(
      "/joint_states", [&] { return JointStateToJson(robot_->ReadJointStates(), t); }, now);
  protocol_->Publish(
      "/tf", [&] { return TfToJson(robot_->ReadFrames(), t); }, now);
  PublishSensors(t, now);
}

/// /<robot>/plan: answers once planned, from the planning worker.
std::optional<Json> RosbridgeRobot::CallPlan(const ClientPtr& c, const std::string& service,
                                             const Json& args, const Json& id) {
  PlanRequest req = PlanRequestFromJson(args, service);
  req.owner = c.get();  // bounded per client, cancelled when it leaves (RemoveClient)
  std::weak_ptr<RosbridgeClient> weak = c;
  robot_->Plan(req, [this, weak, service, id](const PlanResult& r) {
    if (ClientPtr cp = weak.lock())
      protocol_->Reply(cp, ServiceResponseToJson(
                               service, PlanResultToJson(r, robot_->GetJointNames()), true, id));
  });
  return std::nullopt;
}

ServedRobot::ErrorSink RosbridgeRobot::ErrorsTo(const ClientPtr& client, const Json& id) {
  std::weak_ptr<RosbridgeClient> weak = client;
  return [this, weak, id](const std::string& e) {
    if (ClientPtr c = weak.lock()) protocol_->SendError(c, e);
  };
}

/// Checks and applies a message published to one of the simulation's command topics (applied
/// on the simulation thread).
void RosbridgeRobot::HandleCommand(const ClientPtr& c, const std::string& topic, const Json& msg,
                                   const Json& id) {
  if (!msg.is_object()) throw Error("publish to " + topic + ": msg is not an object");
  for (const char* kind : {"position", "velocity", "effort"}) {
    if (topic != Prefix() + "/joint_" + kind + "_controller/command") continue;
    const std::vector<double> data = Float64MultiArrayFromJson(msg, topic);
    if (kind[0] == 'p')
      robot_->CommandPositions(data, topic, ErrorsTo(c, id));
    else if (kind[0] == 'v')
      robot_->CommandVelocities(data, topic, ErrorsTo(c, id));
    else
      robot_->CommandEfforts(data, topic, ErrorsTo(c, id));
    return;
  }
  const TrajectoryCommand cmd = JointTrajectoryFromJson(msg, topic);
  auto errors = ErrorsTo(c, id);
  robot_->CommandTrajectory(cmd, topic, [errors](TrajectoryOutcome o, const std::string& m) {
    if (o == TrajectoryOutcome::kInvalidGoal) errors(m);
  });
}

const std::string& RosbridgeRobot::SensorTopicName(SensorStream stream, size_t camera) const {
  static const std::string imu = "/imu";
  switch (stream) {
    case SensorStream::kImu:
      return imu;
    case SensorStream::kImage:
      return camera_topics_[camera].image;
    case SensorStream::kPoints:
      return camera_topics_[camera].points;
    default:
      return camera_topics_[camera].info;
  }
}

/// Reads the sensors somebody subscribes to, when due (ServedRobot's schedule), and publishes
/// them.
void RosbridgeRobot::PublishSensors(double t, WallClock::time_point now) {
  const std::vector<CameraSensor>& cams = robot_->GetCameras();
  SensorSchedule::Output out;
  out.imu = [&](const ImuReading& r) {
    protocol_->Publish(
        "/imu", [&] { return ImuToJson(r, t, robot_->GetImuFrame()); }, now);
  };
  out.picture = [&](size_t i, const Camera& cam, bool image, bool points) {
    const std::string& frame = cams[i].frame;
    if (image)
      protocol_->Publish(
          camera_topics_[i].image,
          [&] { return ImageToJson(cam.GetWidth(), cam.GetHeight(), CameraRgb8(cam), t, frame); },
          now);
    if (points)
      protocol_->Publish(
          camera_topics_[i].points,
          [&] { return PointCloudToJson(CameraOpticalPoints(cam), t, frame); }, now);
  };
  out.camera_info = [&](size_t i, const Camera& cam) {
    protocol_->Publish(
        camera_topics_[i].info,
        [&] {
          return CameraInfoToJson(cam.GetWidth(), cam.GetHeight(), CameraProjection(cam), t,
                                  cams[i].frame);
        },
        now);
  };
  sensors_.Publish(
      t,
      [&](SensorStream stream, size_t camera) {
        return protocol_->Wanted(SensorTopicName(stream, camera));
      },
      out);
}

}  // namespace partsim::internal
