// The SAPIEN paper's heuristic solvers of the drawer and door tasks: perceive the handle in the
// segmented point clouds of the three cameras, grasp it, then pull along the drawer's axis with a
// velocity controller, or turn the door about its hinge while servoing on its measured angle.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "partsim/core/error.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/image_io.h"
#include "partsim/render/scene_render.h"
#include "partsim/render/video.h"
#include "partsim/tasks/tasks.h"
#include "tasks/task_internal.h"

namespace partsim {
namespace {

using internal::HandleGrasp;

/// What the cameras see of the target: its handle's points, the rest of its points and their
/// normals (world frame).
struct Perception {
  std::vector<Eigen::Vector3d> handle_points;
  std::vector<Eigen::Vector3d> panel_points;
  std::vector<Eigen::Vector3d> panel_normals;
};

class Runner {
 public:
  Runner(ArticulationTask& task, const SolverOptions& options) : task_(task), options_(options) {
    if (options_.frame_every < 1)
      throw Error("solver: frame_every must be at least 1, got " +
                  std::to_string(options_.frame_every));
    if (options_.frames_dir.empty() && options_.video_path.empty()) return;
    // the recording camera: the task's video camera, else the front one
    recorder_ = task_.impl().video_camera;
    if (!recorder_) recorder_ = task_.GetCamera("front");
    if (!options_.video_path.empty()) {
      VideoOptions vo;
      vo.fps = task_.GetOptions().control_rate / options_.frame_every;
      video_ = std::make_unique<VideoWriter>(options_.video_path, recorder_->GetWidth(),
                                             recorder_->GetHeight(), vo);
      Record();  // the first frame: the scene before the solver moves
    }
  }

  /// The outcome of the run, and the video finished (the destructor would finish it too,
  /// without reporting errors).
  SolverResult Result(const std::string& stage, const std::string& message) {
    if (video_) video_->Close();
    SolverResult r;
    r.success = task_.IsSuccess();
    r.progress = task_.GetProgress();
    r.seconds = task_.GetElapsed();
    r.stage = stage;
    r.message = r.success ? "" : message;
    return r;
  }

  /// One control step, with frames written when asked.
  void Step() {
    task_.Step();
    ++steps_;
    if (recorder_ && steps_ % options_.frame_every == 0) Record();
  }

  bool OutOfTime() const { return task_.IsTruncated(); }

  /// Renders the recording camera and writes its frame to the PNG folder and the video.
  void Record() {
    UpdateRender(task_.GetScene());
    recorder_->TakePicture(kColor);
    const Picture& picture = recorder_->GetPictureData();
    if (!options_.frames_dir.empty()) {
      char name[64];
      std::snprintf(name, sizeof(name), "frame_%05d.png", frame_++);
      WriteColorPng((std::filesystem::path(options_.frames_dir) / name).string(), picture);
    }
    if (video_) video_->AddFrame(picture);
  }

  /// Moves the TCP to `target` along a straight line at `speed` (m/s), then waits until it is
  /// within 5 mm and ~3 degrees, or `timeout` seconds pass. Returns whether it got there.
  bool MoveTo(const Pose& target, double speed, double timeout) {
    const double dt = 1.0 / task_.GetOptions().control_rate;
    Pose start = task_.GetTcpPose();
    double dist = (target.p - start.p).norm();
    double ang = start.q.angularDistance(target.q);
    int n = std::max(1, static_cast<int>(std::ceil(std::max(dist / speed, ang / 1.0) / dt)));
    for (int i = 1; i <= n && !OutOfTime(); ++i) {
      double s = static_cast<double>(i) / n;
      task_.SetTcpTarget(Pose(start.p + s * (target.p - start.p), start.q.slerp(s, target.q)));
      Step();
    }
    for (double t = 0; t < timeout && !OutOfTime(); t += dt) {
      Pose now = task_.GetTcpPose();
      if ((now.p - target.p).norm() < 5e-3 && now.q.angularDistance(target.q) < 0.05) return true;
      Step();
    }
    return false;
  }

