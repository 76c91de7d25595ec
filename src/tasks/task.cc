// ArticulationTask: a generated cabinet, the flying gripper and three cameras.
#include <pthread.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <random>

#include "core/atomic_file.h"
#include "core/worker_pool.h"
#include "partsim/assets/generator.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/scene_render.h"
#include "partsim/tasks/tasks.h"
#include "tasks/task_internal.h"

namespace fs = std::filesystem;

namespace partsim {

const char* TaskTypeName(TaskType t) { return t == TaskType::kPullDrawer ? "drawer" : "door"; }

const char* TaskTargetLabel(TaskType t) {
  return t == TaskType::kPullDrawer ? "drawer" : "rotation_door";
}

TaskType ParseTaskType(const std::string& name) {
  if (name == "drawer") return TaskType::kPullDrawer;
  if (name == "door") return TaskType::kOpenDoor;
  throw Error("task type '" + name + "' is unknown (expected 'drawer' or 'door')");
}

namespace internal {

std::vector<int> TargetLinks(const GeneratedObject& object, TaskType type) {
  const std::string label = TaskTargetLabel(type);
  std::vector<int> out;
  for (const GeneratedLink& l : object.links) {
    if (l.name != label) continue;
    bool handle = false;
    for (const GeneratedPart& p : l.parts) handle = handle || p.name == "handle";
    if (handle) out.push_back(l.id);
  }
  return out;
}

std::string EnsureObjectFolder(const GeneratedObject& object, const std::string& asset_dir) {
  fs::path root =
      asset_dir.empty() ? fs::temp_directory_path() / "partsim-assets" : fs::path(asset_dir);
  // the layout version in the path keeps folders written by older partsim out of the way
  fs::path dir =
      root / (object.category + "_s" + std::to_string(object.seed) + "_pm2") / object.anno_id;
  if (fs::exists(dir / "mobility_v2.json")) return dir.string();
  // write beside, then rename: tasks on several threads may ask for the same object, and the
  // first folder to land stays (a later one is identical)
  StagedPath staged(dir.string());
  WriteObject(object, staged.Temporary());
  staged.CommitUnlessPresent();
  if (!fs::exists(dir / "mobility_v2.json"))
    throw Error("task: cannot write the object folder '" + dir.string() + "'");
  return dir.string();
}

void DisableCollisionsWithin(ArticulationDesc& articulation) {
  const std::vector<LinkDesc>& links = articulation.links;
  for (size_t a = 0; a < links.size(); ++a)
    for (size_t b = a + 1; b < links.size(); ++b)
      if (!links[a].collisions.empty() && !links[b].collisions.empty())
        articulation.disabled_collisions.emplace_back(links[a].name, links[b].name);
}

std::optional<CollisionShape> BoxOfMesh(const CollisionShape& shape) {
  if (shape.type != ShapeType::kConvexMesh || !shape.mesh || shape.mesh->vertices.empty())
    return std::nullopt;
  Eigen::Vector3f lo = shape.mesh->vertices.front(), hi = lo;
  for (const Eigen::Vector3f& v : shape.mesh->vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const Eigen::Vector3d size = (hi - lo).cast<double>();
  if (!(size.minCoeff() > 1e-6)) return std::nullopt;
  // every vertex a corner, and all 8 corners present: the hull is the box
  const double tol = 1e-6 * size.maxCoeff();
  int corners = 0;
  for (const Eigen::Vector3f& v : shape.mesh->vertices) {
    int bits = 0;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(double(v[k]) - double(lo[k])) <= tol) continue;
      if (std::abs(double(v[k]) - double(hi[k])) > tol) return std::nullopt;
      bits |= 1 << k;
    }
    corners |= 1 << bits;
  }
  if (corners != 0xFF) return std::nullopt;
  CollisionShape box = shape;
  box.type = ShapeType::kBox;
  box.mesh.reset();
  box.half_size = 0.5 * size;
  box.pose = shape.pose * Pose(0.5 * (lo + hi).cast<double>());
  return box;
}

void BoxesForBoxMeshes(ArticulationDesc& articulation) {
  for (LinkDesc& l : articulation.links)
    for (CollisionShape& s : l.collisions)
      if (std::optional<CollisionShape> box = BoxOfMesh(s)) s = *box;
}

// --- flying gripper kinematics in closed form -------------------------------------------------

Eigen::Vector3d EulerZyx(const Eigen::Matrix3d& R, const Eigen::Vector3d& near) {
  // R = Rz(a) Ry(b) Rx(c); two solutions away from b = +-pi/2: pick the one nearest `near`
  double b = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  double a = std::atan2(R(1, 0), R(0, 0));
  double c = std::atan2(R(2, 1), R(2, 2));
  auto wrap_near = [](double x, double ref) {
    return x + 2 * M_PI * std::round((ref - x) / (2 * M_PI));
  };
  Eigen::Vector3d s1(wrap_near(a, near[0]), wrap_near(b, near[1]), wrap_near(c, near[2]));
  Eigen::Vector3d s2(wrap_near(a + M_PI, near[0]), wrap_near(M_PI - b, near[1]),
                     wrap_near(c + M_PI, near[2]));
  return (s1 - near).squaredNorm() <= (s2 - near).squaredNorm() ? s1 : s2;
}

Eigen::Matrix3d EulerRateMatrix(const Eigen::Vector3d& ypr) {
  // angular velocity (root frame) = E * (yaw', pitch', roll')
  Eigen::Matrix3d Rz = Eigen::AngleAxisd(ypr[0], Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Matrix3d Ry = Eigen::AngleAxisd(ypr[1], Eigen::Vector3d::UnitY()).toRotationMatrix();
  Eigen::Matrix3d E;
  E.col(0) = Eigen::Vector3d::UnitZ();
  E.col(1) = Rz * Eigen::Vector3d::UnitY();
  E.col(2) = Rz * Ry * Eigen::Vector3d::UnitX();
  return E;
}

}  // namespace internal

using internal::TaskImpl;

std::vector<int> FindTaskObjects(TaskType type, int count, std::uint64_t dataset_seed) {
  std::vector<int> out;
  for (int i = 0; static_cast<int>(out.size()) < count; ++i) {
    if (i > 100 * count + 100)
      throw Error("FindTaskObjects: too few StorageFurniture objects with a " +
                  std::string(TaskTypeName(type)));
    GeneratedObject o = GenerateObject("StorageFurniture", i, dataset_seed);
    if (!internal::TargetLinks(o, type).empty()) out.push_back(i);
  }
  return out;
}

std::vector<int> FindTaskTargets(const PartNetMobilityObject& object, TaskType type) {
  std::vector<int> out;
  for (const PartNetLink& l : object.links) {
    if (l.semantic_label != TaskTargetLabel(type)) continue;
    const LinkDesc& link = object.articulation.links[object.LinkIndex(l.id)];
    // a joint with a finite range: the link's own, or its helper's for a rotating slider
    const JointDesc& j =
        l.rotates && link.parent >= 0 ? object.articulation.links[link.parent].joint : link.joint;
    const bool moves = j.type == JointType::kPrismatic || j.type == JointType::kRevolute;
    if (!moves || !(j.upper - j.lower > 0) || !std::isfinite(j.upper - j.lower)) continue;
    bool handle = false;
    for (const PartNetPart& p : l.parts) handle = handle || p.name == "handle";
    for (const VisualShape& v : link.visuals) handle = handle || v.name.rfind("handle-", 0) == 0;
    if (handle) out.push_back(l.id);
  }
  return out;
}

ArticulationTask::ArticulationTask(const TaskOptions& options) : impl_(new Impl(options)) {}
ArticulationTask::~ArticulationTask() = default;

void ArticulationTask::Reset(std::uint64_t seed) { impl_->Reset(seed); }
const TaskOptions& ArticulationTask::GetOptions() const { return impl_->options; }
Scene& ArticulationTask::GetScene() { return *impl_->scene; }
std::shared_ptr<Scene> ArticulationTask::GetSharedScene() const { return impl_->scene; }
const RobotModel& ArticulationTask::GetRobotModel() const { return impl_->robot_model; }
Articulation ArticulationTask::GetRobot() const { return impl_->robot; }
Articulation ArticulationTask::GetObject() const { return impl_->object; }
Link ArticulationTask::GetTargetLink() const { return impl_->object.GetLink(impl_->target_link); }
Joint ArticulationTask::GetTargetJoint() const {
  return impl_->object.GetJoint(impl_->target_link);
}
std::vector<std::string> ArticulationTask::GetTargetCandidates() const {
  std::vector<std::string> out;
  for (int i : impl_->candidates) out.push_back(impl_->object.GetLink(i).GetName());
  return out;
}
std::vector<uint32_t> ArticulationTask::GetHandleVisualIds() const {
  return impl_->handle_visuals.at(impl_->target_link);
}
uint32_t ArticulationTask::GetTargetEntityId() const {
  return impl_->entity_ids.at(impl_->target_link);
}
double ArticulationTask::GetProgress() const { return impl_->Progress(); }
bool ArticulationTask::IsSuccess() const {
  return impl_->Progress() >= impl_->options.success_fraction;
}
bool ArticulationTask::IsFailure() const { return impl_->Progress() < -0.02; }
double ArticulationTask::GetElapsed() const { return impl_->scene->GetTime() - impl_->start_time; }
bool ArticulationTask::IsTruncated() const {
  return GetElapsed() >= impl_->options.max_seconds - 1e-9;
}
Pose ArticulationTask::GetTcpPose() const { return impl_->TcpPose(); }
Eigen::Matrix<double, 6, 1> ArticulationTask::GetTcpVelocity() const {
  return impl_->TcpVelocity();
}
void ArticulationTask::SetTcpTarget(const Pose& target) { impl_->SetTcpTarget(target); }
void ArticulationTask::SetTcpVelocity(const Eigen::Matrix<double, 6, 1>& twist) {
  impl_->SetTcpVelocity(twist);
}
void ArticulationTask::SetGripper(double fraction) { impl_->SetGripper(fraction); }
double ArticulationTask::GetGripperOpening() const { return impl_->GripperOpening(); }
bool ArticulationTask::GripperTouchesTarget() const { return impl_->TouchesTarget(); }
void ArticulationTask::ApplyAction(const Eigen::VectorXd& action) { impl_->ApplyAction(action); }
void ArticulationTask::Step() { impl_->StepControl(); }
void ArticulationTask::TakePictures() { impl_->TakePictures(); }
std::vector<Camera> ArticulationTask::GetCameras() const { return impl_->cameras; }
Camera ArticulationTask::GetCamera(const std::string& name) const {
  for (const Camera& c : impl_->cameras)
    if (c.GetName() == name) return c;
  throw Error("task: no camera named '" + name + "' (cameras: left, right, front" +
              std::string(impl_->cameras.empty() ? "; this task was made without cameras" : "") +
              ")");
}
Camera ArticulationTask::GetVideoCamera() const {
  if (!impl_->video_camera)
    throw Error("task: no video camera (TaskOptions::video_width and video_height were 0)");
  return *impl_->video_camera;
}
Eigen::VectorXd ArticulationTask::GetRawObservation() const { return impl_->RawObservation(); }
Eigen::VectorXd ArticulationTask::GetMobilityObservation() const {
  return impl_->MobilityObservation();
}
double ArticulationTask::GetReward() const { return impl_->last_reward; }

namespace {

// The threads StepTasks runs tasks on beside the caller, kept between calls: a task's step takes
// about 0.4 ms, and a thread started and joined per task and call would add its start-up and the
// caller's wait for it to every step. One pool for the process, used by one call at a time (a
// second caller waits on `call`), grown to the largest number of tasks seen, up to the cores, less
// one; its threads poll for the next call for kPoll before they park, and are joined when the
// process exits (after a call in progress, which holds `call`).
//
// fork() copies only the thread that forks, so a child of a process that has the pool would wait
// for workers it does not have (Gymnasium's AsyncVectorEnv and multiprocessing fork). The fork
// handlers hold `call` across the fork, so that no call is running and the work handed out is
// done (a worker may still be polling); the child then drops the pool without touching it (its
// threads and their locks are not there) and makes a new one on its first call.
class StepPool {
 public:
  static StepPool& Get() {
    static StepPool pool;
    return pool;
  }

