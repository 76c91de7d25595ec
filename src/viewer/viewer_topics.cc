// The viewer's topics: snapshots of the scene taken on its thread (the structure when it
// changed, the poses, joint positions and contacts at most max_rate times a second), published
// on the network thread to each client as what moved since what it was sent last, and the
// status (paused, time, measured rates) every 250 ms.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "partsim/core/error.h"
#include "partsim/physics/observer.h"
#include "viewer/viewer_impl.h"

namespace partsim {

using internal::MotionSnapshot;
using internal::SceneContent;
using viewer_internal::kContactsTopic;
using viewer_internal::kJointStatesTopic;
using viewer_internal::kPosesTopic;
using viewer_internal::kStatusTopic;

// ================= the scene's thread =================

void Viewer::Impl::RebuildContent() {
  description_version = GetDescriptionVersion(*scene);
  content = internal::MakeSceneContent(*scene, ++content_versions);
  if (!sim) initial_state = scene->Pack();
  controllers.clear();  // their articulations may be gone
  next_update.clear();
  {
    std::lock_guard<std::mutex> lock(mutex);
    shared_content = content;
    latest = nullptr;
  }
  PostStatus();
}

void Viewer::Impl::Snapshot(bool force) {
  if (!scene) return;
  const Clock::time_point now = Clock::now();
  if (!force && now - last_snapshot < std::chrono::duration<double>(period)) return;
  last_snapshot = now;
  if (!content || GetDescriptionVersion(*scene) != description_version) RebuildContent();
  auto snap = internal::TakeMotionSnapshot(*scene, *content, want_contacts);
  if (sim) snap->step = sim->GetClockSteps();
  {
    std::lock_guard<std::mutex> lock(mutex);
    latest = std::move(snap);
  }
  ++snapshots;
  SchedulePublish();
}

void Viewer::Impl::RequestSnapshot() {
  if (snapshot_requested.exchange(true)) return;
  auto take = [this] {
    snapshot_requested = false;
    Snapshot(true);
  };
  if (sim) {
    sim->Post(take);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex);
    commands.push_back(take);
  }
  cv.notify_all();
}

// ================= the network thread =================

void Viewer::Impl::SchedulePublish() {
  if (!started || publish_scheduled.exchange(true)) return;
  server->Post([this] {
    publish_scheduled = false;
    Publish();
  });
}

void Viewer::Impl::PostStatus() {
  if (started) server->Post([this] { PublishStatus(); });
}

void Viewer::Impl::Latest(std::shared_ptr<const SceneContent>* c,
                          std::shared_ptr<const MotionSnapshot>* s) const {
  std::lock_guard<std::mutex> lock(mutex);
  *c = shared_content;
  *s = latest;
}

void Viewer::Impl::Publish() {
  std::shared_ptr<const SceneContent> ct;
  std::shared_ptr<const MotionSnapshot> snap;
  Latest(&ct, &snap);
  if (!ct || !snap || snap->version != ct->version) return;
  for (const RosbridgeClientPtr& c : server->Subscribers(kPosesTopic)) PublishPoses(c, *snap);
  for (const RosbridgeClientPtr& c : server->Subscribers(kJointStatesTopic))
    PublishJoints(c, *snap);
  if (snap->has_contacts)
    for (const RosbridgeClientPtr& c : server->Subscribers(kContactsTopic))
      PublishContacts(c, *snap);
}

/// The bodies that moved since what `c` was sent last (all of them after a new structure).
void Viewer::Impl::PublishPoses(const RosbridgeClientPtr& c, const MotionSnapshot& snap) {
  ClientState& st = client_state[c.get()];
  const size_t n = snap.poses.size() / 7;
  const bool all = st.poses_version != snap.version || st.sent_poses.size() != n * 7;
  std::vector<size_t> ids;
  for (size_t i = 0; i < n; ++i)
    if (all || internal::BodyMoved(st.sent_poses, snap.poses, i)) ids.push_back(i);
  if (ids.empty() && !all) return;
  char head[160];
  std::snprintf(head, sizeof(head),
                "{\"op\":\"publish\",\"topic\":\"/partsim/poses\",\"msg\":{\"step\":%lld,"
                "\"time\":%.9g,",
                snap.step, snap.time);
  std::string text = head;
  text += "\"scene_version\":" + std::to_string(snap.version) + ",\"ids\":[";
  std::vector<double> poses;
  poses.reserve(7 * ids.size());
  for (size_t k = 0; k < ids.size(); ++k) {
    text += (k ? "," : "") + std::to_string(ids[k]);
    poses.insert(poses.end(), snap.poses.begin() + 7 * ids[k], snap.poses.begin() + 7 * ids[k] + 7);
  }
  text += "],\"poses\":";
  internal::AppendNumbers(&text, poses.data(), poses.size());
  text += "}}";
  if (!server->SendNow(c, text, true)) return;
  if (all) {
    st.sent_poses = snap.poses;
    st.poses_version = snap.version;
  } else {
    for (size_t i : ids)
      std::copy(snap.poses.begin() + 7 * i, snap.poses.begin() + 7 * i + 7,
                st.sent_poses.begin() + 7 * i);
  }
}

