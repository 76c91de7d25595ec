#include "partsim/viewer/gallery.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>
#include <utility>

#include "core/json_parse.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/assets/scene_file.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/image_io.h"
#include "partsim/render/scene_render.h"
#include "viewer/http_util.h"

// The gallery lives on two threads: the network thread answers /api/gallery.json from what the
// scan found (immutable after construction) and hands everything that touches a scene (opening,
// closing, thumbnails) to the viewer's command queue, which Run's thread empties in Render().

namespace partsim {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

std::string Dump(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace); }

/// The folder's name relative to the root ("." for the root itself).
std::string Relative(const fs::path& folder, const fs::path& root) {
  std::string rel = folder.lexically_relative(root).generic_string();
  return rel.empty() ? "." : rel;
}

/// The world box of the box [lo, hi] of frame X_WB.
void WorldBox(const Pose& X_WB, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
              Eigen::Vector3d* wlo, Eigen::Vector3d* whi) {
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(),
                                 (k & 4) ? hi.z() : lo.z());
    const Eigen::Vector3d w = X_WB.Transform(corner);
    *wlo = k ? wlo->cwiseMin(w) : w;
    *whi = k ? whi->cwiseMax(w) : w;
  }
}

}  // namespace

Pose FrameObjectCameraPose(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                           const Eigen::Vector3d& front, double fovy, double azimuth,
                           double elevation, double margin) {
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-3);
  const double distance = margin * radius / std::sin(0.5 * fovy);
  const double az = std::atan2(front.y(), front.x()) + azimuth;
  const Eigen::Vector3d dir(std::cos(elevation) * std::cos(az), std::cos(elevation) * std::sin(az),
                            std::sin(elevation));
  return CameraLookAt(centre + distance * dir, centre);
}

Gallery::Gallery(const GalleryOptions& options) : options_(options) {
  if (!(options.timestep > 0) || !(options.cycle_seconds > 0) || options.thumbnail_width < 1 ||
      options.thumbnail_height < 1)
    throw Error("Gallery: the timestep, cycle and thumbnail size must be positive");
  const fs::path root(options.root);
  std::error_code ec;
  if (options.root.empty()) throw Error("the gallery needs a dataset folder (ROOT)");
  if (!fs::exists(root, ec)) throw Error("dataset folder '" + options.root + "' does not exist");
  if (!fs::is_directory(root, ec))
    throw Error("dataset folder '" + options.root + "' is not a folder");

  // object folders at any depth, through symbolic links; what cannot be searched (a folder
  // that cannot be read, a link loop) is listed with the errors
  std::vector<UnreadableFolder> unreadable;
  const std::vector<std::string> found = FindPartNetMobilityFolders(options.root, &unreadable);
  const std::vector<fs::path> folders(found.begin(), found.end());
  for (const UnreadableFolder& u : unreadable)
    errors_.push_back({Relative(u.folder, root), u.reason});

  PartNetMobilityLoader loader;
  loader.urdf.load_collisions = false;  // labels and joints: the scan draws and steps nothing
  std::set<std::string> categories_seen;
  for (const fs::path& folder : folders) {
    PartNetMobilityObject object;
    try {
      object = loader.Parse(folder.string());
    } catch (const std::exception& e) {
      errors_.push_back({Relative(folder, root), e.what()});
      continue;
    }
    categories_seen.insert(object.category.empty() ? "(none)" : object.category);
    if (!options.category.empty() && object.category != options.category) continue;
    GalleryObject g;
    g.folder = folder.string();
    g.name = Relative(folder, root);
    g.category = object.category;
    for (const PartNetLink& link : object.links) {
      if (link.joint != "hinge" && link.joint != "slider") continue;
      ++g.parts;
      if (std::find(g.labels.begin(), g.labels.end(), link.semantic_label) == g.labels.end())
        g.labels.push_back(link.semantic_label);
    }
    ++category_counts_[g.category];
    objects_.push_back(std::move(g));
    // the bounds at rest in the root frame: the annotation frame's box through X_BF
    Eigen::Vector3d lo, hi;
    WorldBox(object.X_BF, object.bbox_min, object.bbox_max, &lo, &hi);
    bounds_lo_.push_back(lo);
    bounds_hi_.push_back(hi);
  }
  if (objects_.empty()) {
    std::string why;
    if (!options.category.empty() && !categories_seen.empty()) {
      for (const std::string& c : categories_seen) why += (why.empty() ? "" : ", ") + c;
      throw Error("dataset folder '" + options.root + "' holds no object of category '" +
                  options.category + "' (its categories: " + why + ")");
    }
    if (!errors_.empty())
      why = "; " + std::to_string(errors_.size()) + " could not be read, e.g. " +
            errors_.front().name + ": " + errors_.front().error;
    throw Error("dataset folder '" + options.root +
                "' holds no PartNet-Mobility object (a folder with mobility.urdf)" + why);
  }
  empty_ = std::make_unique<Scene>();
}

