// GenerateDataset: the detection and motion-attribute datasets (partsim/vision/dataset.h).
#include "partsim/vision/dataset.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "core/atomic_file.h"
#include "core/file_read.h"
#include "core/json_parse.h"
#include "core/progress.h"
#include "core/worker_pool.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/core/check.h"
#include "partsim/core/constants.h"
#include "partsim/core/error.h"
#include "partsim/core/log.h"
#include "partsim/render/camera.h"
#include "partsim/render/image_io.h"
#include "partsim/render/scene_render.h"
#include "partsim/vision/coco.h"
#include "vision/npz.h"

namespace partsim::vision {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kDone = "DONE";
constexpr std::uint64_t kMaxDatasetFileBytes = std::uint64_t{1} << 30;

// ---------------------------------------------------------------------------------------------
// the objects of a dataset

// The motion dataset's targets: labelled links whose label contains one of
// DatasetOptions::motion_parts and that move on a hinge (a revolute or continuous joint) or a
// slider (a prismatic joint; also one that turns as it slides, whose slide is its helper link's
// joint). The paper's set is doors and drawers.
enum class Motion { kNone, kHinge, kSlider };

bool IsHinge(JointType type) {
  return type == JointType::kRevolute || type == JointType::kContinuous;
}

Motion MotionOf(const PartNetLink& link, const std::vector<std::string>& words) {
  if (std::none_of(words.begin(), words.end(), [&](const std::string& w) {
        return link.semantic_label.find(w) != std::string::npos;
      }))
    return Motion::kNone;
  const JointType type = PartNetMobilityObject::MotionJointType(link);
  if (IsHinge(type)) return Motion::kHinge;
  if (type == JointType::kPrismatic) return Motion::kSlider;
  return Motion::kNone;
}

// The link whose joint is the motion of labelled link `link` of `desc`: the link itself, or its
// helper parent for a slider that turns; -1 when mobility.urdf's joint there is not of the
// motion's kind (the loader has warned about the disagreement).
int MotionLink(const ArticulationDesc& desc, const PartNetLink& pl, int link) {
  const int m = pl.rotates ? desc.links[static_cast<std::size_t>(link)].parent : link;
  if (m < 0) return -1;
  const JointType want = PartNetMobilityObject::MotionJointType(pl);
  const JointType have = desc.links[static_cast<std::size_t>(m)].joint.type;
  return (IsHinge(want) ? IsHinge(have) : have == want) ? m : -1;
}

// "'a'", "'a' or 'b'", "'a', 'b' or 'c'"
std::string OneOf(const std::vector<std::string>& words) {
  std::string out;
  for (std::size_t k = 0; k < words.size(); ++k)
    out += (k == 0 ? "" : k + 1 == words.size() ? " or " : ", ") + ("'" + words[k] + "'");
  return out;
}

struct ObjectInfo {
  std::string folder;
  std::string name;                 // unique in the dataset: its path under the root, '/' -> '_'
  std::string category;             // meta.json model_cat, "Unknown" when absent
  std::vector<std::string> labels;  // "Category/label" of its labelled links
  int hinges = 0, sliders = 0;      // motion targets
  double max_slider_range = 0;      // of its slider targets, m
  bool train = true;
};

std::string CategoryOf(const PartNetMobilityObject& o) {
  return o.category.empty() ? std::string("Unknown") : o.category;
}

std::string PartCategory(const std::string& category, const PartNetLink& link) {
  return category + "/" + link.semantic_label;
}

// SplitMix64: the stream of every random draw (seeded per object, so that the draws do not
// depend on which worker renders the object or in which order).
std::uint64_t Mix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

std::uint64_t Hash(std::uint64_t seed, const std::string& text) {
  std::uint64_t h = Mix(seed);
  for (unsigned char c : text) h = Mix(h ^ c);
  return h;
}

class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  double Uniform(double lo, double hi) {
    state_ = Mix(state_);
    return lo + (hi - lo) * static_cast<double>(state_ >> 11) * 0x1.0p-53;
  }

 private:
  std::uint64_t state_;
};

std::vector<std::string> FindObjectFolders(const std::string& root) {
  if (!fs::is_directory(root))
    throw Error("vision dataset: --dataset '" + root + "' is not a folder");
  std::vector<std::string> folders;
  try {
    folders = FindPartNetMobilityFolders(root);
  } catch (const Error& e) {
    throw Error(std::string("vision dataset: --dataset ") + e.what());
  }
  if (folders.empty())
    throw Error("vision dataset: no PartNet-Mobility object (a folder with mobility.urdf) under '" +
                root + "'");
  return folders;
}

std::string ObjectName(const std::string& root, const std::string& folder) {
  // lexically: a folder reached through a symbolic link keeps the link's name
  std::string rel = fs::path(folder).lexically_relative(root).generic_string();
  if (rel.empty() || rel == ".") rel = fs::path(folder).filename().string();
  std::replace(rel.begin(), rel.end(), '/', '_');
  return rel;
}

// ---------------------------------------------------------------------------------------------
// files

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
  if (!f) throw Error("vision dataset: cannot write '" + path + "'");
}

// Writes `text` through a temporary of its own beside `path`, renamed into place: a reader never
// sees half a file, and writers at once (shards of one dataset in several processes, say) never
// write into one another's file; the last rename wins.
void WriteTextAtomic(const std::string& path, const std::string& text) {
  try {
    partsim::internal::WriteFileAtomically(path, text);
  } catch (const Error& e) {
    throw Error(std::string("vision dataset: ") + e.what());
  }
}

std::string Two(int i) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "%02d", i);
  return buf;
}

json PoseJson(const Pose& p) {
  return {{"p", {p.p.x(), p.p.y(), p.p.z()}}, {"q", {p.q.w(), p.q.x(), p.q.y(), p.q.z()}}};
}