  void Wait(double seconds) {
    const double dt = 1.0 / task_.GetOptions().control_rate;
    for (double t = 0; t < seconds && !OutOfTime(); t += dt) Step();
  }

  /// Segmented points of the target from the cameras (or its meshes without cameras).
  Perception Perceive() {
    Perception out;
    const uint32_t entity = task_.GetTargetEntityId();
    std::vector<uint32_t> handles = task_.GetHandleVisualIds();
    task_.TakePictures();
    for (const Camera& cam : task_.GetCameras()) {
      const Picture& pic = cam.GetPictureData();
      const Pose X_WC = cam.GetPose();
      const Eigen::Matrix3d R_WG = X_WC.q.toRotationMatrix() * RotationCameraToGl();
      const size_t n = static_cast<size_t>(pic.width) * pic.height;
      for (size_t i = 0; i < n; ++i) {
        if (pic.segmentation[2 * i + 1] != entity) continue;
        Eigen::Vector3d p(pic.position[4 * i], pic.position[4 * i + 1], pic.position[4 * i + 2]);
        Eigen::Vector3d w = X_WC.p + R_WG * p;
        if (std::find(handles.begin(), handles.end(), pic.segmentation[2 * i]) != handles.end()) {
          out.handle_points.push_back(w);
        } else {
          Eigen::Vector3d nn(pic.normal[4 * i], pic.normal[4 * i + 1], pic.normal[4 * i + 2]);
          out.panel_points.push_back(w);
          out.panel_normals.push_back(R_WG * nn);
        }
      }
    }
    return out;
  }

  /// The panel's front normal: the mean of the panel normals within 35 degrees of `guess`.
  static bool FrontNormal(const Perception& p, const Eigen::Vector3d& guess, Eigen::Vector3d* n,
                          double* face_offset) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (const Eigen::Vector3d& m : p.panel_normals) {
      if (m.dot(guess) > std::cos(35.0 * M_PI / 180.0)) {
        sum += m;
        ++count;
      }
    }
    if (count < 10) return false;
    *n = sum.normalized();
    // the front face: the points of that orientation, at their median offset
    std::vector<double> offs;
    for (size_t i = 0; i < p.panel_points.size(); ++i)
      if (p.panel_normals[i].dot(*n) > std::cos(20.0 * M_PI / 180.0))
        offs.push_back(p.panel_points[i].dot(*n));
    if (offs.empty()) return false;
    std::nth_element(offs.begin(), offs.begin() + offs.size() / 2, offs.end());
    *face_offset = offs[offs.size() / 2];
    return true;
  }

  /// Perceives the handle and returns a grasp; false (with message) when it is not seen.
  bool FindGrasp(const Eigen::Vector3d& normal_guess, bool vertical_if_round, HandleGrasp* g,
                 std::string* message) {
    if (!options_.use_cameras) {
      auto* impl = Impl();
      *g = internal::GraspFromHandlePoints(impl->HandlePoints(), impl->AverageNormal(),
                                           impl->FrontFaceOffset(), vertical_if_round);
      return true;
    }
    Perception p = Perceive();
    if (p.handle_points.size() < 8) {
      *message = "handle not seen (" + std::to_string(p.handle_points.size()) + " points)";
      return false;
    }
    Eigen::Vector3d n;
    double face = 0;
    if (!FrontNormal(p, normal_guess, &n, &face)) {
      *message = "front of the target not seen";
      return false;
    }
    *g = internal::GraspFromHandlePoints(p.handle_points, n, face, vertical_if_round);
    return true;
  }