/// The joint positions of each articulation whose joints moved since what `c` was sent last.
void Viewer::Impl::PublishJoints(const RosbridgeClientPtr& c, const MotionSnapshot& snap) {
  ClientState& st = client_state[c.get()];
  std::shared_ptr<const SceneContent> ct;
  std::shared_ptr<const MotionSnapshot> unused;
  Latest(&ct, &unused);
  const bool all = st.joints_version != snap.version || st.sent_qpos.size() != snap.qpos.size();
  if (all) st.sent_qpos.assign(snap.qpos.size(), {});
  st.joints_version = snap.version;
  for (size_t a = 0; a < snap.qpos.size() && ct && a < ct->articulations.size(); ++a) {
    const std::vector<double>& q = snap.qpos[a];
    std::vector<double>& was = st.sent_qpos[a];
    bool moved = was.size() != q.size();
    for (size_t k = 0; !moved && k < q.size(); ++k) moved = std::abs(was[k] - q[k]) > 1e-5;
    if (!moved) continue;
    std::string text =
        "{\"op\":\"publish\",\"topic\":\"/partsim/joint_states\",\"msg\":{\"articulation\":" +
        std::to_string(a) +
        ",\"name\":" + internal::DumpJson(Json(ct->articulations[a].dof_joints)) + ",\"position\":";
    internal::AppendNumbers(&text, q.data(), q.size());
    text += ",\"velocity\":";
    internal::AppendNumbers(&text, snap.qvel[a].data(), snap.qvel[a].size());
    text += "}}";
    if (server->SendNow(c, text, true)) was = q;
  }
}

void Viewer::Impl::PublishContacts(const RosbridgeClientPtr& c, const MotionSnapshot& snap) {
  std::string text = "{\"op\":\"publish\",\"topic\":\"/partsim/contacts\",\"msg\":{\"time\":" +
                     std::to_string(snap.time) + ",\"points\":";
  internal::AppendNumbers(&text, snap.contact_points.data(), snap.contact_points.size());
  text += ",\"normals\":";
  internal::AppendNumbers(&text, snap.contact_normals.data(), snap.contact_normals.size());
  text += ",\"forces\":";
  internal::AppendNumbers(&text, snap.contact_forces.data(), snap.contact_forces.size());
  text += "}}";
  server->SendNow(c, text, true);
}

Viewer::Impl::Json Viewer::Impl::StatusJson() const {
  std::shared_ptr<const SceneContent> ct;
  std::shared_ptr<const MotionSnapshot> snap;
  Latest(&ct, &snap);
  bool is_paused;
  {
    std::lock_guard<std::mutex> lock(mutex);
    is_paused = sim ? sim->IsPaused() : paused;
  }
  return {{"paused", is_paused},
          {"time", snap ? snap->time : 0.0},
          {"step", snap ? snap->step : 0},
          {"steps_per_second", steps_per_second},
          {"realtime_factor", realtime_factor},
          {"scene_version", ct ? ct->version : 0},
          {"closed", closed.load()}};
}

void Viewer::Impl::PublishStatus() {
  std::string text;
  for (const RosbridgeClientPtr& c : server->Subscribers(kStatusTopic)) {
    if (text.empty())
      text = internal::DumpJson(
          Json{{"op", "publish"}, {"topic", kStatusTopic}, {"msg", StatusJson()}});
    server->SendNow(c, text, true);
  }
}

/// Every 250 ms (the server's timer): the measured rates, and /partsim/status.
void Viewer::Impl::StatusTick() {
  std::shared_ptr<const SceneContent> ct;
  std::shared_ptr<const MotionSnapshot> snap;
  Latest(&ct, &snap);
  const Clock::time_point now = Clock::now();
  rate_samples.push_back({now, snap ? snap->step : 0, snap ? snap->time : 0.0});
  while (rate_samples.size() > 5) rate_samples.pop_front();
  const RateSample& first = rate_samples.front();
  const double wall = std::chrono::duration<double>(now - first.wall).count();
  if (wall > 0 && snap) {
    steps_per_second = std::max(0.0, (snap->step - first.step) / wall);
    realtime_factor = std::max(0.0, (snap->time - first.time) / wall);
  }
  PublishStatus();
}

void Viewer::Impl::UpdateWantContacts() {
  want_contacts = !server->Subscribers(kContactsTopic).empty();
}

void Viewer::Impl::AddTopics() {
  // a client that subscribes gets what there is now at once, then what the scene's thread
  // snapshots next
  auto now_then = [this](const RosbridgeClientPtr& c, bool poses) {
    ClientState& st = client_state[c.get()];
    (poses ? st.poses_version : st.joints_version) = -1;
    std::shared_ptr<const SceneContent> ct;
    std::shared_ptr<const MotionSnapshot> snap;
    Latest(&ct, &snap);
    if (ct && snap && snap->version == ct->version) {
      if (poses)
        PublishPoses(c, *snap);
      else
        PublishJoints(c, *snap);
    }
    RequestSnapshot();
  };
  RosbridgeTopicHooks poses, joints, status, contacts;
  poses.on_subscribe = [now_then](const RosbridgeClientPtr& c) { now_then(c, true); };
  joints.on_subscribe = [now_then](const RosbridgeClientPtr& c) { now_then(c, false); };
  status.on_subscribe = [this](const RosbridgeClientPtr& c) {
    server->SendNow(
        c,
        internal::DumpJson(Json{{"op", "publish"}, {"topic", kStatusTopic}, {"msg", StatusJson()}}),
        false);
  };
  contacts.on_subscribe = [this](const RosbridgeClientPtr&) {
    UpdateWantContacts();
    RequestSnapshot();
  };
  contacts.on_unsubscribe = [this](const RosbridgeClientPtr&) { UpdateWantContacts(); };
  server->AddTopic(kPosesTopic, "partsim/Poses", poses);
  server->AddTopic(kJointStatesTopic, "sensor_msgs/JointState", joints);
  server->AddTopic(kStatusTopic, "partsim/Status", status);
  server->AddTopic(kContactsTopic, "partsim/Contacts", contacts);
  server->OnDisconnect([this](const RosbridgeClientPtr& c) { client_state.erase(c.get()); });
  server->Every(0.25, [this] { StatusTick(); });
}

}  // namespace partsim