json MatrixJson(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    json row = json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

// Runs part(0) ... part(count - 1) on `jobs` threads in all: this one and jobs - 1 more (a
// WorkerPool's Wait runs parts on the calling thread too). `part` must not throw.
void RunParts(int jobs, int count, const std::function<void(int)>& part) {
  jobs = std::min(jobs, count);
  if (jobs <= 1) {
    for (int i = 0; i < count; ++i) part(i);
    return;
  }
  partsim::internal::WorkerPool pool(jobs - 1);
  pool.Start(count, part);
  pool.Wait();
}

// One step of work at a time on a second thread, in the order given: an object's views are
// written there while the next view renders (a view's files and masks cost about as much CPU as
// its picture, so a worker that waited for both left the cores idle while llvmpipe's threads
// synchronised). Submit waits for the step before (rethrowing what it threw); Finish waits for
// the last; destroying the stage waits too, so that no step outlives the buffers it reads.
class BackgroundStage {
 public:
  BackgroundStage() = default;
  BackgroundStage(const BackgroundStage&) = delete;
  BackgroundStage& operator=(const BackgroundStage&) = delete;
  ~BackgroundStage() {
    if (pending_.valid()) pending_.wait();
  }
  void Submit(std::function<void()> step) {
    Finish();
    pending_ = std::async(std::launch::async, std::move(step));
  }
  void Finish() {
    if (pending_.valid()) pending_.get();
  }

 private:
  std::future<void> pending_;
};

// The time of each phase of rendering an object (DatasetPhase): wall and thread CPU time. One
// object's phases are timed on its worker's thread ("load", "render", "convert") and on its
// writing thread ("write"), each phase from one thread only, and summed into the run's under a
// lock when the object is done.
enum Phase { kLoadPhase, kRenderPhase, kConvertPhase, kWritePhase, kNumPhases };
constexpr const char* kPhaseNames[kNumPhases] = {"load", "render", "convert", "write"};

struct PhaseTimes {
  std::array<long, kNumPhases> count{};
  std::array<double, kNumPhases> wall{}, cpu{};
  void Add(const PhaseTimes& o) {
    for (int p = 0; p < kNumPhases; ++p) {
      count[p] += o.count[p];
      wall[p] += o.wall[p];
      cpu[p] += o.cpu[p];
    }
  }
};

double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// times the scope into phase `phase` of `times` (nothing when `times` is null)
class PhaseTimer {
 public:
  PhaseTimer(PhaseTimes* times, Phase phase) : times_(times), phase_(phase) {
    if (times_ != nullptr) {
      wall_ = std::chrono::steady_clock::now();
      cpu_ = ThreadCpuSeconds();
    }
  }
  ~PhaseTimer() {
    if (times_ == nullptr) return;
    times_->count[phase_] += 1;
    times_->wall[phase_] +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_).count();
    times_->cpu[phase_] += ThreadCpuSeconds() - cpu_;
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  PhaseTimes* times_;
  Phase phase_;
  std::chrono::steady_clock::time_point wall_;
  double cpu_ = 0;
};

// ---------------------------------------------------------------------------------------------
// rendering one object

// Rasterizers kept from object to object: a new one per object costs a GL context, its programs
// and, on llvmpipe, the shader variants compiled at its first picture (about 45 ms per object
// on the 2-core machine, two to three views' time). A worker takes one for an object and puts it
// back when the object is done, so there are never more than the workers. Other backends are
// made per object.
class BackendShelf {
 public:
  explicit BackendShelf(std::string name) : name_(std::move(name)) {}

  // a kept rasterizer, a new one when none is free, null for other backends
  std::unique_ptr<RenderBackend> Take() {
    if (name_ != "rasterizer") return nullptr;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!free_.empty()) {
        std::unique_ptr<RenderBackend> b = std::move(free_.back());
        free_.pop_back();
        return b;
      }
    }
    return MakeRasterBackend();
  }
  // gives back a backend whose object was rendered whole (one that threw is not kept)
  void Put(std::unique_ptr<RenderBackend> backend) {
    if (!backend) return;
    std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(std::move(backend));
  }

 private:
  std::string name_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<RenderBackend>> free_;
};

// A kept backend lent to one object's scene, which owns this and forwards every picture to it.
// Every scene counts its geometry versions from the same start, so that the rasterizer would
// not see a new object as new geometry (and would keep the earlier objects' meshes): each loan
// renders under versions of its own.
class LentBackend final : public RenderBackend {
 public:
  explicit LentBackend(RenderBackend* backend) : backend_(backend) {
    static std::atomic<std::uint64_t> loans{0};
    version_base_ = ++loans << 32;
  }
  std::string Name() const override { return backend_->Name(); }
  std::string Device() const override { return backend_->Device(); }
  void BeginBatch() override { backend_->BeginBatch(); }
  void EndBatch() override { backend_->EndBatch(); }

 protected:
  void DoRender(const RenderWorld& world, const CameraParams& camera, Picture* out,
                unsigned outputs) override {
    world_ = world;
    world_.geometry_version = version_base_ + world.geometry_version;
    backend_->Render(world_, camera, out, outputs);
  }

 private:
  RenderBackend* backend_;
  std::uint64_t version_base_ = 0;
  RenderWorld world_;  // `world` under this loan's versions
};

// Vertex bounds of each mesh, kept across the views of an object (its meshes do not change).
using MeshBounds = std::unordered_map<const MeshData*, std::pair<Eigen::Vector3f, Eigen::Vector3f>>;

// Bounds of everything the scene renders, in the world, from the meshes' vertex bounds.
void RenderBounds(const RenderWorld& world, MeshBounds* cache, Eigen::Vector3d* lo,
                  Eigen::Vector3d* hi) {
  *lo = Eigen::Vector3d::Constant(kInf);
  *hi = Eigen::Vector3d::Constant(-kInf);
  for (const RenderInstance& inst : world.instances) {
    if (!inst.mesh || inst.mesh->vertices.empty()) continue;
    auto [it, added] = cache->try_emplace(inst.mesh.get());
    if (added) {
      Eigen::Vector3f mlo = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
      Eigen::Vector3f mhi = -mlo;
      for (const Eigen::Vector3f& v : inst.mesh->vertices) {
        mlo = mlo.cwiseMin(v);
        mhi = mhi.cwiseMax(v);
      }
      it->second = {mlo, mhi};
    }
    const Eigen::Vector3f& mlo = it->second.first;
    const Eigen::Vector3f& mhi = it->second.second;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector4d corner((k & 1) ? mhi.x() : mlo.x(), (k & 2) ? mhi.y() : mlo.y(),
                                   (k & 4) ? mhi.z() : mlo.z(), 1.0);
      const Eigen::Vector3d w = (inst.X_WV * corner).head<3>();
      *lo = lo->cwiseMin(w);
      *hi = hi->cwiseMax(w);
    }
  }
  if (!(lo->array() <= hi->array()).all()) *lo = *hi = Eigen::Vector3d::Zero();
}

