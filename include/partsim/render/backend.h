// The renderer's backend interface. A backend turns a RenderWorld (what is visible, where, under
// which lights) and a camera into a Picture. The rasterizer (EGL/OpenGL), the path tracer (Embree)
// and a null backend implement it behind RenderBackend::Render, which checks the arguments for all
// of them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "partsim/physics/description.h"

namespace partsim {

/// Light kinds. Directions are in the world frame; spot angles in radians (half angles).
enum class LightType { kDirectional, kPoint, kSpot };

/// A light of the scene.
struct LightDesc {
  LightType type = LightType::kDirectional;
  Eigen::Vector3f color = Eigen::Vector3f::Ones();     ///< linear RGB radiance scale (W-ish units)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< point and spot (m)
  Eigen::Vector3d direction = Eigen::Vector3d(0, 0, -1);  ///< directional and spot
  double inner_angle = 0.3;  ///< spot: full intensity inside this half angle
  double outer_angle = 0.5;  ///< spot: no light outside this half angle
  bool shadow = false;       ///< cast shadows (directional and spot in the rasterizer)
  std::string name;
};

/// One mesh to draw: geometry in its own frame, where it is, what it is made of, and its ids.
struct RenderInstance {
  std::shared_ptr<const MeshData> mesh;  ///< triangles in the visual's frame (scaled)
  RenderMaterial material;
  Eigen::Matrix4d X_WV = Eigen::Matrix4d::Identity();  ///< world from visual
  uint32_t visual_id = 0;                              ///< scene-wide id of the visual shape (>= 1)
  uint32_t entity_id = 0;  ///< scene-wide id of the actor or link (>= 1)
};

/// What a backend renders: the snapshot taken by UpdateRender(scene) (scene_render.h).
struct RenderWorld {
  std::vector<RenderInstance> instances;
  std::vector<LightDesc> lights;
  Eigen::Vector3f ambient = Eigen::Vector3f::Constant(0.1f);  ///< ambient light, linear RGB
  /// Changes when the set of meshes or materials changes (not when only poses change), so that
  /// backends know when to rebuild their buffers or acceleration structures.
  uint64_t geometry_version = 0;
};

/// A camera as the backend sees it.
/// Frames: the camera pose X_WC uses partsim's camera convention (x forward, y left, z up); the
/// OpenGL camera frame G (x right, y up, z backward) is X_WC * R_CG; OpenCV's (x right, y down,
/// z forward) is X_WC * R_CO.
struct CameraParams {
  int width = 0;
  int height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();     ///< OpenCV intrinsics (pixels)
  double near = 0.01;                                  ///< m
  double far = 100.0;                                  ///< m
  Pose X_WC;                                           ///< camera pose, x forward, y left, z up
  Eigen::Matrix4d view = Eigen::Matrix4d::Identity();  ///< world -> OpenGL camera
  Eigen::Matrix4d projection = Eigen::Matrix4d::Identity();  ///< OpenGL camera -> clip
};

/// Outputs of a picture, as bits of a mask (RenderBackend::Render, Camera::TakePicture).
enum PictureOutput : unsigned {
  kColor = 1,
  kAlbedo = 2,
  kNormal = 4,
  kPosition = 8,
  kSegmentation = 16,
  kAllOutputs = 31,
};

/// "Color, Position": the SAPIEN names of the outputs in `outputs` (PictureOutput bits), in the
/// order Color, Albedo, Normal, Position, Segmentation; "none" for an empty mask.
std::string PictureOutputNames(unsigned outputs);

/// The outputs of one picture, row-major, row 0 at the top of the image. Outputs not in
/// `outputs` were not rendered and are empty (size 0).
struct Picture {
  int width = 0;
  int height = 0;
  unsigned outputs = kAllOutputs;  ///< PictureOutput bits of the outputs that hold data
  std::vector<float> color;        ///< h x w x 4, lit RGBA, linear in [0, 1]
  std::vector<float> albedo;       ///< h x w x 4, surface colour without lighting
  std::vector<float> normal;       ///< h x w x 4, unit normal in the OpenGL camera frame, w = 0
  std::vector<float> position;  ///< h x w x 4, xyz in the OpenGL camera frame (m), w = depth (m);
                                ///< all 0 where no surface is seen
  std::vector<uint32_t> segmentation;  ///< h x w x 2: visual id, entity id; 0 = background
};

/// What a backend did since it was made (for benchmarks and tests: work it could skip).
struct RenderCounters {
  uint64_t pictures = 0;              ///< Render calls that drew a picture
  uint64_t shadow_layers_drawn = 0;   ///< shadow maps drawn (one per shadowed light and picture)
  uint64_t shadow_layers_reused = 0;  ///< shadow maps kept from an earlier picture, unchanged
};

/// A rendering backend. Render is not virtual: it checks its arguments once for every backend,
/// then calls the backend's DoRender, which can rely on them.
class RenderBackend {
 public:
  virtual ~RenderBackend() = default;
  /// "rasterizer", "pathtracer" or "null".
  virtual std::string Name() const = 0;
  /// The backend's counters (only `pictures` for backends without shadow maps).
  virtual RenderCounters Counters() const { return {pictures_, 0, 0}; }

