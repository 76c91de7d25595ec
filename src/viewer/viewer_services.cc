// The page's commands, served as rosbridge services of the viewer's RosbridgeServer:
// /partsim/set_joint_target (through a JointPositionController of the joint, or the served
// robot's own controllers), /partsim/camera (a picture as PNG), /partsim/reset, /partsim/close,
// the simulation controls (pause, resume, step) and the services extensions add. Commands that
// touch the scene run on its thread: at the next Render() (synchronous mode) or posted to the
// SimServer (served mode).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "partsim/core/error.h"
#include "partsim/render/camera.h"
#include "partsim/render/image_io.h"
#include "partsim/render/scene_render.h"
#include "viewer/viewer_impl.h"

namespace partsim {

using viewer_internal::JoinNames;

std::string viewer_internal::JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "none" : out;
}

void Viewer::Impl::Enqueue(RosbridgeServiceReply reply, std::function<Json(Scene&)> fn) {
  auto run = [this, reply, fn] {
    try {
      if (!scene) throw Error("the viewer has no scene");
      reply(true, internal::DumpJson(fn(*scene)));
    } catch (const std::exception& e) {
      reply(false, e.what());
    }
  };
  if (sim) {
    sim->Post([this, run] {
      run();
      Snapshot(true);
    });
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex);
    commands.push_back(run);
  }
  cv.notify_all();
}

Viewer::Impl::Json Viewer::Impl::SetJointTarget(Scene& s, int a, const std::string& name,
                                                double position) {
  if (!content || a < 0 || a >= static_cast<int>(content->articulations.size()))
    throw Error("articulation " + std::to_string(a) + " does not exist (the scene has " +
                std::to_string(content ? content->articulations.size() : 0) + ")");
  const internal::ContentArticulation& ca = content->articulations[a];
  auto it = ca.joint_by_name.find(name);
  if (it == ca.joint_by_name.end())
    throw Error("articulation '" + ca.name + "' has no joint '" + name +
                "' (joints with a position: " + JoinNames(ca.dof_joints) + ")");
  Articulation art(&s, ca.scene_id);
  Joint joint(&s, ca.scene_id, it->second);
  if (joint.GetDofIndex() < 0)
    throw Error("joint '" + name + "' of '" + ca.name + "' is fixed: it has no position");
  if (art.IsKinematic()) {
    // a kinematic articulation has no drives: its links follow qpos
    Eigen::VectorXd q = art.GetQpos();
    q[joint.GetDofIndex()] = position;
    art.SetQpos(q);
    return {{"success", true}, {"message", "kinematic articulation: qpos set"}};
  }
  // a robot served to network clients moves through its own controllers, as a ROS client's
  // command does
  if (joint_command && joint_command(art, name, position))
    return {{"success", true}, {"message", "commanded through the served robot's controllers"}};
  // any other articulation: a position controller of the joint (the robot layer's, with its
  // gains), updated at its control rate from then on
  std::shared_ptr<JointPositionController>& c = controllers[{a, name}];
  if (!c) {
    JointControllerOptions o;
    o.control_rate = 1.0 / s.GetTimestep();
    c = std::make_shared<JointPositionController>(art, std::vector<std::string>{name}, o);
  }
  c->SetTarget(Eigen::VectorXd::Constant(1, position));
  c->Update();
  if (sim) next_update[c.get()] = sim->GetClockSteps() + c->Period();
  return {{"success", true}, {"message", c->GetStatus().message}};
}

void Viewer::Impl::UpdateControllers(long long steps) {
  for (auto& [key, c] : controllers) {
    if (steps >= 0) {
      long long& next = next_update[c.get()];
      if (steps < next) continue;
      next = steps + c->Period();
    }
    c->Update();
  }
}

Viewer::Impl::Json Viewer::Impl::CameraPicture(Scene& s, const std::string& name,
                                               const std::string& picture) {
  std::vector<std::string> names;
  for (const Camera& cam : GetCameras(s)) {
    names.push_back(cam.GetName());
    if (cam.GetName() != name) continue;
    Camera c = cam;
    UpdateRender(s);
    const int w = c.GetWidth(), h = c.GetHeight();
    Json out = {{"picture", picture}, {"width", w}, {"height", h}};
    std::string png;
    if (picture == "Color") {
      c.TakePicture(kColor);
      const std::vector<uint8_t> rgba = c.GetColorRGBA8();
      png = EncodePng(w, h, 4, rgba.data(), kFastPngCompression);
    } else if (picture == "Depth") {
      // grey: near bright, far dark, over the range seen; black where nothing is seen
      c.TakePicture(kPosition);
      const std::vector<float> depth = c.GetDepth();
      float lo = 0, hi = 0;
      bool any = false;
      for (float d : depth)
        if (d > 0) {
          lo = any ? std::min(lo, d) : d;
          hi = any ? std::max(hi, d) : d;
          any = true;
        }
      std::vector<uint8_t> grey(depth.size(), 0);
      for (size_t i = 0; i < depth.size(); ++i)
        if (depth[i] > 0)
          grey[i] = static_cast<uint8_t>(
              std::lround(55 + 200 * (hi > lo ? (hi - depth[i]) / (hi - lo) : 1.0)));
      png = EncodePng(w, h, 1, grey.data(), kFastPngCompression);
      out["depth_range"] = {lo, hi};
    } else {
      c.TakePicture(kSegmentation);
      const std::vector<uint32_t>& seg = c.GetUintPicture("Segmentation");
      std::vector<uint8_t> rgb(3 * static_cast<size_t>(w) * h);
      for (size_t i = 0; i < rgb.size() / 3; ++i) {
        const std::array<uint8_t, 3> col = SegmentationColor(seg[2 * i + 1]);
        std::copy(col.begin(), col.end(), rgb.begin() + 3 * i);
      }
      png = EncodePng(w, h, 3, rgb.data(), kFastPngCompression);
    }
    out["png"] = internal::Base64(reinterpret_cast<const uint8_t*>(png.data()), png.size());
    return out;
  }
  throw Error("no camera '" + name + "' (cameras: " + JoinNames(names) + ")");
}