  // Runs part(0) ... part(n - 1) on the calling thread and the workers, each part taken by the
  // next thread free (tasks whose step takes longer do not hold the others back); returns when
  // all are done. `part` must not throw.
  void Run(int n, const std::function<void(int)>& part) {
    const int threads = std::min(n, Cores()) - 1;  // besides the caller
    if (threads < 1) {
      for (int i = 0; i < n; ++i) part(i);
      return;
    }
    std::lock_guard<std::mutex> lock(call_);
    if (!workers_ || workers_->size() < threads) {
      workers_.reset();  // joins the smaller pool's threads first
      workers_ = std::make_unique<internal::WorkerPool>(threads, kPoll);
    }
    workers_->Start(n, part);
    workers_->Wait();  // runs parts on this thread too
  }

 private:
  StepPool() {
    if (int err = pthread_atfork(&Prepare, &Parent, &Child); err != 0)
      throw Error("step_tasks: could not register the fork handlers of its thread pool (error " +
                  std::to_string(err) + ")");
  }

  // more threads than cores would take turns on them: a task's step is pure computation
  static int Cores() {
    const unsigned cores = std::thread::hardware_concurrency();
    return cores == 0 ? 1 << 20 : static_cast<int>(cores);
  }

  // at exit: after a call still running on another thread, joins the workers
  ~StepPool() {
    std::lock_guard<std::mutex> lock(call_);
    workers_.reset();
  }