  /// A batch of pictures from the calling thread, until the matching EndBatch (batches nest):
  /// the backend keeps what it binds to a thread bound between them (the rasterizer's GL
  /// context stays current, where a picture outside a batch takes it and releases it, so that
  /// any thread can render next). During a batch, pictures from another thread throw
  /// partsim::Error. RenderBatch does both in a scope.
  virtual void BeginBatch() {}
  virtual void EndBatch() {}
  /// A line for logs: which device renders (e.g. the GL_RENDERER string).
  virtual std::string Device() const = 0;
  /// Fills the outputs of `out` named by `outputs` (PictureOutput bits, sized width x height),
  /// leaves the others empty (size 0) and sets out->outputs. Asking for less lets a backend do
  /// less: the rasterizer renders Color and Position alone in one forward pass. Throws
  /// partsim::Error naming the argument when `out` is null, `outputs` names no output or unknown
  /// bits, or `camera` is unusable: width or height outside [1, kMaxPictureSize] pixels, K not
  /// finite or a focal length <= 0, near not finite and > 0, far not finite and > near, X_WC not
  /// finite with a unit quaternion, view or projection not finite; `out` is then untouched. When
  /// the backend throws while rendering, out->outputs is 0 (the picture holds nothing usable).
  void Render(const RenderWorld& world, const CameraParams& camera, Picture* out,
              unsigned outputs = kAllOutputs);
  /// Pictures of one world from several cameras (a camera set), `out[i]` from `cameras[i]`, each
  /// the same as Render would give it. A backend may submit them together: the rasterizer
  /// uploads the world once, draws every camera and reads the pictures back through pixel-pack
  /// buffers, so that drawing the next camera overlaps the copy of the last. Every argument is
  /// checked before anything is drawn (an error names the camera's index) and then the
  /// pictures hold nothing until they are filled.
  void RenderMany(const RenderWorld& world, const std::vector<CameraParams>& cameras,
                  const std::vector<Picture*>& out, unsigned outputs = kAllOutputs);

  /// Largest width or height of a picture (pixels).
  static constexpr int kMaxPictureSize = 16384;

 protected:
  /// The backend's work for Render, on checked arguments: fills the outputs of `out` named by
  /// `outputs` (it may fill others too; Render empties them afterwards).
  virtual void DoRender(const RenderWorld& world, const CameraParams& camera, Picture* out,
                        unsigned outputs) = 0;
  /// The backend's work for RenderMany, on checked arguments; DoRender for each camera unless
  /// a backend does better.
  virtual void DoRenderMany(const RenderWorld& world, const std::vector<CameraParams>& cameras,
                            const std::vector<Picture*>& out, unsigned outputs);
  /// Pictures drawn so far (Render counts them).
  uint64_t pictures_drawn() const { return pictures_; }

 private:
  uint64_t pictures_ = 0;
};

/// BeginBatch and EndBatch of a backend for a scope (see RenderBackend::BeginBatch).
class RenderBatch {
 public:
  explicit RenderBatch(RenderBackend& backend) : backend_(backend) { backend_.BeginBatch(); }
  ~RenderBatch() { backend_.EndBatch(); }
  RenderBatch(const RenderBatch&) = delete;
  RenderBatch& operator=(const RenderBatch&) = delete;

 private:
  RenderBackend& backend_;
};

/// Fills nothing but the background (for tests that need no pixels).
std::unique_ptr<RenderBackend> MakeNullBackend();

/// Rasterizer options.
struct RasterOptions {
  /// GLSL sources replacing the built-in passes; empty keeps the built-in ones. See
  /// shaders/README.md for the inputs and outputs each pass must declare.
  std::string gbuffer_vertex_shader;
  std::string gbuffer_fragment_shader;
  std::string lighting_fragment_shader;
  /// Side of a light's shadow map (texels), in [16, 16384]; 0 (the default) sizes the maps from
  /// each picture: the power of two at or above twice its larger side, in [512, 2048] (512 for
  /// pictures up to 256 pixels a side, 1024 up to 512, 2048 above).
  int shadow_map_size = 0;
  /// Keep a shadow map from one picture to the next while what it holds (the casters' meshes
  /// and poses seen from the light) is the same; false draws every map for every picture (the
  /// pictures are the same either way).
  bool reuse_shadow_maps = true;
};

/// OpenGL 4.5 core through headless EGL. Pictures that ask for no more than Color and Position
/// (with the built-in shaders) are shaded in one forward pass, the same lighting as the deferred
/// G-buffer + lighting passes that every other set of outputs takes; on an NVIDIA GPU when there is
/// one, else Mesa's CPU rasterizer. Throws partsim::Error when no EGL display can be created or a
/// shader fails.
std::unique_ptr<RenderBackend> MakeRasterBackend(const RasterOptions& options = RasterOptions());

/// Path tracer options.
struct PathTracerOptions {
  int samples_per_pixel = 16;  ///< >= 1
  int max_depth = 4;           ///< bounces, >= 1
  uint64_t seed = 0;           ///< the same seed gives the same image
  int threads = 0;             ///< 0: all cores
};

/// Physically based path tracer on Intel Embree 3. It traces every output whatever the mask of
/// Render (they come from the same paths) and then drops those not asked for.
std::unique_ptr<RenderBackend> MakePathTracerBackend(
    const PathTracerOptions& options = PathTracerOptions());

/// A triangle mesh for a primitive visual (box, sphere, capsule, cylinder, plane) in the shape's
/// frame, with outward normals; capsules and cylinders along x; a plane is a square of
/// half-size `half_size.x() x half_size.y()` facing +z.
std::shared_ptr<MeshData> MakePrimitiveMesh(const VisualShape& shape);

namespace internal {
/// Key of a primitive visual for sharing meshes (the renderer's mesh cache, the viewer's mesh
/// table): its type and exact sizes, so that shapes with one key have the same MakePrimitiveMesh.
std::string PrimitiveKey(const VisualShape& shape);
}  // namespace internal

}  // namespace partsim
