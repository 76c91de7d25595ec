// The path tracer backend: Intel Embree 3 ray casting, unidirectional path tracing on the CPU.
//
// Geometry: one Embree scene per distinct mesh (vertices in the visual's frame) and one instance
// per RenderInstance in a top-level scene, the instance ID being the index of the instance in
// RenderWorld::instances. Meshes are rebuilt only when RenderWorld::geometry_version changes (or
// the list of meshes does); otherwise only the moved instances get a new transform and the small
// top-level BVH is rebuilt.
//
// Light transport:
// - materials: the rasterizer's metallic/roughness model: Oren-Nayar diffuse (sigma =
//   roughness) weighted by (1 - F) (1 - metallic), GGX specular (alpha = roughness^2,
//   Smith-Schlick G, Schlick Fresnel with F0 = mix(0.04, base colour, metallic)), roughness
//   clamped to [0.05, 1]; bounces sample a mixture of a cosine lobe and GGX normals; surfaces are
//   two-sided; base colour alpha (transparency) is ignored;
// - next-event estimation towards every light at every vertex, with soft shadows: directional
//   lights subtend a cone of 0.5 degree angular radius, point and spot lights are disks of 2 cm
//   radius facing the shaded point; light colour is the irradiance at normal incidence for a
//   directional light and the intensity (divided by the squared distance) for point and spot
//   lights; spot lights fade smoothly from inner_angle to outer_angle; every light casts
//   shadows (LightDesc::shadow only switches the rasterizer's shadow maps);
// - the ambient colour is a uniform environment light (radiance), gathered when a bounce ray
//   escapes the scene;
// - up to max_depth bounces: at most max_depth surface vertices are shaded, and the bounce ray
//   from the last one still gathers the environment; Russian roulette from the third vertex;
// - camera rays that miss everything are background: colour (0, 0, 0) with alpha 0 (the
//   environment lights the scene but is not seen directly).
//
// Outputs: the first sample of every pixel goes exactly through the OpenCV pixel centre
// K^-1 (u, v, 1), and its first hit fills Albedo, Normal (shading normal turned towards the
// camera, in the OpenGL camera frame), Position and Segmentation; Color is the mean over
// samples_per_pixel samples jittered uniformly within the pixel (samples that miss add black),
// clamped to [0, 1], with alpha 1 where the centre ray hits a surface. Every sample seeds its own
// PCG32 from (seed, pixel index, sample index), so images do not depend on the number of threads.
#include <embree3/rtcore.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "partsim/core/error.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera_math.h"
#include "render/pathtracer/pt_sampling.h"
#include "render/pathtracer/pt_texture.h"

