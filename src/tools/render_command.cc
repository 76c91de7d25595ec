// `partsim render [OBJECT] --out DIR`: places an object on a ground under lights and renders it
// from views around it: colour, metric and preview depth, normals and segmentation images, point
// clouds, a segmentation legend and the cameras' intrinsics and poses.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "object_loader.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/image_io.h"
#include "partsim/render/scene_render.h"

namespace partsim::tools {

namespace {

struct RenderArgs {
  ObjectArgs object;
  std::string out;
  std::string backend = "rasterizer";
  int views = 4;
  int width = 640;
  int height = 480;
  std::optional<int> spp;
};

RenderArgs Parse(const std::vector<std::string>& args) {
  RenderArgs a;
  ArgParser p("partsim render", "partsim --help");
  AddObjectArgs(&p, &a.object);
  p.Option("--out", [&](const FlagValue& v) { a.out = v.NonEmpty("a folder name"); });
  // "null" renders nothing; it is left out of the help, for tests
  p.Option("--backend", [&](const FlagValue& v) {
    a.backend = v.Choice({"rasterizer", "pathtracer"}, {"null"});
  });
  p.Option("--views", [&](const FlagValue& v) { a.views = static_cast<int>(v.Integer(1, 360)); });
  p.Option("--width", [&](const FlagValue& v) { a.width = static_cast<int>(v.Integer(1, 16384)); });
  p.Option("--height",
           [&](const FlagValue& v) { a.height = static_cast<int>(v.Integer(1, 16384)); });
  p.Option("--spp", [&](const FlagValue& v) { a.spp = static_cast<int>(v.Integer(1, 1 << 20)); });
  p.Parse(args);
  if (a.out.empty()) p.Fail("--out DIR is required");
  if (a.spp && a.backend != "pathtracer") p.Fail("--spp applies to --backend pathtracer only");
  return a;
}

/// World bounding box of the visuals of entities in `ids` (from the render world); false when
/// they have none.
bool VisualBounds(const RenderWorld& world, const std::vector<uint32_t>& ids, Eigen::Vector3d* lo,
                  Eigen::Vector3d* hi) {
  bool any = false;
  for (const RenderInstance& inst : world.instances) {
    if (std::find(ids.begin(), ids.end(), inst.entity_id) == ids.end() || !inst.mesh) continue;
    for (const Eigen::Vector3f& v : inst.mesh->vertices) {
      Eigen::Vector3d p = (inst.X_WV * v.cast<double>().homogeneous()).head<3>();
      *lo = any ? lo->cwiseMin(p) : p;
      *hi = any ? hi->cwiseMax(p) : p;
      any = true;
    }
  }
  return any;
}

std::string ViewFile(const std::filesystem::path& dir, const char* stem, int k, const char* ext) {
  return (dir / (std::string(stem) + "_" + std::to_string(k) + ext)).string();
}

/// Writes `depth` (width x height, metres along the view axis, 0 where nothing is seen) as an
/// 8-bit grey PNG for viewing: linear from 255 at the nearest surface seen to 48 at the farthest,
/// and 0 where nothing is seen. (The metric 16-bit depth PNG holds millimetres, a few thousand of
/// 65535, which viewers show black.)
void WriteDepthPreviewPng(const std::string& path, int width, int height,
                          const std::vector<float>& depth) {
  constexpr float kNear = 255.0f, kFar = 48.0f;
  float lo = std::numeric_limits<float>::infinity(), hi = 0.0f;
  for (float d : depth) {
    if (d > 0) {
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  }
  std::vector<uint8_t> grey(depth.size(), 0);
  for (size_t i = 0; i < depth.size(); ++i) {
    if (!(depth[i] > 0)) continue;
    const float t = hi > lo ? (depth[i] - lo) / (hi - lo) : 0.0f;
    grey[i] = static_cast<uint8_t>(std::lround(kNear + t * (kFar - kNear)));
  }
  WritePng(path, width, height, 1, grey.data());
}

void WriteJsonFile(const std::filesystem::path& path, const nlohmann::ordered_json& j) {
  std::ofstream out(path);
  out << j.dump(2) << "\n";
  if (!out) throw std::runtime_error("cannot write '" + path.string() + "'");
}

int Render(const RenderArgs& args) {
  LoadedObject l = LoadObject(args.object, SceneConfig());
  Scene& scene = *l.scene;
  std::filesystem::path dir(args.out);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw std::runtime_error("cannot create the output folder '" + args.out +
                             "': " + (ec ? ec.message() : "not a folder"));
  }
  // what an earlier render wrote here goes first, so that no stale view is left beside this
  // run's (other files in the folder stay)
  ClearOwnedOutputs(args.out, {{"color_", ".png"},
                               {"depth_", ".png"},
                               {"depth_preview_", ".png"},
                               {"normal_", ".png"},
                               {"segmentation_", ".png"},
                               {"cloud_", ".ply"},
                               {"segmentation", ".json"},
                               {"cameras", ".json"}});

  // the backend first: a renderer that cannot start fails before any work
  if (args.backend == "pathtracer") {
    PathTracerOptions options;
    options.samples_per_pixel = args.spp.value_or(64);
    SetRenderBackend(scene, MakePathTracerBackend(options));
  } else {
    SetRenderBackend(scene, args.backend);
  }
  RenderBackend& backend = GetRenderBackend(scene);

  // the object's extent, from its visuals (else from its link origins)
  // (an MJCF model's: all its articulations and actors but the floor of its worldbody)
  std::vector<uint32_t> ids;
  std::vector<int> articulations = {l.art.GetScene() ? l.art.GetId() : -1}, actors;
  if (l.mjcf) {
    for (const Articulation& a : l.mjcf->GetArticulations()) articulations.push_back(a.GetId());
    for (const Actor& a : l.mjcf->GetActors())
      if (a.GetType() != ActorType::kStatic) actors.push_back(a.GetId());
  }
  auto has = [](const std::vector<int>& v, int id) {
    return id >= 0 && std::find(v.begin(), v.end(), id) != v.end();
  };
  for (const RenderEntityInfo& e : GetRenderEntities(scene))
    if (has(articulations, e.articulation_id) || has(actors, e.actor_id)) ids.push_back(e.id);
  UpdateRender(scene);
  Eigen::Vector3d lo, hi;
  if (!VisualBounds(GetRenderWorld(scene), ids, &lo, &hi)) {
    if (!l.art.GetScene()) throw std::runtime_error(l.source + ": nothing to draw");
    std::cerr << "partsim render: the object has no visuals; framing its link origins\n";
    lo = hi = l.art.GetLink(0).GetPose().p;
    for (const Link& link : l.art.GetLinks()) {
      lo = lo.cwiseMin(link.GetPose().p);
      hi = hi.cwiseMax(link.GetPose().p);
    }
    lo -= Eigen::Vector3d::Constant(0.25);
    hi += Eigen::Vector3d::Constant(0.25);
  }
  Eigen::Vector3d centre = 0.5 * (lo + hi);
  double radius = std::max(0.5 * (hi - lo).norm(), 1e-3);

  // ground under the object, a key light with shadows, a fill light and some ambient
  scene.AddGround(lo.z());
  AddDirectionalLight(scene, Eigen::Vector3d(-0.4, 0.3, -1.0), Eigen::Vector3f(2.5f, 2.4f, 2.3f),
                      true);
  AddDirectionalLight(scene, Eigen::Vector3d(0.5, -0.6, -0.4), Eigen::Vector3f(0.6f, 0.6f, 0.7f));
  SetAmbientLight(scene, Eigen::Vector3f(0.25f, 0.25f, 0.25f));

  // cameras on a circle around the centre, 25 degrees above it, the whole object in view
  const double fovy = 0.8;
  const double pi = 3.14159265358979323846;
  std::vector<Camera> cameras;
  for (int k = 0; k < args.views; ++k) {
    Camera cam =
        AddCamera(scene, "view_" + std::to_string(k), args.width, args.height, fovy, 0.01, 100.0);
    double half_fov = 0.5 * std::min(cam.GetFovx(), cam.GetFovy());
    double distance = 1.1 * radius / std::sin(half_fov);
    double azimuth = pi / 6 + 2 * pi * k / args.views, elevation = 25 * pi / 180;
    Eigen::Vector3d dir(std::cos(azimuth) * std::cos(elevation),
                        std::sin(azimuth) * std::cos(elevation), std::sin(elevation));
    cam.SetLocalPose(CameraLookAt(centre + distance * dir, centre));
    cameras.push_back(cam);
  }
  UpdateRender(scene);
  std::printf("rendering %s: %d views of %d x %d with %s on %s\n", l.source.c_str(), args.views,
              args.width, args.height, backend.Name().c_str(), backend.Device().c_str());

  // pictures and their files
  nlohmann::ordered_json views = nlohmann::ordered_json::array();
  for (int k = 0; k < args.views; ++k) {
    Camera& cam = cameras[k];
    auto start = std::chrono::steady_clock::now();
    cam.TakePicture();
    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const Picture& picture = cam.GetPictureData();
    WriteColorPng(ViewFile(dir, "color", k, ".png"), picture);
    WriteDepthPng(ViewFile(dir, "depth", k, ".png"), picture);
    WriteDepthPreviewPng(ViewFile(dir, "depth_preview", k, ".png"), args.width, args.height,
                         DepthImage(picture));
    WriteNormalPng(ViewFile(dir, "normal", k, ".png"), picture);
    WriteSegmentationPng(ViewFile(dir, "segmentation", k, ".png"), picture, 1);
    PointCloud cloud = MakePointCloud(cam, PointCloudFrame::kWorld);
    WritePly(ViewFile(dir, "cloud", k, ".ply"), cloud, true);
    std::printf("view %d: %zu points, %.3f s\n", k, cloud.Size(), seconds);

    nlohmann::ordered_json v;
    v["index"] = k;
    v["width"] = args.width;
    v["height"] = args.height;
    Eigen::Matrix3d K = cam.GetIntrinsicMatrix();
    Eigen::Matrix<double, 3, 4> Rt = cam.GetExtrinsicMatrix();
    v["K"] = {
        {K(0, 0), K(0, 1), K(0, 2)}, {K(1, 0), K(1, 1), K(1, 2)}, {K(2, 0), K(2, 1), K(2, 2)}};
    v["extrinsic"] = nlohmann::ordered_json::array();
    for (int r = 0; r < 3; ++r) v["extrinsic"].push_back({Rt(r, 0), Rt(r, 1), Rt(r, 2), Rt(r, 3)});
    Pose X_WC = cam.GetPose();
    v["pose"] = {{"p", {X_WC.p.x(), X_WC.p.y(), X_WC.p.z()}},
                 {"q", {X_WC.q.w(), X_WC.q.x(), X_WC.q.y(), X_WC.q.z()}}};
    v["points"] = cloud.Size();
    views.push_back(v);
  }

  // what the ids and colours of segmentation images name
  nlohmann::ordered_json legend;
  legend["source"] = l.source;
  legend["channel"] = "segmentation_K.png colours actors and links (entity ids)";
  legend["entities"] = nlohmann::ordered_json::array();
  for (const RenderEntityInfo& e : GetRenderEntities(scene)) {
    std::array<uint8_t, 3> c = SegmentationColor(e.id);
    nlohmann::ordered_json j;
    j["id"] = e.id;
    j["kind"] = e.is_link ? "link" : "actor";
    j["name"] = e.name;
    if (e.is_link) j["articulation"] = e.articulation_name;
    j["semantic_label"] = e.semantic_label;
    j["color"] = {c[0], c[1], c[2]};
    legend["entities"].push_back(j);
  }
  legend["visuals"] = nlohmann::ordered_json::array();
  for (const RenderVisualInfo& v : GetRenderVisuals(scene))
    legend["visuals"].push_back({{"id", v.id}, {"entity_id", v.entity_id}, {"name", v.name}});
  WriteJsonFile(dir / "segmentation.json", legend);
  nlohmann::ordered_json cams;
  cams["backend"] = backend.Name();
  cams["device"] = backend.Device();
  cams["convention"] =
      "K and extrinsic [R|t] in OpenCV's camera frame (x right, y down, z forward); pose X_WC "
      "with x forward, y left, z up; quaternion w, x, y, z";
  cams["views"] = views;
  cams["object_bounds"] = {{"min", {lo.x(), lo.y(), lo.z()}},
                           {"max", {hi.x(), hi.y(), hi.z()}},
                           {"note",
                            "world frame, m: box of the object's visuals (of its link origins, "
                            "0.25 m wider, when it has none)"}};
  WriteJsonFile(dir / "cameras.json", cams);
  std::printf("wrote %d views to %s\n", args.views, args.out.c_str());
  return 0;
}

}  // namespace

int RunRenderCommand(const std::vector<std::string>& args) {
  return RunWithExitCode("partsim render", "", [&] { return Render(Parse(args)); });
}

}  // namespace partsim::tools