// What one rendered view holds, in pixels and in the OpenCV camera frame (its buffers are
// reused from view to view).
struct View {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;       // h x w x 3
  std::vector<float> depth;            // h x w, m
  std::vector<int> link;               // h x w: link index of our articulation seen, -1 none
  std::vector<Eigen::Vector3f> point;  // h x w: OpenCV camera-frame position (0 if none)
  Eigen::Matrix3d K;
  Eigen::Matrix<double, 3, 4> extrinsic;  // world -> OpenCV camera
  Pose X_WC;
  Eigen::VectorXd qpos;
};

class ObjectRenderer {
 public:
  // `backend`: a kept backend to render with (it must outlive this), or null for a new one of
  // options.backend
  // `times`: where the pictures' and conversions' time goes (may be null)
  ObjectRenderer(const DatasetOptions& options, const std::string& folder, RenderBackend* backend,
                 PhaseTimes* times)
      : options_(options), times_(times), scene_(std::make_unique<Scene>()) {
    PhaseTimer timer(times, kLoadPhase);
    if (backend != nullptr)
      SetRenderBackend(*scene_, std::make_unique<LentBackend>(backend));
    else
      SetRenderBackend(*scene_, options.backend);
    PartNetMobilityLoader loader(scene_.get());
    loader.urdf.load_collisions = false;  // rendered, never stepped
    object_ = loader.Parse(folder);
    articulation_ = scene_->AddArticulation(object_.articulation);
    const double fovy = options.fovy_degrees * kPi / 180.0;
    camera_ = AddCamera(*scene_, "dataset", options.size, options.size, fovy, 0.01, 100.0);
    // ambient light and one directional light from above the object's front, no shadows
    SetAmbientLight(*scene_, Eigen::Vector3f::Constant(0.35f));
    const Eigen::Vector3d front = Front();
    AddDirectionalLight(*scene_, (-front - Eigen::Vector3d(0, 0, 1.5)).normalized(),
                        Eigen::Vector3f::Constant(2.2f), false);
    for (const RenderEntityInfo& e : GetRenderEntities(*scene_)) {
      if (!e.is_link || e.articulation_id != articulation_.GetId()) continue;
      const std::size_t id = e.id;
      if (id >= entity_link_.size()) entity_link_.resize(id + 1, -1);
      entity_link_[id] = e.link_index;
    }
    limits_ = articulation_.GetQlimits();
    // the object's pictures as one batch of the kept rasterizer: its context stays current
    if (backend != nullptr) batch_.emplace(*backend);
  }

  const PartNetMobilityObject& Object() const { return object_; }

  // The object's front in the world: mobility.urdf turns the meshes' front (+z of the
  // annotation frame) to -x of the root.
  Eigen::Vector3d Front() const {
    return articulation_.GetRootPose().q * -Eigen::Vector3d::UnitX();
  }
  Articulation& GetArticulation() { return articulation_; }

  // Joint positions drawn per view: each dof uniformly between its limits; a dof without
  // limits (continuous) uniformly in [-pi, pi).
  Eigen::VectorXd DrawJointPositions(Random* rng) const {
    Eigen::VectorXd q(limits_.rows());
    for (Eigen::Index k = 0; k < q.size(); ++k) {
      const double lo = std::isfinite(limits_(k, 0)) ? limits_(k, 0) : -kPi;
      const double hi = std::isfinite(limits_(k, 1)) ? limits_(k, 1) : kPi;
      q[k] = rng->Uniform(lo, hi);
    }
    return q;
  }

  // Places the camera on the upper hemisphere around the object at joint positions `q`: azimuth
  // within 90 degrees either side of the object's front (Front), elevation 10 to 60
  // degrees, looking at the centre of its bounds from a distance that keeps the bounding sphere
  // in frame (1.0 to 1.3 times the nearest such distance).
  void Render(const Eigen::VectorXd& q, Random* rng, View* view) {
    articulation_.SetQpos(q);
    UpdateRender(*scene_);
    Eigen::Vector3d lo, hi;
    RenderBounds(GetRenderWorld(*scene_), &mesh_bounds_, &lo, &hi);
    const Eigen::Vector3d centre = 0.5 * (lo + hi);
    const double radius = std::max(0.5 * (hi - lo).norm(), 1e-3);
    const Eigen::Vector3d front = Front();
    const double front_azimuth = std::atan2(front.y(), front.x());
    const double azimuth = front_azimuth + rng->Uniform(-0.5 * kPi, 0.5 * kPi);
    const double elevation = rng->Uniform(10.0, 60.0) * kPi / 180.0;
    const double half_fov = 0.5 * options_.fovy_degrees * kPi / 180.0;
    const double distance = radius / std::sin(half_fov) * rng->Uniform(1.0, 1.3);
    const Eigen::Vector3d dir(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    const Eigen::Vector3d eye = centre + distance * dir;
    camera_.LookAt(eye, centre);  // a free camera: the picture reads its pose, not the snapshot
    {
      PhaseTimer timer(times_, kRenderPhase);
      camera_.TakePicture(kColor | kPosition | kSegmentation);
    }
    PhaseTimer timer(times_, kConvertPhase);
    const Picture& pic = camera_.GetPictureData();

    View& v = *view;
    v.width = pic.width;
    v.height = pic.height;
    v.K = camera_.GetIntrinsicMatrix();
    v.extrinsic = camera_.GetExtrinsicMatrix();
    v.X_WC = camera_.GetPose();
    v.qpos = q;
    const std::size_t n = static_cast<std::size_t>(pic.width) * pic.height;
    const std::vector<std::uint8_t> rgba = ToRgba8(pic.color);
    v.rgb.resize(3 * n);
    v.depth.resize(n);
    v.link.resize(n);
    v.point.resize(n);
    const float* position = pic.position.data();
    const std::uint32_t* segmentation = pic.segmentation.data();
    for (std::size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) v.rgb[3 * i + c] = rgba[4 * i + c];
      const float depth = position[4 * i + 3];
      v.depth[i] = depth;  // DepthImage's values
      const std::uint32_t entity = segmentation[2 * i + 1];
      v.link[i] = entity < entity_link_.size() ? entity_link_[entity] : -1;
      // OpenGL camera frame (x right, y up, z back) -> OpenCV
      v.point[i] =
          depth > 0 ? Eigen::Vector3f(position[4 * i], -position[4 * i + 1], -position[4 * i + 2])
                    : Eigen::Vector3f::Zero();
    }
  }