namespace partsim {

namespace {

using internal::Bsdf;
using internal::kPi;
using internal::Pcg32;
using internal::PtTexture;
using internal::Vec3;

/// Angular radius of directional lights (rad): soft shadows like a sun twice the real one's size.
constexpr float kDirectionalAngularRadius = 0.5f * kPi / 180.0f;
/// Radius of point and spot lights (m).
constexpr float kPointLightRadius = 0.02f;
constexpr float kInf = std::numeric_limits<float>::infinity();

/// What shading needs to know of an instance, refreshed every Render().
struct InstanceShading {
  const MeshData* mesh = nullptr;
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();  ///< linear part of X_WV
  Eigen::Vector3f t = Eigen::Vector3f::Zero();      ///< translation of X_WV
  Eigen::Matrix3f N = Eigen::Matrix3f::Identity();  ///< normal matrix (R^-T)
  Vec3 base = Vec3::Constant(0.8f);
  float roughness = 0.8f;
  float metallic = 0.0f;
  const PtTexture* texture = nullptr;
  bool has_normals = false;
  bool has_uvs = false;
  uint32_t visual_id = 0;
  uint32_t entity_id = 0;
};

/// A shaded surface point in the world frame.
struct SurfacePoint {
  Vec3 p;     ///< position (m)
  Vec3 ng;    ///< geometric normal, on the side the ray came from
  Vec3 ns;    ///< shading normal, on the same side as ng
  Vec3 base;  ///< base colour, texture included
  float roughness;
  float metallic;
  const InstanceShading* inst;
};

/// Camera rays of one render.
struct CameraRays {
  Eigen::Matrix3d K_inv;
  Eigen::Matrix3d R_WO;  ///< OpenCV camera frame in world
  Eigen::Matrix3d R_GW;  ///< world in OpenGL camera frame
  Eigen::Vector3d origin;
  double near = 0.01;
  double far = 100.0;
};

float Smoothstep(float e0, float e1, float x) {
  if (e1 <= e0) return x >= e0 ? 1.0f : 0.0f;
  float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

void EmbreeErrorCallback(void* user, RTCError code, const char* message) {
  auto* last = static_cast<std::string*>(user);
  *last = message ? message : ("Embree error " + std::to_string(static_cast<int>(code)));
}

class PathTracerBackend : public RenderBackend {
 public:
  explicit PathTracerBackend(const PathTracerOptions& options) : options_(options) {
    threads_ =
        options.threads > 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());
    std::string config = "threads=" + std::to_string(threads_);
    device_ = rtcNewDevice(config.c_str());
    if (!device_) throw Error("path tracer: cannot create an Embree device");
    rtcSetDeviceErrorFunction(device_, EmbreeErrorCallback, &embree_error_);
  }

  ~PathTracerBackend() override {
    ReleaseScene();
    rtcReleaseDevice(device_);
  }

  PathTracerBackend(const PathTracerBackend&) = delete;
  PathTracerBackend& operator=(const PathTracerBackend&) = delete;

  std::string Name() const override { return "pathtracer"; }

  std::string Device() const override {
    return "Embree " RTC_VERSION_STRING " path tracer on the CPU (" + std::to_string(threads_) +
           " threads, " + std::to_string(options_.samples_per_pixel) + " spp, max depth " +
           std::to_string(options_.max_depth) + ")";
  }

 protected:
  // every output comes from the same primary paths: all are traced, and Render drops those not
  // asked for
  void DoRender(const RenderWorld& world, const CameraParams& camera, Picture* out,
                unsigned outputs) override {
    SyncGeometry(world);
    SyncShading(world);
    lights_ = &world.lights;
    ambient_ = world.ambient;

    // camera rays through OpenCV pixel centres
    CameraRays rays;
    rays.K_inv = camera.K.inverse();
    Eigen::Matrix3d R_WC = camera.X_WC.q.normalized().toRotationMatrix();
    rays.R_WO = R_WC * RotationCameraToCv();
    rays.R_GW = (R_WC * RotationCameraToGl()).transpose();
    rays.origin = camera.X_WC.p;
    rays.near = camera.near;
    rays.far = camera.far;

    const int w = camera.width, h = camera.height;
    const size_t n = static_cast<size_t>(w) * h;
    out->width = w;
    out->height = h;
    out->color.assign(4 * n, 0.0f);
    out->albedo.assign(4 * n, 0.0f);
    out->normal.assign(4 * n, 0.0f);
    out->position.assign(4 * n, 0.0f);
    out->segmentation.assign(2 * n, 0u);

    // rows handed out to threads one at a time; each pixel's result depends only on its index
    std::atomic<int> next_row{0};
    auto worker = [&]() {
      for (int row = next_row++; row < h; row = next_row++) {
        for (int col = 0; col < w; ++col) RenderPixel(rays, col, row, w, out);
      }
    };
    int num_threads = std::max(1, std::min(threads_, h));
    std::vector<std::thread> pool;
    for (int i = 1; i < num_threads; ++i) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
  }

 private:
  // --- scene upkeep ---

  void ReleaseScene() {
    for (RTCGeometry g : instance_geometries_) {
      if (g) rtcReleaseGeometry(g);
    }
    instance_geometries_.clear();
    for (auto& [mesh, s] : mesh_scenes_) rtcReleaseScene(s);
    mesh_scenes_.clear();
    if (scene_) rtcReleaseScene(scene_);
    scene_ = nullptr;
    meshes_.clear();
    transforms_.clear();
  }

  void CheckEmbree(const char* what) {
    RTCError e = rtcGetDeviceError(device_);
    if (e != RTC_ERROR_NONE) {
      throw Error(std::string("path tracer: Embree failed to ") + what + ": " + embree_error_);
    }
  }

  static void ToEmbreeTransform(const Eigen::Matrix4d& X, float xfm[12]) {
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 3; ++r) xfm[3 * c + r] = static_cast<float>(X(r, c));
    }
  }