  /// Approaches a grasp from `standoff` in front, closes the fingers; true if they hold the
  /// target.
  bool Grasp(const HandleGrasp& g, std::string* message) {
    const Eigen::Vector3d back = g.tcp.q * Eigen::Vector3d(0, 0, -1);  // out of the panel
    task_.SetGripper(1.0);
    Pose pre(g.tcp.p + 0.12 * back, g.tcp.q);
    if (!MoveTo(pre, 0.4, 1.0)) {
      *message = "could not reach the pre-grasp pose";
      return false;
    }
    MoveTo(g.tcp, 0.15, 0.5);
    task_.SetGripper(0.0);
    Wait(0.5);
    if (!task_.GripperTouchesTarget()) {
      *message = "the fingers closed without touching the target";
      return false;
    }
    return true;
  }

  internal::TaskImpl* Impl() { return &task_.impl(); }

  ArticulationTask& task_;
  SolverOptions options_;
  long steps_ = 0;
  int frame_ = 0;
  std::optional<Camera> recorder_;  // the camera that frames and video record
  std::unique_ptr<VideoWriter> video_;
};

/// The joint's opening direction: +1 if opening increases q.
double OpeningSign(const Joint& j) {
  Eigen::Vector2d lim = j.GetLimits();
  return std::abs(lim[0]) <= std::abs(lim[1]) ? 1.0 : -1.0;
}

}  // namespace

SolverResult SolvePullDrawer(ArticulationTask& task, const SolverOptions& options) {
  if (task.GetOptions().type != TaskType::kPullDrawer)
    throw Error("SolvePullDrawer: the task is a door task");
  if (options.use_cameras && task.GetCameras().empty())
    throw Error("SolvePullDrawer: use_cameras needs a task made with cameras");
  Runner run(task, options);
  Joint joint = task.GetTargetJoint();
  const Eigen::Vector3d axis = joint.GetGlobalAxis() * OpeningSign(joint);
  const double speed = 0.15, dt = 1.0 / task.GetOptions().control_rate;
  std::string msg = "the drawer stopped short of 90% of its range", stage = "grasp";
  // grasp and pull; when the fingers slip off the handle before the drawer stops, let go, back
  // off, find the handle where it is now and pull again
  for (int attempt = 0; attempt < 3 && !task.IsTruncated(); ++attempt) {
    HandleGrasp g;
    if (!run.FindGrasp(Eigen::Vector3d::UnitX(), true, &g, &msg))
      return run.Result("perceive", msg);
    if (!run.Grasp(g, &msg)) continue;
    stage = "pull";
    Eigen::Matrix<double, 6, 1> twist;
    twist << speed * axis, Eigen::Vector3d::Zero();
    task.SetTcpVelocity(twist);
    // stop when the drawer stops (its limit) or the fingers lose it
    double stalled = 0.0, pulled = 0.0, lost = 0.0;
    while (!task.IsTruncated()) {
      run.Step();
      pulled += dt;
      double v = task.GetTcpVelocity().head<3>().dot(axis);
      stalled = v < 0.2 * speed ? stalled + dt : 0.0;
      lost = task.GripperTouchesTarget() ? 0.0 : lost + dt;
      if ((pulled > 0.5 && stalled > 0.4) || lost > 0.2) break;
    }
    task.SetTcpVelocity(Eigen::Matrix<double, 6, 1>::Zero());
    if (lost <= 0.2) break;  // held to the end: the drawer is at its limit
    msg = "the fingers slipped off the handle " + std::to_string(attempt + 1) + " times";
    task.SetGripper(1.0);
    run.Wait(0.2);
    Pose back = task.GetTcpPose();
    back.p += 0.08 * axis;
    run.MoveTo(back, 0.3, 0.5);
  }
  run.Wait(0.2);
  return run.Result(stage, msg);
}

