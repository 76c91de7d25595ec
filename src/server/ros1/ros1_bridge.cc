#include "partsim/server/ros1_bridge.h"

#include <actionlib/server/action_server.h>
#include <control_msgs/FollowJointTrajectoryAction.h>
#include <geometry_msgs/TransformStamped.h>
#include <partsim_msgs/PlanMotion.h>
#include <partsim_msgs/Step.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Float64MultiArray.h>
#include <std_srvs/Empty.h>
#include <tf2_msgs/TFMessage.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <chrono>
#include <cstring>
#include <future>
#include <map>
#include <mutex>
#include <thread>

#include "partsim/core/error.h"

namespace partsim {

namespace {

using FollowServer = actionlib::ActionServer<control_msgs::FollowJointTrajectoryAction>;
using GoalHandle = FollowServer::GoalHandle;

std::vector<double> ToStd(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

/// The command of a trajectory message (`what` names it in errors); throws partsim::Error for
/// more than kMaxTrajectoryPoints points, before any is converted (the rosbridge
/// server's bound).
TrajectoryCommand FromMsg(const trajectory_msgs::JointTrajectory& t, const std::string& what) {
  if (t.points.size() > kMaxTrajectoryPoints)
    throw Error(what + ": " + std::to_string(t.points.size()) + " points, more than the " +
                std::to_string(kMaxTrajectoryPoints) + " a trajectory may have");
  TrajectoryCommand c;
  c.joint_names = t.joint_names;
  bool all_vel = !t.points.empty();
  for (const trajectory_msgs::JointTrajectoryPoint& p : t.points) {
    c.times.push_back(p.time_from_start.toSec());
    c.positions.push_back(p.positions);
    all_vel = all_vel && !p.velocities.empty();
  }
  if (all_vel)  // velocities on some points only: interpolate the positions alone
    for (const trajectory_msgs::JointTrajectoryPoint& p : t.points)
      c.velocities.push_back(p.velocities);
  return c;
}

int32_t ErrorCode(TrajectoryOutcome o) {
  using R = control_msgs::FollowJointTrajectoryResult;
  switch (o) {
    case TrajectoryOutcome::kSucceeded:
      return R::SUCCESSFUL;
    case TrajectoryOutcome::kInvalidGoal:
      return R::INVALID_GOAL;
    case TrajectoryOutcome::kInvalidJoints:
      return R::INVALID_JOINTS;
    case TrajectoryOutcome::kPathToleranceViolated:
      return R::PATH_TOLERANCE_VIOLATED;
    case TrajectoryOutcome::kGoalToleranceViolated:
      return R::GOAL_TOLERANCE_VIOLATED;
    case TrajectoryOutcome::kPreempted:
      break;
  }
  return R::SUCCESSFUL;
}

}  // namespace

struct Ros1Bridge::Impl {
  ServedRobot* robot;
  SimServer* sim;
  Ros1Options options;
  std::string prefix;  // "/<robot>"
  std::atomic<bool> started{false};

  std::unique_ptr<ros::NodeHandle> nh;
  std::unique_ptr<ros::AsyncSpinner> spinner;
  ros::Publisher clock_pub, joint_pub, tf_pub, imu_pub;
  struct CameraPubs {
    ros::Publisher image, info, points;
  };
  std::vector<CameraPubs> cameras;           // one per robot->GetCameras()
  std::unique_ptr<SensorSchedule> schedule;  // simulation thread
  std::vector<ros::Subscriber> subs;
  std::vector<ros::ServiceServer> services;
  std::unique_ptr<FollowServer> follow;

  // goals of the action, by ServedRobot goal id (set on the callback threads)
  std::mutex goals_mutex;
  std::map<std::string, long long> goal_ids;  // action goal id -> ServedRobot goal id