  /// A BVH over one mesh in its own frame, shared by all instances of that mesh.
  RTCScene MeshScene(const MeshData& mesh) {
    auto it = mesh_scenes_.find(&mesh);
    if (it != mesh_scenes_.end()) return it->second;
    const int nv = static_cast<int>(mesh.vertices.size());
    for (const auto& f : mesh.faces) {
      if (f.minCoeff() < 0 || f.maxCoeff() >= nv) {
        throw Error("path tracer: mesh '" + (mesh.name.empty() ? mesh.source : mesh.name) +
                    "' has a face with a vertex index outside [0, " + std::to_string(nv) + ")");
      }
    }
    RTCScene s = rtcNewScene(device_);
    // medium (Embree's default) builds 3x faster than high, and traced no slower (bench/README.md)
    rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices.size()));
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      for (int k = 0; k < 3; ++k) v[3 * i + k] = mesh.vertices[i][k];
    }
    auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), mesh.faces.size()));
    for (size_t i = 0; i < mesh.faces.size(); ++i) {
      for (int k = 0; k < 3; ++k) idx[3 * i + k] = static_cast<unsigned>(mesh.faces[i][k]);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(s, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(s);
    CheckEmbree("build a mesh BVH");
    mesh_scenes_[&mesh] = s;
    return s;
  }

  /// Rebuilds everything when meshes changed, else moves the instances that moved.
  void SyncGeometry(const RenderWorld& world) {
    const auto& instances = world.instances;
    bool rebuild = scene_ == nullptr || world.geometry_version != geometry_version_ ||
                   instances.size() != meshes_.size();
    for (size_t i = 0; !rebuild && i < instances.size(); ++i) {
      rebuild = instances[i].mesh != meshes_[i];
    }
    float xfm[12];
    if (rebuild) {
      ReleaseScene();
      scene_ = rtcNewScene(device_);
      for (size_t i = 0; i < instances.size(); ++i) {
        const RenderInstance& ri = instances[i];
        meshes_.push_back(ri.mesh);
        transforms_.push_back(ri.X_WV);
        if (!ri.mesh || ri.mesh->faces.empty()) {
          instance_geometries_.push_back(nullptr);
          continue;
        }
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, MeshScene(*ri.mesh));
        rtcSetGeometryTimeStepCount(g, 1);
        ToEmbreeTransform(ri.X_WV, xfm);
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene_, g, static_cast<unsigned>(i));
        instance_geometries_.push_back(g);
      }
      rtcCommitScene(scene_);
      CheckEmbree("build the scene BVH");
      geometry_version_ = world.geometry_version;
      return;
    }
    bool moved = false;
    for (size_t i = 0; i < instances.size(); ++i) {
      if (instances[i].X_WV == transforms_[i]) continue;
      transforms_[i] = instances[i].X_WV;
      if (!instance_geometries_[i]) continue;
      ToEmbreeTransform(instances[i].X_WV, xfm);
      rtcSetGeometryTransform(instance_geometries_[i], 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
      rtcCommitGeometry(instance_geometries_[i]);
      moved = true;
    }
    if (moved) {
      rtcCommitScene(scene_);
      CheckEmbree("update the scene BVH");
    }
  }

  /// Materials, textures and transforms as seen by shading.
  void SyncShading(const RenderWorld& world) {
    shading_.assign(world.instances.size(), InstanceShading());
    for (size_t i = 0; i < world.instances.size(); ++i) {
      const RenderInstance& ri = world.instances[i];
      InstanceShading& s = shading_[i];
      s.mesh = ri.mesh.get();
      s.R = ri.X_WV.topLeftCorner<3, 3>().cast<float>();
      s.t = ri.X_WV.topRightCorner<3, 1>().cast<float>();
      s.N = ri.X_WV.topLeftCorner<3, 3>().inverse().transpose().cast<float>();
      s.base = ri.material.base_color.head<3>().cwiseMax(0.0f).cwiseMin(1.0f);
      s.roughness = ri.material.roughness;
      s.metallic = ri.material.metallic;
      s.visual_id = ri.visual_id;
      s.entity_id = ri.entity_id;
      if (s.mesh) {
        s.has_normals = s.mesh->normals.size() == s.mesh->vertices.size();
        s.has_uvs = s.mesh->uvs.size() == s.mesh->vertices.size();
      }
      const std::string& path = ri.material.diffuse_texture;
      if (!path.empty()) {
        auto it = textures_.find(path);
        if (it == textures_.end()) it = textures_.emplace(path, internal::LoadTexture(path)).first;
        s.texture = it->second.get();
      }
    }
  }

  // --- ray casting ---

  /// Closest hit along o + t d, t in [t0, t1]; false when nothing is hit.
  bool Intersect(const Vec3& o, const Vec3& d, float t0, float t1, RTCRayHit* rh) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay& r = rh->ray;
    r.org_x = o.x();
    r.org_y = o.y();
    r.org_z = o.z();
    r.dir_x = d.x();
    r.dir_y = d.y();
    r.dir_z = d.z();
    r.tnear = t0;
    r.tfar = t1;
    r.time = 0.0f;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, rh);
    return rh->hit.geomID != RTC_INVALID_GEOMETRY_ID;
  }

  /// True when something lies along o + t d for t in (0, t1).
  bool Occluded(const Vec3& o, const Vec3& d, float t1) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay r;
    r.org_x = o.x();
    r.org_y = o.y();
    r.org_z = o.z();
    r.dir_x = d.x();
    r.dir_y = d.y();
    r.dir_z = d.z();
    r.tnear = 0.0f;
    r.tfar = t1;
    r.time = 0.0f;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(scene_, &context, &r);
    return r.tfar < 0.0f;
  }

  /// The surface at a hit of a ray with direction d.
  SurfacePoint Surface(const RTCRayHit& rh, const Vec3& d) const {
    const InstanceShading& inst = shading_[rh.hit.instID[0]];
    const MeshData& mesh = *inst.mesh;
    const Eigen::Vector3i& f = mesh.faces[rh.hit.primID];
    const float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
    const Vec3& a = mesh.vertices[f[0]];
    const Vec3& b = mesh.vertices[f[1]];
    const Vec3& c = mesh.vertices[f[2]];
    SurfacePoint sp;
    sp.inst = &inst;
    // barycentric position is more precise than o + t d far from the ray origin
    sp.p = inst.R * (w * a + u * b + v * c) + inst.t;
    sp.ng = (inst.N * (b - a).cross(c - a)).normalized();
    sp.ns = sp.ng;
    if (inst.has_normals) {
      Vec3 n = inst.N * (w * mesh.normals[f[0]] + u * mesh.normals[f[1]] + v * mesh.normals[f[2]]);
      float len = n.norm();
      if (len > 1e-12f && std::isfinite(len)) sp.ns = n / len;
    }
    // two-sided surfaces: normals towards the incoming ray
    if (sp.ng.dot(d) > 0.0f) {
      sp.ng = -sp.ng;
      sp.ns = -sp.ns;
    }
    if (sp.ns.dot(d) >= 0.0f) sp.ns = sp.ng;
    sp.base = inst.base;
    if (inst.texture) {
      Eigen::Vector2f uv = Eigen::Vector2f::Zero();
      if (inst.has_uvs) uv = w * mesh.uvs[f[0]] + u * mesh.uvs[f[1]] + v * mesh.uvs[f[2]];
      sp.base = sp.base.cwiseProduct(inst.texture->Sample(uv.x(), uv.y()).head<3>());
    }
    sp.roughness = inst.roughness;
    sp.metallic = inst.metallic;
    return sp;
  }

  /// A ray origin just off the surface, on the side of `dir`.
  static Vec3 Offset(const SurfacePoint& sp, const Vec3& dir) {
    float eps = 1e-4f * (1.0f + sp.p.cwiseAbs().maxCoeff());
    return sp.p + (sp.ng.dot(dir) >= 0.0f ? eps : -eps) * sp.ng;
  }

  // --- light transport ---

  /// Direct light from every light at sp, soft shadows included.
  Vec3 DirectLight(const SurfacePoint& sp, const Bsdf& bsdf, const Vec3& wo, Pcg32& rng) const {
    Vec3 sum = Vec3::Zero();
    for (const LightDesc& light : *lights_) {
      float u1 = rng.Uniform(), u2 = rng.Uniform();
      Vec3 wi;
      float dist = kInf;
      Vec3 e = light.color;
      if (light.type == LightType::kDirectional) {
        Vec3 to_light = -light.direction.cast<float>().normalized();
        static const float cos_max = std::cos(kDirectionalAngularRadius);
        wi = internal::FromLocal(to_light, internal::SampleConeLocal(u1, u2, cos_max));
      } else {
        Vec3 centre = light.position.cast<float>();
        Vec3 to_centre = centre - sp.p;
        float d2 = to_centre.squaredNorm();
        if (!(d2 > 0.0f)) continue;
        Vec3 axis = to_centre / std::sqrt(d2);
        if (light.type == LightType::kSpot) {
          float cos_angle = (-axis).dot(light.direction.cast<float>().normalized());
          e *= Smoothstep(std::cos(static_cast<float>(light.outer_angle)),
                          std::cos(static_cast<float>(light.inner_angle)), cos_angle);
        }
        e /= std::max(d2, kPointLightRadius * kPointLightRadius);
        // a point on the light's disk facing sp
        Vec3 t, b;
        internal::OrthoBasis(axis, &t, &b);
        Eigen::Vector2f q = internal::SampleDisk(u1, u2) * kPointLightRadius;
        Vec3 to_sample = to_centre + q.x() * t + q.y() * b;
        dist = to_sample.norm();
        wi = to_sample / dist;
      }
      if (e.maxCoeff() <= 0.0f || sp.ng.dot(wi) <= 0.0f) continue;
      Vec3 f = bsdf.EvalCos(sp.ns, wo, wi);
      if (f.maxCoeff() <= 0.0f) continue;
      Vec3 o = Offset(sp, wi);
      float t1 = std::isinf(dist) ? kInf : dist * (1.0f - 1e-4f);
      if (Occluded(o, wi, t1)) continue;
      sum += f.cwiseProduct(e);
    }
    return sum;
  }

  /// Radiance towards -d from the first hit sp of a camera ray with direction d.
  Vec3 PathRadiance(SurfacePoint sp, Vec3 d, Pcg32& rng) const {
    Vec3 radiance = Vec3::Zero();
    Vec3 throughput = Vec3::Ones();
    for (int bounce = 0;; ++bounce) {
      Vec3 wo = -d;
      Bsdf bsdf(sp.base, sp.roughness, sp.metallic, std::max(sp.ns.dot(wo), 0.0f));
      radiance += throughput.cwiseProduct(DirectLight(sp, bsdf, wo, rng));

      // bounce: one sample from the mixture of both lobes
      float ul = rng.Uniform(), u1 = rng.Uniform(), u2 = rng.Uniform();
      Vec3 wi;
      if (!bsdf.Sample(sp.ns, wo, ul, u1, u2, &wi) || sp.ng.dot(wi) <= 0.0f) break;
      float pdf = bsdf.Pdf(sp.ns, wo, wi);
      if (!(pdf > 0.0f)) break;
      throughput = throughput.cwiseProduct(bsdf.EvalCos(sp.ns, wo, wi) / pdf);
      if (bounce >= 2) {
        float q = std::min(throughput.maxCoeff(), 0.95f);
        if (rng.Uniform() >= q) break;
        throughput /= q;
      }
      if (!(throughput.maxCoeff() > 0.0f) || !throughput.allFinite()) break;

      // the environment where the bounce ray escapes
      RTCRayHit rh;
      if (!Intersect(Offset(sp, wi), wi, 0.0f, kInf, &rh)) {
        radiance += throughput.cwiseProduct(ambient_);
        break;
      }
      if (bounce + 1 >= options_.max_depth) break;
      sp = Surface(rh, wi);
      d = wi;
    }
    return radiance;
  }

  void RenderPixel(const CameraRays& rays, int col, int row, int width, Picture* out) const {
    const size_t pixel = static_cast<size_t>(row) * width + col;
    const int spp = options_.samples_per_pixel;
    Vec3 sum = Vec3::Zero();
    const Vec3 origin = rays.origin.cast<float>();
    for (int s = 0; s < spp; ++s) {
      Pcg32 rng(options_.seed, pixel, static_cast<uint64_t>(s));
      // sample 0 through the pixel centre, the others jittered within the pixel
      double dx = 0.0, dy = 0.0;
      if (s > 0) {
        dx = rng.Uniform() - 0.5;
        dy = rng.Uniform() - 0.5;
      }
      Eigen::Vector3d d_O = (rays.K_inv * Eigen::Vector3d(col + dx, row + dy, 1.0)).normalized();
      Vec3 d = (rays.R_WO * d_O).cast<float>();
      // clip at the near and far planes (z in the camera frame), as a rasterizer does
      float t0 = static_cast<float>(rays.near / d_O.z());
      float t1 = static_cast<float>(rays.far / d_O.z());
      RTCRayHit rh;
      bool hit = d_O.z() > 0.0 && Intersect(origin, d, t0, t1, &rh);
      if (!hit) continue;
      SurfacePoint sp = Surface(rh, d);
      if (s == 0) {
        // G-buffer from the centre ray
        Eigen::Vector3d p_O = static_cast<double>(rh.ray.tfar) * d_O;
        float* pos = &out->position[4 * pixel];
        pos[0] = static_cast<float>(p_O.x());
        pos[1] = static_cast<float>(-p_O.y());
        pos[2] = static_cast<float>(-p_O.z());
        pos[3] = static_cast<float>(p_O.z());
        Eigen::Vector3f n_G = (rays.R_GW * sp.ns.cast<double>()).normalized().cast<float>();
        float* nrm = &out->normal[4 * pixel];
        nrm[0] = n_G.x();
        nrm[1] = n_G.y();
        nrm[2] = n_G.z();
        float* alb = &out->albedo[4 * pixel];
        alb[0] = sp.base.x();
        alb[1] = sp.base.y();
        alb[2] = sp.base.z();
        alb[3] = 1.0f;
        out->segmentation[2 * pixel] = sp.inst->visual_id;
        out->segmentation[2 * pixel + 1] = sp.inst->entity_id;
        out->color[4 * pixel + 3] = 1.0f;
      }
      Vec3 l = PathRadiance(sp, d, rng);
      if (l.allFinite()) sum += l;
    }
    // the mean of the samples, clamped to the documented [0, 1] as the rasterizer does
    sum /= static_cast<float>(spp);
    for (int k = 0; k < 3; ++k) out->color[4 * pixel + k] = std::clamp(sum[k], 0.0f, 1.0f);
  }

  PathTracerOptions options_;
  int threads_ = 1;
  RTCDevice device_ = nullptr;
  std::string embree_error_;

  // geometry, valid for geometry_version_
  RTCScene scene_ = nullptr;
  uint64_t geometry_version_ = 0;
  std::unordered_map<const MeshData*, RTCScene> mesh_scenes_;
  std::vector<std::shared_ptr<const MeshData>> meshes_;  ///< per instance, kept alive
  std::vector<Eigen::Matrix4d> transforms_;              ///< per instance, as built
  std::vector<RTCGeometry> instance_geometries_;         ///< per instance, null if empty

  // per render
  std::vector<InstanceShading> shading_;
  std::map<std::string, std::shared_ptr<const PtTexture>> textures_;
  const std::vector<LightDesc>* lights_ = nullptr;
  Vec3 ambient_ = Vec3::Zero();
};

}  // namespace

std::unique_ptr<RenderBackend> MakePathTracerBackend(const PathTracerOptions& options) {
  if (options.samples_per_pixel < 1) {
    throw Error("PathTracerOptions.samples_per_pixel must be >= 1, got " +
                std::to_string(options.samples_per_pixel));
  }
  if (options.max_depth < 1) {
    throw Error("PathTracerOptions.max_depth must be >= 1, got " +
                std::to_string(options.max_depth));
  }
  if (options.threads < 0) {
    throw Error("PathTracerOptions.threads must be >= 0 (0: all cores), got " +
                std::to_string(options.threads));
  }
  return std::make_unique<PathTracerBackend>(options);
}

}  // namespace partsim
