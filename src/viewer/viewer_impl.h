// The viewer's state, shared by its parts: viewer.cc (the public API, starting and stopping, the
// synchronous loop), viewer_topics.cc (snapshots of the scene and what each client is sent of
// them), viewer_services.cc (the page's commands) and viewer_routes.cc (HTTP: the web bundle,
// scene.json, meshes, textures, extension routes). The network side is a RosbridgeServer: its
// transport, login, Origin check and op table are the rosbridge server's; the viewer adds its
// topics, services, simulation controls and HTTP handler to it.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/json_parse.h"
#include "partsim/physics/scene.h"
#include "partsim/robot/controllers.h"
#include "partsim/server/rosbridge.h"
#include "partsim/server/sim_server.h"
#include "partsim/viewer/viewer.h"
#include "viewer/scene_content.h"

namespace partsim {

namespace viewer_internal {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

constexpr const char* kPosesTopic = "/partsim/poses";
constexpr const char* kJointStatesTopic = "/partsim/joint_states";
constexpr const char* kStatusTopic = "/partsim/status";
constexpr const char* kContactsTopic = "/partsim/contacts";

/// "a, b, c" ("none" for no names).
std::string JoinNames(const std::vector<std::string>& names);

}  // namespace viewer_internal

struct Viewer::Impl {
  using Json = viewer_internal::Json;
  using Clock = viewer_internal::Clock;

  ViewerOptions options;
  std::string token;
  std::string web_root;
  SimServer* sim = nullptr;
  double period = 1.0 / 60;  ///< s between pose snapshots
  std::unique_ptr<RosbridgeServer> server;
  int port = 0;

  // ---- the scene's thread ----
  Scene* scene = nullptr;
  std::shared_ptr<const internal::SceneContent> content;  ///< the structure last snapshotted
  uint64_t description_version = 0;  ///< GetDescriptionVersion at that snapshot
  long long content_versions = 0;
  std::vector<char> initial_state;  ///< what reset restores (synchronous mode)
  Clock::time_point last_snapshot{};
  /// The position controllers of the joints the page moved, by (articulation, joint): the
  /// robot layer's JointPositionController, updated at its control rate (served mode: from the
  /// step callback; synchronous mode: at each Render()).
  std::map<std::pair<int, std::string>, std::shared_ptr<JointPositionController>> controllers;
  /// served mode: the step of each controller's next update
  std::map<JointPositionController*, long long> next_update;
  /// served mode: what moves the served robot's joints (Viewer::SetJointCommand)
  ViewerJointCommand joint_command;

  // ---- shared (mutex) ----
  mutable std::mutex mutex;
  std::condition_variable cv;
  std::deque<std::function<void()>> commands;  ///< synchronous mode: run by Render()
  bool paused = false;                         ///< synchronous mode
  long long pending_steps = 0;                 ///< synchronous mode
  std::shared_ptr<const internal::SceneContent> shared_content;
  std::shared_ptr<const internal::MotionSnapshot> latest;
  std::optional<Eigen::Vector3d> camera_position, camera_rpy;  ///< the page's initial camera
  std::optional<double> camera_fovy;
  std::atomic<bool> closed{false};
  std::atomic<bool> want_contacts{false};
  std::atomic<bool> started{false};
  std::atomic<bool> publish_scheduled{false};
  std::atomic<bool> snapshot_requested{false};  ///< a forced snapshot is queued already

  // ---- the network thread ----
  /// What a client was sent last, to send it only what moved since.
  struct ClientState {
    long long poses_version = -1;  ///< content version of sent_poses; -1: send every body next
    std::vector<double> sent_poses;
    long long joints_version = -1;
    std::vector<std::vector<double>> sent_qpos;
  };
  std::map<const void*, ClientState> client_state;  ///< by RosbridgeClientPtr::get()
  struct RateSample {
    Clock::time_point wall;
    long long step;
    double time;
  };
  std::deque<RateSample> rate_samples;
  double steps_per_second = 0, realtime_factor = 0;

  // ---- extensions (set before Start, then read only) ----
  struct ApiRoute {
    std::string prefix;
    ViewerApiRoute route;
    double timeout = 30;
  };
  std::vector<ApiRoute> api_routes;
  std::map<std::string, ViewerService> services;

  std::atomic<long long> http_requests{0}, snapshots{0};

  // ---- set-up and the synchronous loop (viewer.cc) ----
  /// Runs the commands the page queued (synchronous mode); true when there were some.
  bool RunCommands();
  /// The server's options from the viewer's.
  RosbridgeOptions ServerOptions() const;
  /// Adds the viewer's topics, services, controls and HTTP handler to `server` (before Start).
  void Serve();

  // ---- snapshots and topics (viewer_topics.cc) ----
  /// Snapshots the structure of the scene (a new scene_version); the scene's thread.
  void RebuildContent();
  /// Snapshots what moved, at most every `period` s unless `force`, and has it published.
  void Snapshot(bool force);
  /// A forced snapshot on the scene's thread (a client subscribed); one waits at most.
  void RequestSnapshot();
  void SchedulePublish();
  void PostStatus();
  void Latest(std::shared_ptr<const internal::SceneContent>* c,
              std::shared_ptr<const internal::MotionSnapshot>* s) const;
  void Publish();
  void PublishPoses(const RosbridgeClientPtr& c, const internal::MotionSnapshot& snap);
  void PublishJoints(const RosbridgeClientPtr& c, const internal::MotionSnapshot& snap);
  void PublishContacts(const RosbridgeClientPtr& c, const internal::MotionSnapshot& snap);
  Json StatusJson() const;
  void PublishStatus();
  void StatusTick();
  void UpdateWantContacts();
  void AddTopics();

  // ---- the page's commands (viewer_services.cc) ----
  /// Runs `fn` on the scene's thread and answers through `reply` with what it returns, or with
  /// its error.
  void Enqueue(RosbridgeServiceReply reply, std::function<Json(Scene&)> fn);
  Json SetJointTarget(Scene& s, int a, const std::string& name, double position);
  /// Updates the page's joint controllers due (scene's thread); `steps`: the SimServer's clock
  /// in served mode, -1 in synchronous mode (every controller, at each Render()).
  void UpdateControllers(long long steps);
  Json CameraPicture(Scene& s, const std::string& name, const std::string& picture);
  void AddServices();

  // ---- HTTP (viewer_routes.cc) ----
  double HandleHttp(const RosbridgeHttpRequest& request, RosbridgeHttpRespond respond);
  /// The answer to GET `path` of the viewer's own API.
  RosbridgeHttpAnswer Api(const std::string& path) const;
  RosbridgeHttpAnswer Bundle(std::string path) const;
};

}  // namespace partsim