  // ---- simulation thread ----
  void OnStep(long long steps) {
    if (!started) return;
    const double t = steps * sim->GetTimestep();
    const ros::Time stamp(t);
    if (clock_pub.getNumSubscribers() > 0) {
      rosgraph_msgs::Clock c;
      c.clock = stamp;
      clock_pub.publish(c);
    }
    if (joint_pub.getNumSubscribers() > 0) {
      JointStateReading r = robot->ReadJointStates();
      sensor_msgs::JointState js;
      js.header.stamp = stamp;
      js.name = r.names;
      js.position = r.position;
      js.velocity = r.velocity;
      js.effort = r.effort;
      joint_pub.publish(js);
    }
    if (tf_pub.getNumSubscribers() > 0) {
      tf2_msgs::TFMessage tf;
      for (const FrameReading& f : robot->ReadFrames()) {
        geometry_msgs::TransformStamped ts;
        ts.header.stamp = stamp;
        ts.header.frame_id = "world";
        ts.child_frame_id = f.child;
        ts.transform.translation.x = f.pose.p.x();
        ts.transform.translation.y = f.pose.p.y();
        ts.transform.translation.z = f.pose.p.z();
        ts.transform.rotation.x = f.pose.q.x();
        ts.transform.rotation.y = f.pose.q.y();
        ts.transform.rotation.z = f.pose.q.z();
        ts.transform.rotation.w = f.pose.q.w();
        tf.transforms.push_back(ts);
      }
      tf_pub.publish(tf);
    }
    PublishSensors(t, stamp);
  }

  /// Reads the sensors somebody subscribes to, when due (ServedRobot's schedule), and publishes
  /// them.
  void PublishSensors(double t, const ros::Time& stamp) {
    const std::vector<CameraSensor>& sensors = robot->GetCameras();
    SensorSchedule::Output out;
    out.imu = [&](const ImuReading& r) {
      sensor_msgs::Imu m;
      m.header.stamp = stamp;
      m.header.frame_id = robot->GetImuFrame();
      m.orientation.w = r.orientation[0];
      m.orientation.x = r.orientation[1];
      m.orientation.y = r.orientation[2];
      m.orientation.z = r.orientation[3];
      m.angular_velocity.x = r.angular_velocity.x();
      m.angular_velocity.y = r.angular_velocity.y();
      m.angular_velocity.z = r.angular_velocity.z();
      m.linear_acceleration.x = r.linear_acceleration.x();
      m.linear_acceleration.y = r.linear_acceleration.y();
      m.linear_acceleration.z = r.linear_acceleration.z();
      imu_pub.publish(m);
    };
    out.picture = [&](size_t i, const Camera& cam, bool image, bool points) {
      const std::string& frame = sensors[i].frame;
      if (image) {
        sensor_msgs::Image m;
        m.header.stamp = stamp;
        m.header.frame_id = frame;
        m.height = cam.GetHeight();
        m.width = cam.GetWidth();
        m.encoding = "rgb8";
        m.is_bigendian = 0;
        m.step = 3 * m.width;
        m.data = CameraRgb8(cam);
        cameras[i].image.publish(m);
      }
      if (points) {
        std::vector<float> xyz = CameraOpticalPoints(cam);
        sensor_msgs::PointCloud2 m;
        m.header.stamp = stamp;
        m.header.frame_id = frame;
        m.height = 1;
        m.width = static_cast<uint32_t>(xyz.size() / 3);
        const char* names[] = {"x", "y", "z"};
        for (int k = 0; k < 3; ++k) {
          sensor_msgs::PointField f;
          f.name = names[k];
          f.offset = 4 * k;
          f.datatype = sensor_msgs::PointField::FLOAT32;
          f.count = 1;
          m.fields.push_back(f);
        }
        m.is_bigendian = false;
        m.point_step = 12;
        m.row_step = 12 * m.width;
        m.data.resize(xyz.size() * 4);
        std::memcpy(m.data.data(), xyz.data(), m.data.size());
        m.is_dense = true;
        cameras[i].points.publish(m);
      }
    };
    out.camera_info = [&](size_t i, const Camera& cam) {
      std::vector<double> p = CameraProjection(cam);
      sensor_msgs::CameraInfo m;
      m.header.stamp = stamp;
      m.header.frame_id = sensors[i].frame;
      m.height = cam.GetHeight();
      m.width = cam.GetWidth();
      m.distortion_model = "plumb_bob";
      m.D.assign(5, 0.0);
      m.K = {p[0], p[1], p[2], p[4], p[5], p[6], p[8], p[9], p[10]};
      m.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
      std::copy(p.begin(), p.end(), m.P.begin());
      cameras[i].info.publish(m);
    };
    schedule->Publish(
        t,
        [&](SensorStream stream, size_t i) {
          switch (stream) {
            case SensorStream::kImu:
              return imu_pub.getNumSubscribers() > 0;
            case SensorStream::kImage:
              return cameras[i].image.getNumSubscribers() > 0;
            case SensorStream::kPoints:
              return cameras[i].points.getNumSubscribers() > 0;
            default:
              return cameras[i].info.getNumSubscribers() > 0;
          }
        },
        out);
  }