Gallery::~Gallery() = default;

std::string Gallery::GalleryJson() const {
  Json objects = Json::array();
  for (size_t i = 0; i < objects_.size(); ++i) {
    const GalleryObject& o = objects_[i];
    objects.push_back({{"index", i},
                       {"name", o.name},
                       {"category", o.category},
                       {"parts", o.parts},
                       {"labels", o.labels},
                       {"thumbnail", "/api/thumbnail/" + std::to_string(i) + ".png"}});
  }
  Json errors = Json::array();
  for (const GalleryError& e : errors_) errors.push_back({{"name", e.name}, {"error", e.error}});
  const int open = open_;
  return Dump({{"root", options_.root},
               {"objects", objects},
               {"categories", category_counts_},
               {"errors", errors},
               {"open", open >= 0 ? Json(open) : Json(nullptr)}});
}

void Gallery::AttachTo(Viewer* viewer) {
  if (!viewer) throw Error("Gallery::AttachTo: the viewer is null");
  viewer_ = viewer;
  viewer->SetScene(empty_.get());
  viewer->AddApiRoute("/api/gallery.json", [this](const std::string& path, ViewerHttpRespond r) {
    if (path != "/api/gallery.json")
      return r({404, "text/plain; charset=utf-8", "no API path '" + path + "'\n"});
    r({200, "application/json", GalleryJson()});
  });
  viewer->AddApiRoute("/api/thumbnail/", [this](const std::string& path, ViewerHttpRespond r) {
    const long long i = internal::PathIndex(path, "/api/thumbnail/", ".png");
    if (i < 0 || i >= static_cast<long long>(objects_.size()))
      return r({404, "text/plain; charset=utf-8",
                "no thumbnail '" + path + "': the gallery has objects 0 to " +
                    std::to_string(objects_.size() - 1) + " (/api/thumbnail/I.png)\n"});
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = thumbnails_.find(static_cast<int>(i));
      if (it != thumbnails_.end()) return r({200, "image/png", it->second});
    }
    viewer_->Post([this, i, r] {
      try {
        r({200, "image/png", Thumbnail(static_cast<int>(i))});
      } catch (const std::exception& e) {
        r({500, "text/plain; charset=utf-8",
           "thumbnail " + std::to_string(i) + ": " + e.what() + "\n"});
      }
    });
  });
  viewer->AddService("/partsim/open", [this](const std::string& args, ViewerServiceReply reply) {
    const Json a = internal::ParseJsonBounded(args);
    const long long n = static_cast<long long>(objects_.size());
    if (!a.is_object() || !a.contains("index") || !a["index"].is_number_integer())
      return reply(false, "args need an integer 'index' (an object of /api/gallery.json, 0 to " +
                              std::to_string(n - 1) + ")");
    const long long i = a["index"].get<long long>();
    if (i < 0 || i >= n)
      return reply(false, "no object " + std::to_string(i) + ": the gallery has objects 0 to " +
                              std::to_string(n - 1));
    viewer_->Post([this, i, reply] {
      try {
        Open(static_cast<int>(i));
        reply(true, Dump({{"success", true}, {"message", objects_[i].name}}));
      } catch (const std::exception& e) {
        reply(false, e.what());
      }
    });
  });
  viewer->AddService("/partsim/gallery", [this](const std::string&, ViewerServiceReply reply) {
    viewer_->Post([this, reply] {
      CloseObject();
      reply(true, Dump({{"success", true}, {"message", ""}}));
    });
  });
}