  // How long a worker that has stepped a task polls for the next call before it parks, and how
  // long the caller polls for the workers' tasks: a vector environment calls again within
  // 0.1-0.5 ms (its Python, the policy), and waking a parked thread on a 2-vCPU virtual machine
  // cost about 0.4 ms, as much as a step (bench/README.md). Bounded so that a pause of the caller
  // (a learner's update) costs at most this much CPU per call.
  static constexpr std::chrono::microseconds kPoll{500};

  static void Prepare() { Get().call_.lock(); }
  static void Parent() { Get().call_.unlock(); }
  static void Child() {
    StepPool& p = Get();
    // left unfreed: its destructor would join threads that the child does not have
    static_cast<void>(p.workers_.release());
    p.call_.unlock();  // locked by Prepare on this very thread
  }

  std::mutex call_;
  std::unique_ptr<internal::WorkerPool> workers_;
};

}  // namespace

void StepTasks(const std::vector<ArticulationTask*>& tasks, const Eigen::MatrixXd& actions) {
  const size_t n = tasks.size();
  if (actions.rows() != static_cast<Eigen::Index>(n) || actions.cols() != 7)
    throw Error("step_tasks: actions must have shape (" + std::to_string(n) + ", 7), got (" +
                std::to_string(actions.rows()) + ", " + std::to_string(actions.cols()) + ")");
  if (!actions.allFinite()) throw Error("step_tasks: actions hold NaN or infinite values");
  for (size_t i = 0; i < n; ++i) {
    if (tasks[i] == nullptr) throw Error("step_tasks: task " + std::to_string(i) + " is None");
    for (size_t j = 0; j < i; ++j)
      if (tasks[i] == tasks[j])
        throw Error("step_tasks: task " + std::to_string(i) + " is task " + std::to_string(j) +
                    " again");
  }
  std::vector<std::exception_ptr> errors(n);
  StepPool::Get().Run(static_cast<int>(n), [&](int i) {
    try {
      const Scene::Use use(tasks[i]->GetScene());
      tasks[i]->ApplyAction(actions.row(i).transpose());
      tasks[i]->Step();
    } catch (...) {
      errors[i] = std::current_exception();
    }
  });
  // the first error, once every task has finished its step
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

// --- Impl ----------------------------------------------------------------------------------

namespace internal {

TaskImpl::TaskImpl(const TaskOptions& o) : options(o) {
  if (!(o.timestep > 0) || !(o.control_rate > 0) || o.control_rate * o.timestep > 1.0 + 1e-9)
    throw Error("task: the control rate (" + FormatNumber(o.control_rate) +
                " Hz) must be positive and at most the physics rate (1 / timestep)");
  if (o.cameras && (o.camera_width <= 0 || o.camera_height <= 0))
    throw Error("task: camera size must be positive");
  if (o.video_width < 0 || o.video_height < 0 || (o.video_width > 0) != (o.video_height > 0))
    throw Error("task: video_width and video_height must both be positive, or both 0 (got " +
                std::to_string(o.video_width) + " x " + std::to_string(o.video_height) + ")");
  if (o.object_folder.empty() &&
      (o.object_index < 0 || o.object_index >= PaperModelCount("StorageFurniture")))
    throw Error("task: object_index " + std::to_string(o.object_index) +
                " is out of range: the generated dataset has " +
                std::to_string(PaperModelCount("StorageFurniture")) +
                " StorageFurniture objects (0 to " +
                std::to_string(PaperModelCount("StorageFurniture") - 1) + ")");
  if (!(o.success_fraction > 0 && o.success_fraction <= 1))
    throw Error("task: success_fraction must be in (0, 1]");
  substeps = std::max(1, static_cast<int>(std::lround(1.0 / (o.control_rate * o.timestep))));

  // the object: a PartNet-Mobility folder, or the generator's object written as one
  std::string folder = o.object_folder, what = "'" + o.object_folder + "'";
  if (folder.empty()) {
    GeneratedObject gen = GenerateObject("StorageFurniture", o.object_index, o.dataset_seed);
    folder = EnsureObjectFolder(gen, o.asset_dir);
    what = "StorageFurniture object " + std::to_string(o.object_index) + " (seed " +
           std::to_string(o.dataset_seed) + ")";
  }
  PartNetMobilityLoader loader;
  PartNetMobilityObject obj = loader.Parse(folder);
  std::vector<int> targets = FindTaskTargets(obj, o.type);
  if (targets.empty())
    throw Error(
        "task: " + what + " has no " + TaskTypeName(o.type) + " (a link labelled '" +
        TaskTargetLabel(o.type) + "' in semantics.txt, with a handle and a joint range)" +
        (o.object_folder.empty() ? "; FindTaskObjects lists the objects that have one" : ""));
  if (o.target >= static_cast<int>(targets.size()))
    throw Error("task: target " + std::to_string(o.target) + " is out of range: " + what + " has " +
                std::to_string(targets.size()) + " " + TaskTypeName(o.type) +
                (targets.size() == 1 ? "" : "s"));

  if (o.box_primitives) internal::BoxesForBoxMeshes(obj.articulation);
  if (o.filter_collisions) internal::DisableCollisionsWithin(obj.articulation);

  SceneConfig cfg;
  cfg.timestep = o.timestep;
  scene = std::make_shared<Scene>(cfg);
  // mobility.urdf turns the meshes' front (+z of the annotation frame F) to world -x: a half
  // turn about z makes it face +x; then the bounds' centre goes over the origin
  const Eigen::Quaterniond half_turn(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d centre_W = half_turn * (obj.X_BF.q * (0.5 * (obj.bbox_min + obj.bbox_max)));
  obj.articulation.root_pose = Pose(Eigen::Vector3d(-centre_W.x(), -centre_W.y(), 0), half_turn);
  object = scene->AddArticulation(obj.articulation);
  PlaceOnGround(object, 0.0);
  for (int id : targets) candidates.push_back(obj.LinkIndex(id));
  // cabinet size from its bounds (frame F: x width, y height, z depth)
  cabinet_half_depth = 0.5 * (obj.bbox_max.z() - obj.bbox_min.z());
  cabinet_height = obj.bbox_max.y() - obj.bbox_min.y();
  cabinet_half_width = 0.5 * (obj.bbox_max.x() - obj.bbox_min.x());

  robot_model = BuildFlyingGripper();
  // at q = 0 the TCP is at the root, approaching along -x with the fingers opening along y
  robot_model.articulation.root_pose =
      Pose(Eigen::Vector3d::Zero(),
           Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY())));
  robot = scene->AddArticulation(robot_model.articulation);
  for (const std::string& n : robot_model.arm_joints)
    arm_dofs.push_back(robot.FindJointByName(n).GetDofIndex());
  for (const std::string& n : robot_model.gripper_joints)
    finger_dofs.push_back(robot.FindJointByName(n).GetDofIndex());
  ee_link = robot.FindLinkByName(robot_model.ee_link).GetIndex();
  for (const Link& l : robot.GetLinks())
    if (l.GetName().find("finger") != std::string::npos) finger_links.push_back(l.GetIndex());
  // gravity compensation's tables: the links below each dof's joint (parents come first)
  const std::vector<LinkDesc>& rlinks = robot_model.articulation.links;
  robot_kinematics = KinematicModel::FromArticulation(robot);
  for (size_t i = 0; i < rlinks.size(); ++i) {
    const Link l = robot.GetLink(static_cast<int>(i));
    robot_link_mass.push_back(l.GetMass());
    robot_link_com.push_back(l.GetPose().Inverse().Transform(l.GetCMassPose().p));
    robot_joint_in_child.push_back(i == 0 ? Pose()
                                          : robot.GetJoint(static_cast<int>(i)).GetPoseInChild());
  }
  for (const Joint& j : robot.GetActiveJoints()) {
    GravityJoint g;
    g.joint = j.GetIndex();
    const JointType type = j.GetType();
    if (type != JointType::kPrismatic && type != JointType::kRevolute &&
        type != JointType::kContinuous) {
      gravity_joints.clear();  // GravityCompensation falls back to ComputePassiveForce
      break;
    }
    g.revolute = type != JointType::kPrismatic;
    std::vector<bool> below(rlinks.size(), false);
    below[static_cast<size_t>(g.joint)] = true;
    for (size_t i = 0; i < rlinks.size(); ++i) {
      const int parent = rlinks[i].parent;
      if (parent >= 0 && below[static_cast<size_t>(parent)]) below[i] = true;
      if (!below[i]) continue;
      g.links.push_back(static_cast<int>(i));
      g.mass += robot_link_mass[i];
    }
    gravity_joints.push_back(g);
  }

  // render ids of the candidates and their handles
  for (const RenderEntityInfo& e : GetRenderEntities(*scene))
    if (e.is_link && e.articulation_id == object.GetId()) entity_ids[e.link_index] = e.id;
  for (const RenderVisualInfo& v : GetRenderVisuals(*scene)) {
    if (v.name.rfind("handle-", 0) != 0) continue;
    for (int li : candidates)
      if (entity_ids.count(li) && entity_ids[li] == v.entity_id) handle_visuals[li].push_back(v.id);
  }
  const bool video = o.video_width > 0;
  Eigen::Vector3d centre(0, 0, 0.5 * cabinet_height);
  double d = 0.6 + 1.3 * std::max({cabinet_height, 2 * cabinet_half_width, 0.6});
  double fovy = 50.0 * M_PI / 180.0;
  if (o.cameras || video) {
    if (video && o.render_backend == "rasterizer") {
      // the video's shadows: a 1024 map covers a cabinet's shadow sharply enough at 640 x 480,
      // at less than half the cost of the 2048 the automatic size gives it on a CPU rasterizer
      RasterOptions ro;
      ro.shadow_map_size = 1024;
      SetRenderBackend(*scene, MakeRasterBackend(ro));
    } else {
      SetRenderBackend(*scene, o.render_backend);
    }
    SetAmbientLight(*scene, Eigen::Vector3f(0.35f, 0.35f, 0.35f));
    AddDirectionalLight(*scene, Eigen::Vector3d(-1, -0.5, -1), Eigen::Vector3f(0.8f, 0.8f, 0.8f),
                        video);
  }
  if (video) {
    // a floor for the eye only: a static actor with a visual and no collision shape
    scene->CreateActorBuilder()
        .SetName("floor")
        .AddBoxVisual(Pose(Eigen::Vector3d(0, 0, -0.01)), Eigen::Vector3d(10, 10, 0.01),
                      Eigen::Vector4f(0.55f, 0.52f, 0.48f, 1.0f), "floor")
        .BuildStatic();
    AddDirectionalLight(*scene, Eigen::Vector3d(0.6, 0.8, -0.5),
                        Eigen::Vector3f(0.3f, 0.3f, 0.35f));
    // three-quarter view from the front right, a little above: the drawer's travel (+x) and
    // the door's swing are across the image
    const Eigen::Vector3d look = centre + Eigen::Vector3d(0.15, 0, -0.1 * cabinet_height);
    Camera cam =
        AddCamera(*scene, "video", o.video_width, o.video_height, 45.0 * M_PI / 180.0, 0.05, 20.0);
    cam.SetLocalPose(
        CameraLookAt(look + 0.9 * d * Eigen::Vector3d(1.0, -0.75, 0.6).normalized(), look));
    video_camera = cam;
  }
  if (o.cameras) {
    struct View {
      const char* name;
      Eigen::Vector3d dir;
    };
    for (const View& v : {View{"left", Eigen::Vector3d(1.0, 0.8, 0.45)},
                          View{"right", Eigen::Vector3d(1.0, -0.8, 0.45)},
                          View{"front", Eigen::Vector3d(1.0, 0.0, 0.3)}}) {
      Camera cam = AddCamera(*scene, v.name, o.camera_width, o.camera_height, fovy, 0.05, 10.0);
      cam.SetLocalPose(CameraLookAt(centre + d * v.dir.normalized(), centre));
      cameras.push_back(cam);
    }
  }
  initial_state = scene->Pack();
  Reset(0);
}

void TaskImpl::Reset(std::uint64_t seed) {
  scene->Unpack(initial_state);
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + 12345);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  target_link =
      options.target >= 0
          ? candidates[options.target]
          : candidates[std::uniform_int_distribution<size_t>(0, candidates.size() - 1)(rng)];
  Joint j = object.GetJoint(target_link);
  Eigen::Vector2d lim = j.GetLimits();
  closed_at_lower = std::abs(lim[0]) <= std::abs(lim[1]);
  range = lim[1] - lim[0];
  start_time = scene->GetTime();
  rest_orientation = object.GetLink(target_link).GetPose().q;
  handle_centre_in_link = HandleCentreInLink();
  grasped_once = false;

  // gripper open, in front of the target's handle and to one side
  Eigen::Vector3d handle = HandleCentre();
  // beside the line of sight of the front camera, so that it does not hide the handle
  const double side = U(rng) < 0 ? -1.0 : 1.0;
  Eigen::Vector3d p =
      handle + Eigen::Vector3d(0.3 + 0.05 * U(rng), side * (0.3 + 0.05 * U(rng)), 0.05 * U(rng));
  Eigen::Quaterniond q(Eigen::AngleAxisd(0.1 * U(rng), Eigen::Vector3d::UnitZ()) *
                       Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()));
  PlaceGripper(Pose(p, q), 1.0);
  if (options.init_on_handle) {
    Pose grasp = GroundTruthGrasp();
    PlaceGripper(grasp, 1.0);
    SetGripper(0.0);
    for (int i = 0; i < 25; ++i) StepControl();
    start_time = scene->GetTime();
  }
  last_reward = 0.0;
}