  // ---- callback threads ----
  void OnArrayCommand(const std::string& kind, const std::string& topic,
                      const std_msgs::Float64MultiArray::ConstPtr& msg) {
    auto log = [topic](const std::string& e) { ROS_ERROR_STREAM("partsim: " << e); };
    try {
      if (kind == "position")
        robot->CommandPositions(msg->data, topic, log);
      else if (kind == "velocity")
        robot->CommandVelocities(msg->data, topic, log);
      else
        robot->CommandEfforts(msg->data, topic, log);
    } catch (const std::exception& e) {
      log(e.what());
    }
  }

  void OnTrajectory(const std::string& topic,
                    const trajectory_msgs::JointTrajectory::ConstPtr& msg) {
    try {
      robot->CommandTrajectory(FromMsg(*msg, topic), topic,
                               [](TrajectoryOutcome o, const std::string& m) {
                                 if (o == TrajectoryOutcome::kInvalidGoal)
                                   ROS_ERROR_STREAM("partsim: " << m);
                               });
    } catch (const std::exception& e) {
      ROS_ERROR_STREAM("partsim: " << e.what());
    }
  }

  void OnGoal(GoalHandle gh) {
    const control_msgs::FollowJointTrajectoryGoal& goal = *gh.getGoal();
    const std::string what = "follow_joint_trajectory goal";
    TrajectoryCommand c;
    control_msgs::FollowJointTrajectoryResult result;
    try {
      c = FromMsg(goal.trajectory, what);
      for (const control_msgs::JointTolerance& t : goal.path_tolerance)
        c.path_tolerance.emplace_back(t.name, t.position);
      for (const control_msgs::JointTolerance& t : goal.goal_tolerance)
        c.goal_tolerance.emplace_back(t.name, t.position);
      c.goal_time_tolerance = goal.goal_time_tolerance.toSec();
      robot->CheckTrajectory(c, what);
    } catch (const std::exception& e) {
      // the joints at fault, or the goal (the words after the prefix that names the goal)
      std::string why = e.what();
      if (why.rfind(what, 0) == 0) why = why.substr(what.size());
      const bool joints =
          why.find("joint") != std::string::npos && why.find("joint_names") == std::string::npos;
      result.error_code = joints ? result.INVALID_JOINTS : result.INVALID_GOAL;
      result.error_string = e.what();
      gh.setRejected(result, e.what());
      return;
    }
    gh.setAccepted();
    const std::string key = gh.getGoalID().id;
    auto done = [this, gh, key](TrajectoryOutcome o, const std::string& msg) mutable {
      {
        std::lock_guard<std::mutex> lock(goals_mutex);
        goal_ids.erase(key);
      }
      control_msgs::FollowJointTrajectoryResult r;
      r.error_code = ErrorCode(o);
      r.error_string = msg;
      if (o == TrajectoryOutcome::kSucceeded)
        gh.setSucceeded(r);
      else if (o == TrajectoryOutcome::kPreempted)
        gh.setCanceled(r, msg);
      else
        gh.setAborted(r, msg);
    };
    auto feedback = [gh](const TrajectoryFeedback& f) mutable {
      control_msgs::FollowJointTrajectoryFeedback fb;
      fb.header.stamp = ros::Time(f.time);
      fb.joint_names = f.joint_names;
      fb.desired.positions = ToStd(f.desired);
      fb.desired.velocities = ToStd(f.desired_velocity);
      fb.actual.positions = ToStd(f.actual);
      fb.actual.velocities = ToStd(f.actual_velocity);
      fb.error.positions = ToStd(f.error);
      fb.error.velocities = ToStd(f.desired_velocity - f.actual_velocity);
      gh.publishFeedback(fb);
    };
    try {
      long long id = robot->CommandTrajectory(c, what, done, feedback);
      std::lock_guard<std::mutex> lock(goals_mutex);
      goal_ids[key] = id;
    } catch (const std::exception& e) {
      result.error_code = result.INVALID_GOAL;
      result.error_string = e.what();
      gh.setAborted(result, e.what());
    }
  }