namespace {

/// The args of a call as a JSON object (the server checked that they are one).
nlohmann::json Args(const std::string& args_json) { return internal::ParseJsonBounded(args_json); }

}  // namespace

void Viewer::Impl::AddServices() {
  server->AddService(
      "/partsim/set_joint_target",
      [this](const RosbridgeClientPtr&, const std::string& text, RosbridgeServiceReply reply) {
        const Json args = Args(text);
        if (!args.contains("articulation") || !args["articulation"].is_number_integer())
          throw Error("args need an integer 'articulation' (an id of scene.json)");
        if (!args.contains("joint") || !args["joint"].is_string())
          throw Error("args need a string 'joint' (a joint name)");
        if (!args.contains("position") || !args["position"].is_number())
          throw Error("args need a number 'position' (m or rad)");
        const double q = args["position"].get<double>();
        if (!std::isfinite(q))
          throw Error("position must be finite, got " + internal::DumpJson(args["position"]));
        const long long a = args["articulation"].get<long long>();
        const std::string joint = args["joint"].get<std::string>();
        if (a < 0 || a > 1000000000)
          throw Error("articulation " + std::to_string(a) + " does not exist");
        Enqueue(reply, [this, a, joint, q](Scene& s) {
          return SetJointTarget(s, static_cast<int>(a), joint, q);
        });
      });
  server->AddService("/partsim/camera", [this](const RosbridgeClientPtr&, const std::string& text,
                                               RosbridgeServiceReply reply) {
    const Json args = Args(text);
    if (!args.contains("name") || !args["name"].is_string())
      throw Error("args need a string 'name' (a camera of scene.json)");
    const std::string picture = args.value("picture", std::string("Color"));
    if (picture != "Color" && picture != "Depth" && picture != "Segmentation")
      throw Error("picture must be \"Color\", \"Depth\" or \"Segmentation\", got \"" + picture +
                  "\"");
    const std::string name = args["name"].get<std::string>();
    Enqueue(reply, [this, name, picture](Scene& s) { return CameraPicture(s, name, picture); });
  });
  server->AddService("/partsim/close", [this](const RosbridgeClientPtr&, const std::string&,
                                              RosbridgeServiceReply reply) {
    closed = true;
    cv.notify_all();
    reply(true, "{}");
    PublishStatus();
  });
  // pause, resume and step: the SimServer's in served mode, Render()'s otherwise
  RosbridgeSimControls controls;
  auto set_paused = [this](bool pause) {
    if (sim) {
      if (pause)
        sim->Pause();
      else
        sim->Resume();
    } else {
      std::lock_guard<std::mutex> lock(mutex);
      paused = pause;
      pending_steps = 0;
    }
    cv.notify_all();
    PublishStatus();
  };
  controls.pause = [set_paused] { set_paused(true); };
  controls.resume = [set_paused] { set_paused(false); };
  controls.step = [this](long long n) {
    // while running: pause first, then the n steps
    if (sim) {
      if (!sim->IsPaused()) sim->Pause();
      sim->StepN(n);
    } else {
      std::lock_guard<std::mutex> lock(mutex);
      if (!paused) pending_steps = 0;
      paused = true;
      pending_steps = std::min(pending_steps + n, SimServer::kMaxStepRequest);
    }
    cv.notify_all();
    PublishStatus();
  };
  if (sim) {
    controls.reset = [this] {
      sim->Reset();
      RequestSnapshot();
    };
  } else {
    // the scene's thread restores the state the viewer started with
    server->AddService("/partsim/reset", [this](const RosbridgeClientPtr&, const std::string&,
                                                RosbridgeServiceReply reply) {
      Enqueue(reply, [this](Scene& s) {
        s.Unpack(initial_state);
        for (auto& [key, c] : controllers) c->SetTarget(c->GetQpos());
        return Json::object();
      });
    });
  }
  server->SetSimControls(controls);
  // the extensions' services (partsim view --dataset's gallery)
  for (const auto& [name, service] : services)
    server->AddService(name, [service = service](const RosbridgeClientPtr&, const std::string& args,
                                                 RosbridgeServiceReply reply) {
      service(args, [reply](bool ok, const std::string& text) { reply(ok, text); });
    });
}

}  // namespace partsim