double TaskImpl::Progress() const {
  double q = object.GetJoint(target_link).GetQpos();
  Eigen::Vector2d lim = object.GetJoint(target_link).GetLimits();
  if (!(range > 0) || !std::isfinite(range)) return 0.0;
  return closed_at_lower ? (q - lim[0]) / range : (lim[1] - q) / range;
}

Pose TaskImpl::TcpPose() const { return robot.GetLink(ee_link).GetPose() * robot_model.tcp_in_ee; }

Eigen::Matrix<double, 6, 1> TaskImpl::TcpVelocity() const {
  Link l = robot.GetLink(ee_link);
  Eigen::Vector3d w = l.GetAngularVelocity();
  Eigen::Vector3d r = l.GetPose().q * robot_model.tcp_in_ee.p;
  Eigen::Matrix<double, 6, 1> out;
  out << l.GetVelocity() + w.cross(r), w;
  return out;
}

Eigen::VectorXd TaskImpl::ArmJointsFor(const Pose& tcp) const {
  const Pose rel = robot_model.articulation.root_pose.Inverse() * tcp;
  Eigen::VectorXd q = robot.GetQpos();
  Eigen::Vector3d near(q[arm_dofs[3]], q[arm_dofs[4]], q[arm_dofs[5]]);
  Eigen::Vector3d ypr = EulerZyx(rel.q.toRotationMatrix(), near);
  Eigen::VectorXd out(6);
  out << rel.p, ypr;
  return out;
}