  void OnCancel(GoalHandle gh) {
    std::lock_guard<std::mutex> lock(goals_mutex);
    auto it = goal_ids.find(gh.getGoalID().id);
    if (it != goal_ids.end()) robot->CancelTrajectory(it->second);
  }

  bool OnPlan(partsim_msgs::PlanMotion::Request& req, partsim_msgs::PlanMotion::Response& res) {
    PlanRequest r;
    r.joint_goal = req.joint_goal;
    const geometry_msgs::Pose& p = req.pose_goal;
    r.pose_goal = Pose(
        Eigen::Vector3d(p.position.x, p.position.y, p.position.z),
        Eigen::Quaterniond(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z));
    r.execute = req.execute;
    if (req.time_limit > 0) r.options.time_limit = req.time_limit;
    auto promise = std::make_shared<std::promise<PlanResult>>();
    std::future<PlanResult> fut = promise->get_future();
    try {
      robot->Plan(r, [promise](const PlanResult& pr) { promise->set_value(pr); });
    } catch (const std::exception& e) {
      res.success = false;
      res.message = e.what();
      return true;
    }
    const double wait = r.options.time_limit + 30.0;
    if (fut.wait_for(std::chrono::duration<double>(wait)) != std::future_status::ready) {
      res.success = false;
      res.message = "planning did not answer in time";
      return true;
    }
    PlanResult pr = fut.get();
    res.success = pr.success;
    res.message = pr.message;
    res.planning_time = pr.planning_time;
    res.trajectory.joint_names = robot->GetJointNames();
    const JointTrajectory& t = pr.trajectory;
    for (size_t k = 0; k < t.times.size(); ++k) {
      trajectory_msgs::JointTrajectoryPoint pt;
      pt.positions = ToStd(t.positions[k]);
      if (!t.velocities.empty()) pt.velocities = ToStd(t.velocities[k]);
      pt.time_from_start = ros::Duration(t.times[k]);
      res.trajectory.points.push_back(pt);
    }
    return true;
  }
};

Ros1Bridge::Ros1Bridge(ServedRobot* robot, const Ros1Options& options)
    : impl_(std::make_unique<Impl>()) {
  if (!robot) throw Error("Ros1Bridge: robot is null");
  if (options.node_name.empty()) throw Error("Ros1Bridge: empty node_name");
  impl_->robot = robot;
  impl_->sim = robot->GetSim();
  impl_->options = options;
  impl_->prefix = "/" + robot->GetName();
  robot->GetSim()->AddStepCallback([this](long long steps) { impl_->OnStep(steps); });
}

Ros1Bridge::~Ros1Bridge() { Stop(); }

void Ros1Bridge::Start() {
  Impl& m = *impl_;
  if (m.started) throw Error("Ros1Bridge: already started");
  if (!ros::isInitialized()) {
    ros::M_string remappings;
    ros::init(remappings, m.options.node_name, ros::init_options::NoSigintHandler);
  }
  const auto t0 = std::chrono::steady_clock::now();
  while (!ros::master::check()) {
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >
        m.options.master_timeout)
      throw Error("ROS 1: no master at " + ros::master::getURI() +
                  " (start roscore or rosmaster, " + "or set ROS_MASTER_URI)");
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  if (m.options.use_sim_time) ros::param::set("/use_sim_time", true);
  m.nh = std::make_unique<ros::NodeHandle>();
  ros::NodeHandle& nh = *m.nh;
  m.clock_pub = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  m.joint_pub = nh.advertise<sensor_msgs::JointState>("/joint_states", 10);
  m.tf_pub = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);
  m.imu_pub = nh.advertise<sensor_msgs::Imu>(SensorTopic(*m.robot, SensorStream::kImu), 10);
  for (size_t i = 0; i < m.robot->GetCameras().size(); ++i) {
    Impl::CameraPubs p;
    p.image = nh.advertise<sensor_msgs::Image>(SensorTopic(*m.robot, SensorStream::kImage, i), 2);
    p.info = nh.advertise<sensor_msgs::CameraInfo>(
        SensorTopic(*m.robot, SensorStream::kCameraInfo, i), 2);
    p.points =
        nh.advertise<sensor_msgs::PointCloud2>(SensorTopic(*m.robot, SensorStream::kPoints, i), 2);
    m.cameras.push_back(p);
  }
  m.schedule = std::make_unique<SensorSchedule>(m.robot);
  Impl* im = impl_.get();
  for (const char* kind : {"position", "velocity", "effort"}) {
    const std::string k = kind, topic = m.prefix + "/joint_" + k + "_controller/command";
    m.subs.push_back(nh.subscribe<std_msgs::Float64MultiArray>(
        topic, 10, [im, k, topic](const std_msgs::Float64MultiArray::ConstPtr& msg) {
          im->OnArrayCommand(k, topic, msg);
        }));
  }
  const std::string traj_topic = m.prefix + "/joint_trajectory_controller/command";
  m.subs.push_back(nh.subscribe<trajectory_msgs::JointTrajectory>(
      traj_topic, 10, [im, traj_topic](const trajectory_msgs::JointTrajectory::ConstPtr& msg) {
        im->OnTrajectory(traj_topic, msg);
      }));
  m.follow = std::make_unique<FollowServer>(
      nh, m.prefix + "/joint_trajectory_controller/follow_joint_trajectory",
      [im](GoalHandle gh) { im->OnGoal(gh); }, [im](GoalHandle gh) { im->OnCancel(gh); }, false);
  m.follow->start();
  using Empty = std_srvs::Empty;
  SimServer* sim = m.sim;
  auto empty = [&](const std::string& name, std::function<void()> f) {
    m.services.push_back(nh.advertiseService<Empty::Request, Empty::Response>(
        name, [f](Empty::Request&, Empty::Response&) {
          f();
          return true;
        }));
  };
  empty("/partsim/pause", [sim] { sim->Pause(); });
  empty("/partsim/resume", [sim] { sim->Resume(); });
  empty("/partsim/reset", [sim] { sim->Reset(); });
  m.services.push_back(
      nh.advertiseService<partsim_msgs::Step::Request, partsim_msgs::Step::Response>(
          "/partsim/step",
          [sim](partsim_msgs::Step::Request& req, partsim_msgs::Step::Response& res) {
            // out of range: the caller sees the service fail
            if (req.steps < 1 || req.steps > SimServer::kMaxStepRequest) return false;
            sim->StepN(req.steps);
            res.clock_steps = sim->GetClockSteps();
            return true;
          }));
  m.services.push_back(
      nh.advertiseService<partsim_msgs::PlanMotion::Request, partsim_msgs::PlanMotion::Response>(
          m.prefix + "/plan",
          [im](partsim_msgs::PlanMotion::Request& req, partsim_msgs::PlanMotion::Response& res) {
            return im->OnPlan(req, res);
          }));
  m.spinner = std::make_unique<ros::AsyncSpinner>(4);
  m.spinner->start();
  m.started = true;
}

void Ros1Bridge::Stop() {
  Impl& m = *impl_;
  if (!m.started) return;
  m.started = false;
  m.spinner->stop();
  m.follow.reset();
  m.services.clear();
  m.subs.clear();
  m.cameras.clear();
  m.clock_pub = m.joint_pub = m.tf_pub = m.imu_pub = ros::Publisher();
  m.nh.reset();
  ros::shutdown();
}

}  // namespace partsim