 private:
  const DatasetOptions& options_;
  PhaseTimes* times_;
  std::unique_ptr<Scene> scene_;
  PartNetMobilityObject object_;
  Articulation articulation_;
  Camera camera_;
  std::vector<int> entity_link_;  // render entity id -> link index of the object, -1 none
  MeshBounds mesh_bounds_;
  Eigen::MatrixX2d limits_;
  std::optional<RenderBatch> batch_;  // with a kept backend, for the object's lifetime
};

// Link index -> its PartNet entry (only labelled links of the file).
std::map<int, const PartNetLink*> LabelledLinks(const PartNetMobilityObject& o) {
  std::map<int, const PartNetLink*> out;
  for (const PartNetLink& l : o.links) {
    if (l.semantic_label.empty()) continue;
    try {
      out[o.LinkIndex(l.id)] = &l;
    } catch (const Error&) {
      // an entry of mobility_v2.json without a link in mobility.urdf: nothing to annotate
    }
  }
  return out;
}

// The datasets' PNGs: zlib level 1, rows not filtered. The same pixels as libpng's default
// compression (level 6, a filter chosen per row by trying all five), written about five times
// faster in files 1.5 to 2 times larger: tens of kB per view, beside the 1 MB depth NPY.
constexpr PngCompression kPngCompression = kFastPngCompression;

void WriteViewPictures(const std::string& dir, const std::string& stem, const View& v) {
  WritePng(dir + "/rgb/" + stem + ".png", v.width, v.height, 3, v.rgb.data(), kPngCompression);
  WriteDepthPng(dir + "/depth/" + stem + ".png", v.width, v.height, v.depth.data(),
                kPngCompression);
  WriteNpy(dir + "/depth/" + stem + ".npy", v.depth.data(),
           {static_cast<std::size_t>(v.height), static_cast<std::size_t>(v.width)});
}

json CameraJson(const View& v) {
  return {{"K", MatrixJson(v.K)},
          {"extrinsic", MatrixJson(v.extrinsic)},
          {"pose", PoseJson(v.X_WC)},
          {"width", v.width},
          {"height", v.height}};
}

json RleJson(const Rle& rle) {
  return {{"size", {rle.height, rle.width}}, {"counts", CompressRleCounts(rle.counts)}};
}

// The RLE of every instance 1..count of a width x height instance map (row-major, 0 = none) in
// one column-major walk: the runs EncodeMask makes of each instance's mask (background first,
// a run ends where the pixel's membership changes), without a mask per instance.
std::vector<Rle> EncodeInstances(const std::vector<std::uint16_t>& map, int width, int height,
                                 int count) {
  std::vector<Rle> rle(static_cast<std::size_t>(count) + 1);
  std::vector<std::uint32_t> run_start(rle.size(), 0);  // where each instance's current run began
  std::uint32_t at = 0;
  std::uint16_t previous = 0;
  for (int x = 0; x < width; ++x) {
    for (int y = 0; y < height; ++y, ++at) {
      const std::uint16_t value = map[static_cast<std::size_t>(y) * width + x];
      if (value == previous) continue;
      if (previous != 0) {  // previous's run of pixels ends
        rle[previous].counts.push_back(at - run_start[previous]);
        run_start[previous] = at;
      }
      if (value != 0) {  // value's run of background ends
        rle[value].counts.push_back(at - run_start[value]);
        run_start[value] = at;
      }
      previous = value;
    }
  }
  for (std::size_t k = 1; k < rle.size(); ++k) {
    rle[k].counts.push_back(at - run_start[k]);
    rle[k].height = height;
    rle[k].width = width;
  }
  return rle;
}