void TaskImpl::PlaceGripper(const Pose& tcp, double opening) {
  Eigen::VectorXd arm = ArmJointsFor(tcp);
  Eigen::VectorXd qpos = robot.GetQpos();
  for (int k = 0; k < 6; ++k) qpos[arm_dofs[k]] = arm[k];
  for (int d : finger_dofs) qpos[d] = FingerPosition(opening);
  robot.SetQpos(qpos);
  robot.SetQvel(Eigen::VectorXd::Zero(robot.Dof()));
  tcp_target = tcp;
  twist.setZero();
  velocity_mode = false;
  Eigen::VectorXd target = robot.GetDriveTarget();
  for (int k = 0; k < 6; ++k) target[arm_dofs[k]] = arm[k];
  for (int d : finger_dofs) target[d] = FingerPosition(opening);
  robot.SetDriveTarget(target);
  robot.SetDriveVelocityTarget(Eigen::VectorXd::Zero(robot.Dof()));
  gripper_fraction = opening;
}

double TaskImpl::FingerPosition(double fraction) const {
  return robot_model.gripper_closed +
         std::clamp(fraction, 0.0, 1.0) * (robot_model.gripper_open - robot_model.gripper_closed);
}

void TaskImpl::SetTcpTarget(const Pose& target) {
  if (!target.p.allFinite() || !target.q.coeffs().allFinite())
    throw Error("task: SetTcpTarget: the target pose is not finite");
  tcp_target = Pose(target.p, target.q.normalized());
  velocity_mode = false;
  twist.setZero();
}

