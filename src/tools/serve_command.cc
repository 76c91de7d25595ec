// `partsim serve`: a scene stepped in real time (or faster) behind a rosbridge v2 server.
#include <sys/resource.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "net_options.h"
#include "partsim/assets/default_objects.h"
#include "partsim/assets/scene_file.h"
#include "partsim/assets/urdf.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/scene_render.h"
#include "partsim/robot/robots.h"
#include "partsim/server/ros1_bridge.h"
#include "partsim/server/rosbridge.h"
#include "partsim/server/served_robot.h"
#include "partsim/server/sim_server.h"
#include "partsim/viewer/viewer.h"

namespace partsim::tools {
namespace {

constexpr char kServeUsage[] = R"(usage:
  partsim serve [SCENE] [--port P] [--rate R | --realtime-factor F | --fast]
                [--robot gripper|panda] [--address A] [--duration S] [--camera WxH]
                [--camera-rate HZ] [--token T] [--allow-origin O]... [--max-clients N]
                [--ros1 [--ros1-wall-time]] [--viewer [--viewer-port P]]

Steps a scene on its own thread and serves it over the rosbridge v2 protocol (JSON over
WebSocket): /clock, /joint_states and /tf out; /<robot>/joint_position_controller/command,
/<robot>/joint_velocity_controller/command (std_msgs/Float64MultiArray) and
/<robot>/joint_trajectory_controller/command (trajectory_msgs/JointTrajectory) in; services
/rosapi/topics, /rosapi/topic_type, /rosapi/services, /partsim/pause|resume|reset|step|stats.
Sensors, read only while a client subscribes: /front_camera/image_raw (sensor_msgs/Image,
rgb8), /front_camera/camera_info, /front_camera/points (sensor_msgs/PointCloud2, x y z
float32) from a camera looking at the robot and the object from the -y side, and /imu
(sensor_msgs/Imu) on the robot's end-effector link at the physics rate.
Motion planning: the /<robot>/plan service ({joint_goal: [..]} or {pose_goal: geometry_msgs/Pose},
execute, time_limit) plans a collision-free path (OMPL) and runs it.
With --ros1 (when partsim is built with ROS 1) a roscpp node serves the same topics and
services to ROS 1 nodes, plus the action
/<robot>/joint_trajectory_controller/follow_joint_trajectory (control_msgs); the master is
ROS_MASTER_URI's, and /use_sim_time is set to true unless --ros1-wall-time.
SCENE is a URDF file or a PartNet-Mobility folder (placed 1 m ahead of the robot, root fixed),
or a JSON scene file listing several with their poses (see include/partsim/assets/scene_file.h).
With no SCENE, a built-in cabinet stands in front of the robot.
  --port P               WebSocket port (default 9090; 0 picks a free one, printed on start)
  --rate R               physics rate in Hz (default 500), stepped in real time
  --realtime-factor F    simulated seconds per wall second (default 1)
  --fast                 step as fast as possible
  --robot gripper|panda  the robot (default panda), commanded under /panda or /flying_gripper
  --address A            interface to listen on, an address or a host name (default
                         127.0.0.1; anything else is reachable from other machines: see --token)
  --token T              clients must first send {"op": "auth", "mac": "T"} (default: none;
                         also read from the PARTSIM_SERVE_TOKEN environment variable)
  --allow-origin O       web pages from origin O (e.g. http://myhost:8000, or * for any) may
                         connect; repeatable (default: pages of this machine only)
  --max-clients N        connections at once (default 100)
  --duration S           stop after S wall-clock seconds (default: run until SIGINT/SIGTERM)
  --camera WxH           image size of /front_camera (default 640x480)
  --camera-rate HZ       camera topics per simulated second (default 10; 0: every step)
  --ros1                 also serve over native ROS 1 (needs a ROS master)
  --ros1-wall-time       with --ros1: leave /use_sim_time alone
  --viewer               also serve the browser viewer of the scene (docs/viewer.md) on its own
                         port, attached to the same simulation; its URL is printed. It takes
                         the --token if given (else a random one, in the URL), --address and
                         --allow-origin
  --viewer-port P        the viewer's port (default 8000; 0 picks a free one)
)";

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop = true; }

}  // namespace

void AddServedObjects(Scene* scene, const std::string& scene_file, const Pose& where) {
  if (scene_file.empty()) {
    UrdfLoader loader(scene);
    loader.fix_root_link = true;
    ArticulationDesc object = loader.Parse(MakeCabinetUrdf(), ".", "cabinet");
    object.root_pose = where;
    scene->AddArticulation(object);
  } else {
    AddSceneObjects(scene, scene_file, where, true);
  }
}