SolverResult SolveOpenDoor(ArticulationTask& task, const SolverOptions& options) {
  if (task.GetOptions().type != TaskType::kOpenDoor)
    throw Error("SolveOpenDoor: the task is a drawer task");
  if (options.use_cameras && task.GetCameras().empty())
    throw Error("SolveOpenDoor: use_cameras needs a task made with cameras");
  Runner run(task, options);
  Joint joint = task.GetTargetJoint();
  const double sign = OpeningSign(joint);
  const Eigen::Vector3d axis = joint.GetGlobalAxis() * sign;
  const Eigen::Vector3d origin = joint.GetGlobalPose().p;
  const Eigen::Vector2d lim = joint.GetLimits();
  const double range = lim[1] - lim[0];
  const double dt = 1.0 / task.GetOptions().control_rate;
  const Eigen::Vector3d n0 = Eigen::Vector3d::UnitX();  // the closed door faces the front

  // the door's measured opening angle (rad): from its segmented front normal
  auto measure = [&](double predicted, double* angle) {
    if (!options.use_cameras) {
      *angle = sign * (joint.GetQpos() - (sign > 0 ? lim[0] : lim[1]));
      return true;
    }
    Perception p = run.Perceive();
    Eigen::Vector3d guess = Eigen::AngleAxisd(predicted, axis) * n0, n;
    double face;
    if (!Runner::FrontNormal(p, guess, &n, &face)) return false;
    Eigen::Vector3d a = n0 - n0.dot(axis) * axis, b = n - n.dot(axis) * axis;
    *angle = std::atan2(a.cross(b).dot(axis), a.dot(b));
    return true;
  };

  std::string msg = "the door stopped short of 90% of its range";
  std::string stage = "grasp";
  double angle = 0.0;
  for (int attempt = 0; attempt < 3 && !task.IsTruncated(); ++attempt) {
    Eigen::Vector3d guess = Eigen::AngleAxisd(angle, axis) * n0;
    HandleGrasp g;
    if (!run.FindGrasp(guess, false, &g, &msg)) return run.Result("perceive", msg);
    if (!run.Grasp(g, &msg)) continue;
    stage = "open";
    // the grasp, rigidly attached to the door: turn it about the hinge
    const Pose grasp = task.GetTcpPose();
    const double grasp_angle = angle;
    double commanded = angle, since_progress = 0.0, best = angle;
    int step = 0;
    while (!task.IsTruncated()) {
      if (step % 5 == 0) {
        double m;
        if (measure(commanded, &m)) angle = m;
      }
      ++step;
      if (angle > 0.97 * range) break;
      // lead the measured angle a little, at a bounded angular speed
      double goal = std::min(angle + 0.15, range);
      commanded = std::clamp(goal, commanded - 0.6 * dt, commanded + 0.6 * dt);
      Eigen::AngleAxisd R(commanded - grasp_angle, axis);
      Pose target(origin + R * (grasp.p - origin), Eigen::Quaterniond(R) * grasp.q);
      task.SetTcpTarget(target);
      run.Step();
      if (angle > best + 0.01) {
        best = angle;
        since_progress = 0.0;
      } else {
        since_progress += dt;
      }
      if (since_progress > 1.0) break;  // lost the handle or jammed: let go and grasp again
    }
    if (task.IsSuccess() || angle > 0.97 * range) break;
    // let go and back off along the door's normal before grasping again
    task.SetGripper(1.0);
    run.Wait(0.3);
    Eigen::Vector3d out = Eigen::AngleAxisd(angle, axis) * n0;
    Pose back = task.GetTcpPose();
    back.p += 0.1 * out;
    run.MoveTo(back, 0.3, 0.5);
  }
  task.SetTcpVelocity(Eigen::Matrix<double, 6, 1>::Zero());
  run.Wait(0.2);
  return run.Result(stage, msg);
}

SolverResult SolveTask(ArticulationTask& task, const SolverOptions& options) {
  return task.GetOptions().type == TaskType::kPullDrawer ? SolvePullDrawer(task, options)
                                                         : SolveOpenDoor(task, options);
}

}  // namespace partsim