void TaskImpl::SetTcpVelocity(const Eigen::Matrix<double, 6, 1>& t) {
  if (!t.allFinite()) throw Error("task: SetTcpVelocity: the twist is not finite");
  Eigen::Matrix<double, 6, 1> c = t;
  double v = c.head<3>().norm(), w = c.tail<3>().norm();
  if (v > kMaxLinearSpeed) c.head<3>() *= kMaxLinearSpeed / v;
  if (w > kMaxAngularSpeed) c.tail<3>() *= kMaxAngularSpeed / w;
  if (!velocity_mode) tcp_target = TcpPose();
  twist = c;
  velocity_mode = true;
}

void TaskImpl::SetGripper(double fraction) {
  if (!std::isfinite(fraction)) throw Error("task: SetGripper: the opening is not finite");
  gripper_fraction = std::clamp(fraction, 0.0, 1.0);
}

double TaskImpl::GripperOpening() const {
  Eigen::VectorXd q = robot.GetQpos();
  double s = 0;
  for (int d : finger_dofs) s += q[d];
  double span = robot_model.gripper_open - robot_model.gripper_closed;
  return std::clamp((s / finger_dofs.size() - robot_model.gripper_closed) / span, 0.0, 1.0);
}

bool TaskImpl::TouchesTarget() const {
  for (const Contact& c : scene->GetContacts()) {
    const ContactBody* a = &c.body0;
    const ContactBody* b = &c.body1;
    for (int k = 0; k < 2; ++k, std::swap(a, b)) {
      if (a->kind != ContactBody::Kind::kLink || b->kind != ContactBody::Kind::kLink) continue;
      if (a->articulation_id != robot.GetId() || b->articulation_id != object.GetId()) continue;
      if (b->link_index != target_link) continue;
      if (std::find(finger_links.begin(), finger_links.end(), a->link_index) != finger_links.end())
        return true;
    }
  }
  return false;
}