int RunServeCommand(int argc, char** argv) {
  std::string scene_file, robot_kind = "panda";
  NetOptions net;
  net.port = 9090;
  const char* env_token = std::getenv("PARTSIM_SERVE_TOKEN");
  if (env_token) net.token = env_token;
  size_t max_clients = 100;
  double rate = 500, factor = 1, duration = 0;
  bool fast = false, ros1 = false, ros1_sim_time = true, viewer = false;
  int viewer_port = 8000;
  int cam_w = 640, cam_h = 480;
  double camera_rate = 10;
  const std::vector<std::string> args(argv, argv + argc);
  if (ArgParser::AsksForHelp(args)) {
    std::fputs(kServeUsage, stdout);
    return 0;
  }
  const int parsed = RunWithExitCode("partsim serve", "see partsim serve --help\n", [&] {
    ArgParser p("partsim serve");
    p.Positional([&](const FlagValue& v) {
      if (!scene_file.empty()) v.Fail("unexpected extra argument '" + v.Text() + "'");
      scene_file = v.Text();
    });
    AddNetOptions(&p, &net);
    p.Option("--rate", [&](const FlagValue& v) { rate = v.Number(0, false, 1e9); });
    p.Option("--realtime-factor", [&](const FlagValue& v) { factor = v.Number(0, false, 1e9); });
    p.Switch("--fast", [&] { fast = true; });
    p.Option("--robot", [&](const FlagValue& v) { robot_kind = v.Choice({"gripper", "panda"}); });
    p.Option("--duration", [&](const FlagValue& v) { duration = v.Number(0, false, 1e9); });
    p.Option("--camera", [&](const FlagValue& v) { std::tie(cam_w, cam_h) = v.Size(1, 8192); });
    p.Option("--camera-rate", [&](const FlagValue& v) { camera_rate = v.Number(0, true, 1e9); });
    p.Option("--max-clients",
             [&](const FlagValue& v) { max_clients = static_cast<size_t>(v.Integer(1, 100000)); });
    p.Switch("--ros1", [&] { ros1 = true; });
    p.Switch("--ros1-wall-time", [&] { ros1_sim_time = false; });
    p.Switch("--viewer", [&] { viewer = true; });
    p.Option("--viewer-port", [&](const FlagValue& v) { viewer_port = PortValue(v); });
    p.Switch("--help", [] {});  // answered above; declared to be suggested
    p.Parse(args);
    return 0;
  });
  if (parsed != 0) return parsed;
  // from here on Ctrl-C and SIGTERM end the server cleanly, whenever they come: a client that
  // reads the printed address may stop it at once
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
#ifndef PARTSIM_WITH_ROS1
  if (ros1) {
    std::fprintf(stderr,
                 "partsim serve: --ros1: this partsim was built without ROS 1 (install Debian's "
                 "libroscpp-dev, libactionlib-dev and the ROS message packages that "
                 "scripts/setup.sh lists, then rebuild)\n");
    return 2;
  }
#endif

  // every connection costs a file descriptor: take the hard limit, so that the connection cap,
  // not the descriptor limit, is what refuses clients (websocketpp retries a failed accept at
  // once, and would spin there)
  rlimit files{};
  if (getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max) {
    files.rlim_cur = files.rlim_max;
    setrlimit(RLIMIT_NOFILE, &files);
  }

  try {
    // the scene: what SCENE names (a URDF or a PartNet-Mobility folder 1 m ahead of the
    // robot, or a scene file's objects at their poses) or the built-in cabinet; then the robot
    SceneConfig cfg;
    cfg.timestep = 1.0 / rate;
    Scene scene(cfg);
    scene.AddGround(0.0);
    AddServedObjects(&scene, scene_file, Pose(Eigen::Vector3d(1.0, 0, 0)));
    RobotModel model = robot_kind == "panda" ? BuildPanda() : BuildFlyingGripper();
    if (robot_kind == "gripper") model.articulation.root_pose = Pose(Eigen::Vector3d(0, 0, 0.5));
    Articulation robot = scene.AddArticulation(model.articulation);
    Eigen::VectorXd q = robot.GetQpos();
    for (size_t i = 0; i < model.arm_joints.size() && i < model.home.size(); ++i)
      q[robot.FindJointByName(model.arm_joints[i]).GetDofIndex()] = model.home[i];
    for (const std::string& g : model.gripper_joints) {
      int d = robot.FindJointByName(g).GetDofIndex();
      if (d >= 0) q[d] = model.gripper_open;
    }
    robot.SetQpos(q);
    // lights and a camera in front of the robot and the object, looking at both
    SetAmbientLight(scene, Eigen::Vector3f(0.35f, 0.35f, 0.35f));
    AddDirectionalLight(scene, Eigen::Vector3d(-1, -0.5, -1), Eigen::Vector3f(0.8f, 0.8f, 0.8f));
    Camera camera = AddCamera(scene, "front_camera", cam_w, cam_h, 1.0, 0.05, 20.0);
    camera.SetLocalPose(
        CameraLookAt(Eigen::Vector3d(1.3, -2.2, 1.4), Eigen::Vector3d(0.5, 0, 0.4)));

    ControlLoop loop(&scene);
    SimServerOptions so;
    so.fast = fast;
    so.realtime_factor = factor;
    SimServer sim(&scene, &loop, so);
    ServedRobotOptions sro;
    sro.camera_rate = camera_rate;
    sro.imu_link = model.ee_link;
    sro.ee_link = model.ee_link;
    sro.tcp_in_ee = model.tcp_in_ee;
    ServedRobot served(&sim, &scene, &loop, robot, robot.GetName(), sro);
    RosbridgeOptions ro;
    net.ApplyTo(&ro);
    ro.max_clients = max_clients;
    ro.log_clients = true;
    RosbridgeServer bridge(&served, ro);
    try {
      bridge.Start();
    } catch (const std::exception& e) {
      throw CannotListen(e);
    }
    // the browser viewer, attached to the same simulation (before it starts)
    std::unique_ptr<Viewer> page;
    if (viewer) {
      ViewerOptions vo;
      net.ApplyTo(&vo);
      vo.port = viewer_port;
      page = std::make_unique<Viewer>(&scene, vo);
      page->Attach(&sim);
      // a joint of the robot moved in the page goes through the robot's controllers, as a ROS
      // client's position command does: the other joints keep their targets
      page->SetJointCommand(
          [&served](const Articulation& a, const std::string& joint, double position) {
            if (!(a == served.GetRobot())) return false;
            std::vector<double> q;
            for (const Joint& j : served.GetRobot().GetActiveJoints())
              q.push_back(j.GetName() == joint        ? position
                          : j.GetDriveStiffness() > 0 ? j.GetDriveTarget()
                                                      : j.GetQpos());
            served.CommandPositions(q, "the viewer's /partsim/set_joint_target");
            return true;
          });
      try {
        page->Start();
      } catch (const std::exception& e) {
        throw CannotListen(e, "choose another port with --viewer-port P (0: a free one)");
      }
    }
#ifdef PARTSIM_WITH_ROS1
    std::unique_ptr<Ros1Bridge> ros1_bridge;
    if (ros1) {
      Ros1Options o;
      o.use_sim_time = ros1_sim_time;
      ros1_bridge = std::make_unique<Ros1Bridge>(&served, o);
      ros1_bridge->Start();
    }
#endif
    sim.Start();
    std::printf(
        "partsim serve: rosbridge on ws://%s:%d, robot /%s (%d joints), %zu articulations, %g Hz "
        "physics, %s%s\n",
        net.address.c_str(), bridge.GetPort(), robot.GetName().c_str(), robot.Dof(),
        scene.GetArticulations().size(), rate,
        fast ? "as fast as possible" : ("real-time factor " + std::to_string(factor)).c_str(),
        ros1 ? ", ROS 1 node /partsim" : "");
    // what to do next: connect a client, find the topics and services
    const std::string url = "ws://" + net.address + ":" + std::to_string(bridge.GetPort());
    char stop[64] = "stop with Ctrl-C";
    if (duration > 0) std::snprintf(stop, sizeof(stop), "stops after %g s", duration);
    std::printf(
        "  connect a rosbridge client to %s, e.g. Python roslibpy: "
        "roslibpy.Ros(host='%s', port=%d), or JavaScript roslib: new ROSLIB.Ros({url: '%s'})\n"
        "  topics: /joint_states, /tf, /clock, /%s/joint_position_controller/command, "
        "/front_camera/image_raw, ...; the service /rosapi/topics lists them all "
        "(partsim serve --help)\n"
        "  clients are logged on stderr as they connect and leave; %s\n",
        url.c_str(), net.address.c_str(), bridge.GetPort(), url.c_str(), robot.GetName().c_str(),
        stop);
    if (page)
      std::printf(
          "  viewer: open %s in a browser%s\n", page->GetUrl().c_str(),
          page->GetWebRoot().empty() ? " (web page not built: bash scripts/build_web.sh)" : "");
    std::fflush(stdout);

    auto t0 = std::chrono::steady_clock::now();
    while (!g_stop) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      if (duration > 0 &&
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >= duration)
        break;
    }
    sim.Stop();
    served.Close();
    bridge.Stop();
    if (page) page->Stop();
#ifdef PARTSIM_WITH_ROS1
    if (ros1_bridge) ros1_bridge->Stop();
#endif
    RosbridgeStats s = bridge.GetStats();
    std::printf(
        "partsim serve: stopped after %lld steps (%.3f s simulated); %lld messages sent, %lld "
        "dropped; %lld commands, latency %.2f steps mean, %lld max\n",
        sim.GetClockSteps(), sim.GetClockSeconds(), s.messages_sent, s.messages_dropped, s.commands,
        s.mean_latency_steps, s.max_latency_steps);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "partsim serve: %s\n", e.what());
    return 1;
  }
}

}  // namespace partsim::tools