// The detection views of one object into `dir`; returns views.json.
json RenderDetectionObject(const DatasetOptions& options, const std::string& folder,
                           const std::string& name, const std::map<std::string, int>& category_ids,
                           const std::string& dir, RenderBackend* backend, long* views_rendered,
                           PhaseTimes* times) {
  ObjectRenderer r(options, folder, backend, times);
  const PartNetMobilityObject& o = r.Object();
  const std::string category = CategoryOf(o);
  // per link index: its PartNet entry when labelled (else null) and its category id
  const std::size_t num_links = r.GetArticulation().GetLinks().size();
  std::vector<const PartNetLink*> labelled(num_links, nullptr);
  std::vector<int> category_of(num_links, 0);
  for (const auto& [link, pl] : LabelledLinks(o)) {
    if (link < 0 || static_cast<std::size_t>(link) >= num_links) continue;
    labelled[static_cast<std::size_t>(link)] = pl;
    category_of[static_cast<std::size_t>(link)] = category_ids.at(PartCategory(category, *pl));
  }
  std::vector<std::string> link_names(num_links);
  for (std::size_t link = 0; link < num_links; ++link)
    link_names[link] = r.GetArticulation().GetLink(static_cast<int>(link)).GetName();
  for (const char* sub : {"rgb", "depth", "instances", "cloud"})
    fs::create_directories(dir + "/" + sub);
  Random rng(Hash(options.seed, name));
  const double min_pixels = options.min_area_fraction * options.size * options.size;
  json views = json::array();
  // the scratch of the writing step, one step at a time
  std::vector<long> pixels(num_links);
  std::vector<int> instance_of(num_links);  // link -> instance number (1-based), 0 none
  std::vector<std::uint16_t> instance_map;
  // view k renders into buffer k % 2 while view k - 1 is written from the other
  std::array<View, 2> buffers;
  BackgroundStage writing;
  for (int k = 0; k < options.views; ++k) {
    View& v = buffers[static_cast<std::size_t>(k % 2)];
    r.Render(r.DrawJointPositions(&rng), &rng, &v);
    ++*views_rendered;
    writing.Submit([&, k, &v = v] {
      PhaseTimer timer(times, kWritePhase);
      const std::string stem = Two(k);
      WriteViewPictures(dir, stem, v);
      // pixel counts of the labelled links seen; instances numbered in link order
      std::fill(pixels.begin(), pixels.end(), 0);
      for (int l : v.link)
        if (l >= 0) ++pixels[static_cast<std::size_t>(l)];
      std::fill(instance_of.begin(), instance_of.end(), 0);
      std::vector<std::size_t> instance_links;  // instance number - 1 -> link
      for (std::size_t link = 0; link < num_links; ++link) {
        if (!labelled[link] || pixels[link] == 0) continue;
        if (static_cast<double>(pixels[link]) < min_pixels) continue;
        instance_links.push_back(link);
        instance_of[link] = static_cast<int>(instance_links.size());
      }
      const std::size_t n = v.link.size();
      instance_map.assign(n, 0);
      for (std::size_t i = 0; i < n; ++i)
        if (v.link[i] >= 0)
          instance_map[i] =
              static_cast<std::uint16_t>(instance_of[static_cast<std::size_t>(v.link[i])]);
      const std::vector<Rle> rles =
          EncodeInstances(instance_map, v.width, v.height, static_cast<int>(instance_links.size()));
      json instances = json::array();
      for (std::size_t m = 0; m < instance_links.size(); ++m) {
        const std::size_t link = instance_links[m];
        const PartNetLink& pl = *labelled[link];
        const Rle& rle = rles[m + 1];
        const std::array<double, 4> box = RleBoundingBox(rle);
        instances.push_back({{"instance", m + 1},
                             {"link", link_names[link]},
                             {"label", pl.semantic_label},
                             {"category", PartCategory(category, pl)},
                             {"joint", pl.joint},
                             {"area", RleArea(rle)},
                             {"bbox", {box[0], box[1], box[2], box[3]}},
                             {"segmentation", RleJson(rle)}});
      }
      WritePng16(dir + "/instances/" + stem + ".png", v.width, v.height, instance_map.data(),
                 kPngCompression);
      if (options.point_clouds) {
        // every pixel that sees a surface, in pixel order
        std::size_t m = 0;
        for (float d : v.depth) m += d > 0 ? 1 : 0;
        std::vector<float> xyz(3 * m);
        std::vector<std::uint8_t> rgb(3 * m);
        std::vector<std::int32_t> instance(m), label(m);
        for (std::size_t i = 0, j = 0; i < n; ++i) {
          if (!(v.depth[i] > 0)) continue;
          for (int c = 0; c < 3; ++c) {
            xyz[3 * j + c] = v.point[i][c];
            rgb[3 * j + c] = v.rgb[3 * i + c];
          }
          instance[j] = instance_map[i];
          label[j] = instance_map[i] ? category_of[static_cast<std::size_t>(v.link[i])] : 0;
          ++j;
        }
        internal::WriteNpz(
            dir + "/cloud/" + stem + ".npz",
            {internal::MakeNpyArray("xyz", xyz, {m, 3}), internal::MakeNpyArray("rgb", rgb, {m, 3}),
             internal::MakeNpyArray("instance", instance, {m}),
             internal::MakeNpyArray("label", label, {m})});
      }
      views.push_back({{"view", k},
                       {"rgb", "rgb/" + stem + ".png"},
                       {"depth", "depth/" + stem + ".png"},
                       {"depth_npy", "depth/" + stem + ".npy"},
                       {"instances_png", "instances/" + stem + ".png"},
                       {"cloud", options.point_clouds ? "cloud/" + stem + ".npz" : ""},
                       {"camera", CameraJson(v)},
                       {"qpos", std::vector<double>(v.qpos.data(), v.qpos.data() + v.qpos.size())},
                       {"instances", instances}});
    });
  }
  writing.Finish();
  return {{"object", name}, {"category", category}, {"views", views}};
}