void TaskImpl::ApplyAction(const Eigen::VectorXd& action) {
  if (action.size() != 7)
    throw Error("task: action has " + std::to_string(action.size()) +
                " entries; expected 7 (TCP twist: vx, vy, vz, wx, wy, wz; gripper)");
  for (int i = 0; i < 7; ++i)
    if (!std::isfinite(action[i]))
      throw Error("task: action entry " + std::to_string(i) + " is not finite");
  SetTcpVelocity(action.head<6>());
  SetGripper(0.5 * (std::clamp(action[6], -1.0, 1.0) + 1.0));
}

Eigen::VectorXd TaskImpl::GravityCompensation() const {
  if (gravity_joints.empty() && robot.Dof() > 0) return robot.ComputePassiveForce(true, false);
  const Eigen::Vector3d g = scene->GetGravity();
  const std::vector<Pose> X_WL = robot_kinematics->ForwardKinematics(robot.GetQpos());
  // mass-weighted centres of mass of the robot's links (world)
  std::vector<Eigen::Vector3d> mc(robot_link_mass.size());
  for (size_t i = 0; i < mc.size(); ++i)
    mc[i] = robot_link_mass[i] * X_WL[i].Transform(robot_link_com[i]);
  Eigen::VectorXd out(static_cast<Eigen::Index>(gravity_joints.size()));
  for (size_t k = 0; k < gravity_joints.size(); ++k) {
    const GravityJoint& gj = gravity_joints[k];
    const Pose X_WJ =
        X_WL[static_cast<size_t>(gj.joint)] * robot_joint_in_child[static_cast<size_t>(gj.joint)];
    const Eigen::Vector3d axis = X_WJ.q * Eigen::Vector3d::UnitX();
    // gravity's generalized force on the dof: sum over the moved links of m J^T g, J the
    // Jacobian of the link's centre of mass (axis, or axis x (c - p) for a turning joint)
    double f = 0.0;
    if (gj.revolute) {
      Eigen::Vector3d moment = -gj.mass * X_WJ.p;
      for (int i : gj.links) moment += mc[static_cast<size_t>(i)];
      f = axis.cross(moment).dot(g);
    } else {
      f = gj.mass * axis.dot(g);
    }
    out[static_cast<Eigen::Index>(k)] = -f;
  }
  return out;
}