void Gallery::Open(int index) {
  if (index < 0 || index >= static_cast<int>(objects_.size()))
    throw Error("no object " + std::to_string(index) + ": the gallery has objects 0 to " +
                std::to_string(objects_.size() - 1));
  const GalleryObject& o = objects_[index];
  SceneConfig cfg;
  cfg.timestep = options_.timestep;
  auto scene = std::make_unique<Scene>(cfg);
  scene->AddGround(0.0);
  std::vector<Articulation> added;
  try {
    added = AddSceneObjects(scene.get(), o.folder, Pose(), true);
  } catch (const std::exception& e) {
    throw Error("cannot open " + o.name + ": " + e.what());
  }
  // standing 2 mm above the ground, so that no part rubs on it while it moves
  for (Articulation& a : added) PlaceOnGround(a, 0.002);
  SetAmbientLight(*scene, Eigen::Vector3f(0.35f, 0.35f, 0.35f));
  AddDirectionalLight(*scene, Eigen::Vector3d(-1, -0.5, -1), Eigen::Vector3f(0.8f, 0.8f, 0.8f));
  Camera camera = AddCamera(*scene, "front", 640, 480, 1.0, 0.05, 20.0);
  Eigen::Vector3d lo, hi;
  const Pose X_WB = added.empty() ? Pose() : added.front().GetRootPose();
  WorldBox(X_WB, bounds_lo_[index], bounds_hi_[index], &lo, &hi);
  camera.SetLocalPose(
      FrameObjectCameraPose(lo, hi, X_WB.q * -Eigen::Vector3d::UnitX(), camera.GetFovy()));

  // every movable joint sweeps its range (a continuous one a full turn) under a drive
  std::vector<Sweep> sweeps;
  for (Articulation& a : added) {
    double mass = 0;
    for (const Link& l : a.GetLinks()) mass = std::max(mass, l.GetMass());
    mass = std::max(mass, 1e-3);
    for (Joint& j : a.GetActiveJoints()) {
      const Eigen::Vector2d lim = j.GetLimits();
      Sweep s;
      s.articulation = a.GetId();
      s.joint = j.GetIndex();
      if (std::isfinite(lim[0]) && std::isfinite(lim[1])) {
        s.lo = lim[0];
        s.hi = lim[1];
      } else {
        s.lo = j.GetQpos();
        s.hi = s.lo + 2 * kPi;
      }
      if (j.GetDriveStiffness() == 0 && j.GetDriveDamping() == 0)
        j.SetDriveProperty(400 * mass, 40 * mass);  // as the viewer's set_joint_target does
      sweeps.push_back(s);
    }
  }
  viewer_->SetScene(scene.get());
  opened_ = std::move(scene);  // the object open before (if any) goes now
  sweeps_ = std::move(sweeps);
  open_ = index;
}

void Gallery::CloseObject() {
  viewer_->SetScene(empty_.get());
  opened_.reset();
  sweeps_.clear();
  open_ = -1;
}

void Gallery::Animate(double t) {
  if (!opened_) return;
  // 0 at rest, 1 at the far end of the range, and back, once a cycle
  const double phase = 0.5 * (1 - std::cos(2 * kPi * t / options_.cycle_seconds));
  for (const Sweep& s : sweeps_) {
    Joint j(opened_.get(), s.articulation, s.joint);
    j.SetDriveTarget(s.lo + phase * (s.hi - s.lo));
  }
}