// The motion samples of one object into `dir`; returns views.json. Per door or drawer, `views`
// samples; a sample whose camera does not see the part (fewer pixels than the threshold) is
// drawn again, at most 10 times, then left out.
json RenderMotionObject(const DatasetOptions& options, const std::string& folder,
                        const std::string& name, const std::string& dir, RenderBackend* backend,
                        long* views_rendered, PhaseTimes* times) {
  ObjectRenderer r(options, folder, backend, times);
  const PartNetMobilityObject& o = r.Object();
  Articulation& art = r.GetArticulation();
  for (const char* sub : {"rgb", "depth", "mask"}) fs::create_directories(dir + "/" + sub);
  Random rng(Hash(options.seed, name));
  const double min_pixels = options.min_area_fraction * options.size * options.size;
  json samples = json::array();
  // a sample renders into one buffer while the one before is written from the other
  std::array<View, 2> buffers;
  std::size_t next = 0;
  BackgroundStage writing;
  for (const auto& [link, pl] : LabelledLinks(o)) {
    const Motion motion = MotionOf(*pl, options.motion_parts);
    const int motion_link = motion == Motion::kNone ? -1 : MotionLink(o.articulation, *pl, link);
    if (motion_link < 0) continue;
    const Joint joint = art.GetJoint(motion_link);
    const int dof = joint.GetDofIndex();
    if (dof < 0) continue;
    const std::string link_name = art.GetLink(link).GetName();
    const double lower = joint.GetLimits()[0];
    for (int k = 0; k < options.views; ++k) {
      View& v = buffers[next];
      bool seen = false;
      for (int attempt = 0; attempt < 10 && !seen; ++attempt) {
        r.Render(r.DrawJointPositions(&rng), &rng, &v);
        ++*views_rendered;
        long count = std::count(v.link.begin(), v.link.end(), link);
        seen = static_cast<double>(count) >= min_pixels;
      }
      if (!seen) continue;
      next = 1 - next;
      // the joint's frame at the sample's joint positions (what Render left), read here: the
      // scene stays on this thread
      art.SetQpos(v.qpos);
      const Pose X_WJ = joint.GetGlobalPose();
      writing.Submit([&, k, link = link, pl = pl, motion, dof, lower, link_name, X_WJ, &v = v] {
        PhaseTimer timer(times, kWritePhase);
        const std::string stem = link_name + "_" + Two(k);
        WriteViewPictures(dir, stem, v);
        std::vector<std::uint8_t> mask(v.link.size());
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        long count = 0;
        for (std::size_t i = 0; i < v.link.size(); ++i) {
          mask[i] = v.link[i] == link ? 255 : 0;
          if (mask[i] && v.depth[i] > 0) {
            centroid += v.point[i].cast<double>();
            ++count;
          }
        }
        if (count > 0) centroid /= static_cast<double>(count);
        WritePng(dir + "/mask/" + stem + ".png", v.width, v.height, 1, mask.data(),
                 kPngCompression);
        // the joint's axis in the OpenCV camera frame; the pivot is the point of the axis
        // nearest the centroid of the part's visible points
        const Eigen::Matrix3d R = v.extrinsic.leftCols<3>();
        const Eigen::Vector3d t = v.extrinsic.col(3);
        const Eigen::Vector3d origin = R * X_WJ.p + t;
        const Eigen::Vector3d axis = (R * (X_WJ.q * Eigen::Vector3d::UnitX())).normalized();
        const Eigen::Vector3d pivot = origin + axis * axis.dot(centroid - origin);
        // the opening from the lower limit; a hinge without limits (continuous) from 0, in
        // [0, 2 pi)
        double state = v.qpos[dof] - (std::isfinite(lower) ? lower : 0.0);
        if (!std::isfinite(lower)) state = std::fmod(std::fmod(state, 2 * kPi) + 2 * kPi, 2 * kPi);
        samples.push_back(
            {{"sample_id", name + "/" + stem},
             {"link", link_name},
             {"label", pl->semantic_label},
             {"type", motion == Motion::kHinge ? "hinge" : "slider"},
             {"rgb", "rgb/" + stem + ".png"},
             {"depth", "depth/" + stem + ".png"},
             {"depth_npy", "depth/" + stem + ".npy"},
             {"mask", "mask/" + stem + ".png"},
             {"camera", CameraJson(v)},
             {"qpos", std::vector<double>(v.qpos.data(), v.qpos.data() + v.qpos.size())},
             {"pivot", {pivot.x(), pivot.y(), pivot.z()}},
             {"axis", {axis.x(), axis.y(), axis.z()}},
             {"state", state}});
      });
    }
  }
  writing.Finish();
  return {{"object", name}, {"category", CategoryOf(o)}, {"samples", samples}};
}

// ---------------------------------------------------------------------------------------------
// the split files

void Merge(const DatasetOptions& options, const std::vector<ObjectInfo>& objects,
           const std::vector<std::string>& categories, double slider_range,
           DatasetSummary* summary) {
  const std::string objects_dir = options.out + "/objects";
  json split[2];  // train, test
  std::set<std::string> objects_in[2];
  long annotation_id = 0;
  if (options.kind == DatasetKind::kDetection) {
    for (json& s : split) {
      s["info"] = {{"description", "partsim movable-part detection"},
                   {"seed", options.seed},
                   {"views", options.views}};
      s["images"] = json::array();
      s["annotations"] = json::array();
      s["categories"] = json::array();
      for (std::size_t c = 0; c < categories.size(); ++c) {
        const std::string& n = categories[c];
        s["categories"].push_back(
            {{"id", c + 1}, {"name", n}, {"supercategory", n.substr(0, n.find('/'))}});
      }
    }
  } else {
    for (json& s : split) {
      s["slider_range"] = slider_range;
      s["samples"] = json::array();
    }
  }
  std::map<std::string, std::size_t> category_id;
  for (std::size_t c = 0; c < categories.size(); ++c) category_id[categories[c]] = c + 1;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const ObjectInfo& info = objects[i];
    const std::string dir = objects_dir + "/" + info.name;
    if (!fs::exists(dir + "/" + kDone)) continue;
    const int s = info.train ? 0 : 1;
    objects_in[s].insert(info.name);
    const json doc = partsim::internal::ParseJsonBounded(partsim::internal::ReadWholeFile(
        dir + "/views.json", "vision dataset", kMaxDatasetFileBytes));
    const std::string prefix = "objects/" + info.name + "/";
    if (options.kind == DatasetKind::kDetection) {
      for (const json& v : doc.at("views")) {
        const long image_id = static_cast<long>(i) * options.views + v.at("view").get<long>() + 1;
        split[s]["images"].push_back({{"id", image_id},
                                      {"file_name", prefix + v.at("rgb").get<std::string>()},
                                      {"width", v.at("camera").at("width")},
                                      {"height", v.at("camera").at("height")},
                                      {"object", info.name},
                                      {"view", v.at("view")}});
        for (const json& inst : v.at("instances")) {
          split[s]["annotations"].push_back(
              {{"id", ++annotation_id},
               {"image_id", image_id},
               {"category_id", category_id.at(inst.at("category").get<std::string>())},
               {"segmentation", inst.at("segmentation")},
               {"area", inst.at("area")},
               {"bbox", inst.at("bbox")},
               {"iscrowd", 0}});
        }
      }
    } else {
      for (const json& smp : doc.at("samples")) {
        const bool hinge = smp.at("type") == "hinge";
        const std::vector<double> pivot = smp.at("pivot"), axis = smp.at("axis");
        const double state = smp.at("state");
        std::vector<double> m(13, 0.0);
        m[hinge ? 0 : 1] = 1;
        if (hinge) {
          for (int c = 0; c < 3; ++c) m[2 + c] = pivot[c], m[5 + c] = axis[c];
          m[11] = state / (2 * kPi);
        } else {
          for (int c = 0; c < 3; ++c) m[8 + c] = axis[c];
          m[12] = slider_range > 0 ? state / slider_range : 0.0;
        }
        json entry = smp;
        for (const char* key : {"rgb", "depth", "depth_npy", "mask"})
          entry[key] = prefix + smp.at(key).get<std::string>();
        entry["object"] = info.name;
        entry["category"] = info.category;
        entry["m"] = m;
        split[s]["samples"].push_back(entry);
      }
    }
  }
  const bool detection = options.kind == DatasetKind::kDetection;
  const char* names[2] = {detection ? "instances_train.json" : "motion_train.json",
                          detection ? "instances_test.json" : "motion_test.json"};
  for (int s = 0; s < 2; ++s) WriteTextAtomic(options.out + "/" + names[s], split[s].dump());
  summary->train_objects = static_cast<int>(objects_in[0].size());
  summary->test_objects = static_cast<int>(objects_in[1].size());
  const char* key = detection ? "images" : "samples";
  summary->train_images = static_cast<long>(split[0][key].size());
  summary->test_images = static_cast<long>(split[1][key].size());
  summary->annotations = annotation_id;
  summary->slider_range = slider_range;
}