void TaskImpl::StepControl() {
  const double dt = scene->GetTimestep();
  const double before = Progress();
  for (int s = 0; s < substeps; ++s) {
    Eigen::VectorXd target = robot.GetDriveTarget();
    Eigen::VectorXd vtarget = Eigen::VectorXd::Zero(robot.Dof());
    if (velocity_mode) {
      // integrate the commanded twist into the target pose
      tcp_target.p += twist.head<3>() * dt;
      Eigen::Vector3d w = twist.tail<3>() * dt;
      if (w.norm() > 0)
        tcp_target.q =
            Eigen::Quaterniond(Eigen::AngleAxisd(w.norm(), w.normalized())) * tcp_target.q;
      tcp_target.q.normalize();
    }
    Eigen::VectorXd arm = ArmJointsFor(tcp_target);
    for (int k = 0; k < 6; ++k) target[arm_dofs[k]] = arm[k];
    if (velocity_mode) {
      const Eigen::Matrix3d Rr = robot_model.articulation.root_pose.q.toRotationMatrix();
      Eigen::Vector3d v_root = Rr.transpose() * twist.head<3>();
      Eigen::Vector3d w_root = Rr.transpose() * twist.tail<3>();
      Eigen::Vector3d rates = EulerRateMatrix(arm.tail<3>()).colPivHouseholderQr().solve(w_root);
      for (int k = 0; k < 3; ++k) vtarget[arm_dofs[k]] = v_root[k];
      for (int k = 0; k < 3; ++k) vtarget[arm_dofs[3 + k]] = rates[k];
    }
    for (int d : finger_dofs) target[d] = FingerPosition(gripper_fraction);
    robot.SetDriveTarget(target);
    robot.SetDriveVelocityTarget(vtarget);
    // gravity compensation of the hand (the paper's flying gripper ignores gravity)
    robot.SetQf(GravityCompensation());
    scene->Step();
  }
  // reward
  const double p = Progress();
  const bool touching = TouchesTarget();
  double r = 10.0 * (p - before);
  if (p >= options.success_fraction) r += 1.0;
  // the paper's "negative rewards when the gripper falls off the handle": every step off the
  // target once it has been held, not only the step it was lost
  if (grasped_once && !touching) r -= 0.1;
  if (!grasped_once) r -= 0.5 * (TcpPose().p - HandleCentre()).norm();
  grasped_once = grasped_once || touching;
  last_reward = r;
}

void TaskImpl::TakePictures() {
  if (cameras.empty()) throw Error("task: TakePictures: this task was made without cameras");
  UpdateRender(*scene);
  for (Camera& c : cameras) c.TakePicture();
}

Eigen::VectorXd TaskImpl::RobotState() const {
  Pose tcp = TcpPose();
  Eigen::VectorXd out(14);
  out << tcp.p, tcp.Wxyz(), TcpVelocity(), GripperOpening();
  return out;
}

Eigen::VectorXd TaskImpl::RawObservation() const {
  Eigen::VectorXd q = object.GetQpos(), qd = object.GetQvel(), r = RobotState();
  Eigen::VectorXd out(q.size() + qd.size() + r.size());
  out << q, qd, r;
  return out;
}

Eigen::VectorXd TaskImpl::MobilityObservation() const {
  Joint j = object.GetJoint(target_link);
  Eigen::VectorXd r = RobotState();
  Eigen::VectorXd out(11 + r.size());
  out << j.GetGlobalPose().p, j.GetGlobalAxis(), AverageNormal(), j.GetQpos(), j.GetQvel(), r;
  return out;
}

}  // namespace internal
}  // namespace partsim