std::string Gallery::Thumbnail(int index) {
  if (index < 0 || index >= static_cast<int>(objects_.size()))
    throw Error("no object " + std::to_string(index) + ": the gallery has objects 0 to " +
                std::to_string(objects_.size() - 1));
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = thumbnails_.find(index);
    if (it != thumbnails_.end()) return it->second;
  }
  const int w = options_.thumbnail_width, h = options_.thumbnail_height;
  if (!thumbs_) {
    // one scene (and one rasterizer) for every thumbnail: lit from the front and above
    thumbs_ = std::make_unique<Scene>();
    SetRenderBackend(*thumbs_, "rasterizer");
    SetAmbientLight(*thumbs_, Eigen::Vector3f::Constant(0.35f));
    AddDirectionalLight(*thumbs_, Eigen::Vector3d(1, 0.3, -1.5).normalized(),
                        Eigen::Vector3f::Constant(2.2f));
    AddCamera(*thumbs_, "thumbnail", w, h, 0.8, 0.01, 100.0);
  }
  PartNetMobilityLoader loader(thumbs_.get());
  loader.urdf.load_collisions = false;  // drawn, never stepped
  Articulation a = loader.Load(objects_[index].folder);
  std::string png;
  try {
    Camera camera = GetCameras(*thumbs_).front();
    Eigen::Vector3d lo, hi;
    const Pose X_WB = a.GetRootPose();
    WorldBox(X_WB, bounds_lo_[index], bounds_hi_[index], &lo, &hi);
    camera.SetLocalPose(
        FrameObjectCameraPose(lo, hi, X_WB.q * -Eigen::Vector3d::UnitX(), camera.GetFovy()));
    UpdateRender(*thumbs_);
    camera.TakePicture(kColor);
    const std::vector<uint8_t> rgba = camera.GetColorRGBA8();
    png = EncodePng(w, h, 4, rgba.data(), kFastPngCompression);
  } catch (...) {
    thumbs_->RemoveArticulation(a);
    throw;
  }
  thumbs_->RemoveArticulation(a);
  std::lock_guard<std::mutex> lock(mutex_);
  thumbnails_[index] = png;
  return png;
}

void Gallery::Run(const std::function<bool()>& keep_going) {
  using Clock = std::chrono::steady_clock;
  if (!viewer_) throw Error("Gallery::Run: attach the gallery to a viewer first");
  const double dt = options_.timestep;
  Clock::time_point anchor = Clock::now();
  long long steps = 0;  // taken since anchor
  Scene* stepped = nullptr;
  auto reanchor = [&] {
    anchor = Clock::now();
    steps = 0;
  };
  while (keep_going() && !viewer_->IsClosed()) {
    // the page's commands (open, close, thumbnails, joints, ...); blocks while paused
    const bool returned = viewer_->Render(0.1);
    if (viewer_->IsClosed()) break;
    Scene* scene = opened_.get();
    if (scene != stepped) {
      stepped = scene;
      reanchor();
    }
    if (!returned) {  // still paused
      reanchor();
      continue;
    }
    if (!scene) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      continue;
    }
    if (viewer_->IsPaused()) {  // a step the page asked for
      Animate(scene->GetTime());
      scene->Step();
      reanchor();
      continue;
    }
    // real time: the steps due since the anchor; more than 0.1 s behind drops the lag
    const double wall = std::chrono::duration<double>(Clock::now() - anchor).count();
    long long due = static_cast<long long>(wall / dt) - steps;
    if (due * dt > 0.1) {
      reanchor();
      due = 1;
    }
    for (long long k = 0; k < due; ++k) {
      Animate(scene->GetTime());
      scene->Step();
      ++steps;
    }
    const double next =
        (steps + 1) * dt - std::chrono::duration<double>(Clock::now() - anchor).count();
    if (next > 0) std::this_thread::sleep_for(std::chrono::duration<double>(std::min(next, 0.01)));
  }
}

}  // namespace partsim