void CheckOptions(const DatasetOptions& o) {
  if (o.dataset_root.empty()) throw Error("vision dataset: --dataset is required");
  if (o.out.empty()) throw Error("vision dataset: --out is required");
  if (!(o.views >= 1 && o.views <= 10000))
    throw Error("vision dataset: --views must be in [1, 10000], got " + std::to_string(o.views));
  if (!(o.size >= 16 && o.size <= 4096))
    throw Error("vision dataset: --size must be in [16, 4096], got " + std::to_string(o.size));
  if (!(o.split >= 0 && o.split <= 1))
    throw Error("vision dataset: --split must be in [0, 1], got " + FormatNumber(o.split));
  if (!(o.jobs >= 1 && o.jobs <= 256))
    throw Error("vision dataset: --jobs must be in [1, 256], got " + std::to_string(o.jobs));
  if (!(o.shard_count >= 1 && o.shard_index >= 0 && o.shard_index < o.shard_count))
    throw Error("vision dataset: --shard i/N needs 0 <= i < N, got " +
                std::to_string(o.shard_index) + "/" + std::to_string(o.shard_count));
  if (!(o.backend == "rasterizer" || o.backend == "pathtracer"))
    throw Error("vision dataset: --backend must be rasterizer or pathtracer, got '" + o.backend +
                "'");
  if (!(o.min_area_fraction >= 0 && o.min_area_fraction < 1))
    throw Error("vision dataset: the minimum area fraction must be in [0, 1)");
  if (!(o.fovy_degrees > 1 && o.fovy_degrees < 170))
    throw Error("vision dataset: the field of view must be in (1, 170) degrees");
  if (o.motion_parts.empty()) throw Error("vision dataset: --parts names no label word");
  for (const std::string& w : o.motion_parts)
    if (w.empty() || w.find_first_of(" ,\t\n") != std::string::npos)
      throw Error("vision dataset: --parts takes label words without spaces, got '" + w + "'");
}

// The options that decide the bytes of a dataset, as dataset.json records them; a run into an
// existing dataset must agree with them.
json DefiningOptions(const DatasetOptions& o) {
  json options = {{"kind", o.kind == DatasetKind::kDetection ? "detection" : "motion"},
                  {"views", o.views},
                  {"size", o.size},
                  {"seed", o.seed},
                  {"split", o.split},
                  {"backend", o.backend},
                  {"min_area_fraction", o.min_area_fraction},
                  {"fovy_degrees", o.fovy_degrees},
                  {"point_clouds", o.point_clouds}};
  if (o.kind == DatasetKind::kMotion) options["parts"] = o.motion_parts;
  return options;
}

std::string Duration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  return buf;
}

}  // namespace

DatasetSummary GenerateDataset(const DatasetOptions& options) {
  CheckOptions(options);
  const auto start = std::chrono::steady_clock::now();
  DatasetSummary summary;
  const std::vector<std::string> folders = FindObjectFolders(options.dataset_root);
  fs::create_directories(options.out + "/objects");

  // the dataset as a whole: every object's category, labels and targets (for the split, the
  // category ids and the slider range), whichever shard renders it
  // (parsed on `jobs` threads: reading every object's meshes is most of a run's start)
  std::vector<ObjectInfo> parsed(folders.size());
  std::vector<std::string> parse_error(folders.size());
  std::vector<std::exception_ptr> parse_exception(folders.size());
  RunParts(options.jobs, static_cast<int>(folders.size()), [&](int part) {
    const auto f = static_cast<std::size_t>(part);
    const std::string& folder = folders[f];
    ObjectInfo& info = parsed[f];
    info.folder = folder;
    try {
      info.name = ObjectName(options.dataset_root, folder);
      PartNetMobilityLoader loader;
      loader.urdf.load_collisions = false;
      const PartNetMobilityObject o = loader.Parse(folder);
      info.category = CategoryOf(o);
      for (const auto& [link, pl] : LabelledLinks(o)) {
        info.labels.push_back(PartCategory(info.category, *pl));
        const Motion motion = MotionOf(*pl, options.motion_parts);
        const int m = motion == Motion::kNone ? -1 : MotionLink(o.articulation, *pl, link);
        if (m < 0) continue;
        if (motion == Motion::kHinge) ++info.hinges;
        if (motion == Motion::kSlider) {
          ++info.sliders;
          const JointDesc& j = o.articulation.links[static_cast<std::size_t>(m)].joint;
          if (std::isfinite(j.upper - j.lower))
            info.max_slider_range = std::max(info.max_slider_range, j.upper - j.lower);
        }
      }
    } catch (const Error& e) {
      parse_error[f] = folder + ": " + e.what();
    } catch (...) {
      parse_exception[f] = std::current_exception();  // thrown from here below, as before
    }
  });
  std::vector<ObjectInfo> objects;
  for (std::size_t f = 0; f < folders.size(); ++f) {
    if (parse_exception[f]) std::rethrow_exception(parse_exception[f]);
    if (!parse_error[f].empty()) {
      summary.errors.push_back(parse_error[f]);
      ++summary.failed;
      continue;
    }
    ObjectInfo& info = parsed[f];
    if (options.kind == DatasetKind::kMotion && info.hinges + info.sliders == 0) continue;
    objects.push_back(std::move(info));
  }
  if (objects.empty())
    throw Error("vision dataset: none of the " + std::to_string(folders.size()) +
                " objects under '" + options.dataset_root + "' can be used" +
                (options.kind == DatasetKind::kMotion
                     ? " (the motion dataset needs parts whose label contains " +
                           OneOf(options.motion_parts) +
                           " on a hinge or a slider; --parts chooses the words)"
                     : "") +
                (summary.errors.empty() ? "" : "; first error: " + summary.errors.front()));
  summary.objects = static_cast<int>(objects.size());

  // the split: per category, objects ordered by a hash of the seed and their name; the first
  // round(split * n) train, at most n - 1 when n >= 2
  std::map<std::string, std::vector<std::size_t>> by_category;
  for (std::size_t i = 0; i < objects.size(); ++i) by_category[objects[i].category].push_back(i);
  for (auto& [category, members] : by_category) {
    std::sort(members.begin(), members.end(), [&](std::size_t a, std::size_t b) {
      return Hash(options.seed, objects[a].name) < Hash(options.seed, objects[b].name);
    });
    auto train = static_cast<std::size_t>(std::lround(options.split * members.size()));
    // a category of two or more objects keeps one for testing (unless split is 1)
    if (members.size() >= 2 && options.split < 1) train = std::min(train, members.size() - 1);
    for (std::size_t k = 0; k < members.size(); ++k) objects[members[k]].train = k < train;
  }
  std::set<std::string> category_set;
  double slider_range = 0;
  for (const ObjectInfo& o : objects) {
    category_set.insert(o.labels.begin(), o.labels.end());
    slider_range = std::max(slider_range, o.max_slider_range);
  }
  const std::vector<std::string> categories(category_set.begin(), category_set.end());
  std::map<std::string, int> category_ids;
  for (std::size_t c = 0; c < categories.size(); ++c)
    category_ids[categories[c]] = static_cast<int>(c) + 1;

  // dataset.json: the options that decide the bytes; another run into the folder must agree
  const std::string manifest = options.out + "/dataset.json";
  const json defining = DefiningOptions(options);
  if (fs::exists(manifest)) {
    const json old = partsim::internal::ParseJsonBounded(
        partsim::internal::ReadWholeFile(manifest, "vision dataset", kMaxDatasetFileBytes));
    if (old.value("options", json()) != defining)
      throw Error("vision dataset: '" + options.out +
                  "' holds a dataset made with other options (" +
                  old.value("options", json()).dump() + "; this run: " + defining.dump() +
                  "): use another --out, or the same options to resume");
  }
  json split_json = json::object();
  for (const ObjectInfo& o : objects) split_json[o.name] = o.train ? "train" : "test";
  WriteTextAtomic(manifest, json({{"options", defining},
                                  {"categories", categories},
                                  {"slider_range", slider_range},
                                  {"split", split_json}})
                                .dump(1));

  // this shard's objects that are not done yet
  std::vector<std::size_t> pending;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (static_cast<int>(i % options.shard_count) != options.shard_index) continue;
    if (fs::exists(options.out + "/objects/" + objects[i].name + "/" + kDone)) {
      ++summary.skipped;
      continue;
    }
    pending.push_back(i);
  }
  if (!options.merge_only && !pending.empty()) {
    std::mutex mutex;
    long done = 0;
    PhaseTimes run_times;
    partsim::internal::ProgressLine progress(stderr);
    BackendShelf backends(options.backend);
    // the scan above logged each object's load warnings once; reading the objects again to
    // render them would log them again
    const LogLevel log_level = GetLogLevel();
    if (log_level == LogLevel::kWarning) SetLogLevel(LogLevel::kError);
    struct RestoreLogLevel {
      LogLevel level;
      ~RestoreLogLevel() { SetLogLevel(level); }
    } restore_log_level{log_level};
    RunParts(options.jobs, static_cast<int>(pending.size()), [&](int part) {
      const ObjectInfo& info = objects[pending[static_cast<std::size_t>(part)]];
      const std::string final_dir = options.out + "/objects/" + info.name;
      long views = 0;
      std::string error;
      PhaseTimes times;
      try {
        // made under <name>.partial (removed on an error), renamed into place when whole
        partsim::internal::StagedPath staged(final_dir, final_dir + ".partial");
        const std::string& dir = staged.Temporary();
        fs::remove_all(dir);  // a torn earlier attempt
        fs::remove_all(final_dir);
        fs::create_directories(dir);
        std::unique_ptr<RenderBackend> backend = backends.Take();  // null: a new one per object
        const json doc = options.kind == DatasetKind::kDetection
                             ? RenderDetectionObject(options, info.folder, info.name, category_ids,
                                                     dir, backend.get(), &views, &times)
                             : RenderMotionObject(options, info.folder, info.name, dir,
                                                  backend.get(), &views, &times);
        backends.Put(std::move(backend));
        WriteText(dir + "/views.json", doc.dump(1));
        WriteText(dir + "/" + kDone, "");
        staged.Commit();
      } catch (const std::exception& e) {
        error = info.folder + ": " + e.what();
      }
      std::lock_guard<std::mutex> lock(mutex);
      summary.views += views;
      run_times.Add(times);
      if (error.empty()) {
        ++summary.rendered;
      } else {
        ++summary.failed;
        summary.errors.push_back(error);
      }
      ++done;
      if (options.progress) {
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double rate = summary.views / std::max(elapsed, 1e-9);
        const double eta = elapsed / static_cast<double>(done) *
                           static_cast<double>(static_cast<long>(pending.size()) - done);
        std::ostringstream text;
        text << "[" << done << "/" << pending.size() << "] " << info.name << "  "
             << FormatNumber(std::round(rate * 10) / 10) << " views/s  elapsed "
             << Duration(elapsed) << "  eta " << Duration(eta);
        progress.Update(done, static_cast<long>(pending.size()), text.str());
      }
    });
    progress.Break();
    for (int p = 0; p < kNumPhases; ++p)
      summary.phases.push_back(
          {kPhaseNames[p], run_times.count[p], run_times.wall[p], run_times.cpu[p]});
  }
  std::sort(summary.errors.begin(), summary.errors.end());
  Merge(options, objects, categories, slider_range, &summary);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace partsim::vision
