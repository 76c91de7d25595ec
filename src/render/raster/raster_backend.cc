// The rasterizer: OpenGL 4.5 core on a headless EGL context (a GPU when there is one, else Mesa's
// llvmpipe). Deferred shading in three steps per picture:
//   1. shadow maps (shadows.cc): depth of every instance seen from each directional or spot light
//      with shadow = true (up to kMaxShadows of them), layers of one depth array texture;
//   2. geometry pass (passes.cc): every instance into the G-buffer (albedo, normal, position +
//      depth, segmentation ids, material parameters), one draw call per instance;
//   3. lighting pass (passes.cc): a full-screen triangle reads the G-buffer and shades every pixel
//      (Oren-Nayar diffuse + GGX specular, ambient, directional, point and spot lights, PCF
//      shadows) into the colour target.
// Then the read-back (readback.cc) copies each target asked for into the Picture. Pictures that
// ask only for Color and Position (with the built-in shaders) take the forward pass instead of
// steps 2 and 3, and Position is rebuilt from the depth buffer on the CPU. The programs
// (program.cc) come from shaders/*.glsl, embedded at build time, or from RasterOptions; meshes and
// textures (resources.cc) stay on the GPU across pictures.
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "partsim/core/error.h"
#include "partsim/render/backend.h"
#include "render/gl_util.h"
#include "render/raster/passes.h"
#include "render/raster/program.h"
#include "render/raster/readback.h"
#include "render/raster/resources.h"
#include "render/raster/shadows.h"

namespace partsim {
namespace {

using internal::raster::LightUniforms;

class RasterBackend final : public RenderBackend {
 public:
  explicit RasterBackend(const RasterOptions& options)
      : options_(options),
        programs_(options),
        shadows_(options.shadow_map_size, options.reuse_shadow_maps),
        passes_(programs_, resources_, shadows_),
        read_back_(options.gbuffer_fragment_shader.empty()) {
    if (options_.shadow_map_size != 0 &&
        (options_.shadow_map_size < 16 || options_.shadow_map_size > 16384)) {
      throw Error("RasterOptions::shadow_map_size must be 0 (automatic) or in [16, 16384], got " +
                  std::to_string(options_.shadow_map_size));
    }
    context_ = std::make_unique<internal::EglContext>();
    internal::CurrentContextScope current(*context_);
    static std::once_flag logged;
    std::call_once(logged, [&] {
      std::fprintf(stderr, "partsim: rasterizer on %s\n", context_->Renderer().c_str());
    });
    try {
      programs_.Build();
    } catch (...) {
      DeleteGlObjects();
      throw;
    }
    passes_.Create();
    shadows_.Create();
    resources_.Create();
  }

  ~RasterBackend() override {
    try {
      internal::CurrentContextScope current(*context_);
      DeleteGlObjects();
    } catch (...) {
      // the context cannot be made current here: its objects die with it
    }
  }

  std::string Name() const override { return "rasterizer"; }
  std::string Device() const override { return context_->Renderer(); }
  void BeginBatch() override {
    if (batch_depth_ > 0) {
      CheckBatchThread();
    } else {
      context_->MakeCurrent();
      batch_thread_ = std::this_thread::get_id();
    }
    ++batch_depth_;
  }
  void EndBatch() override {
    if (batch_depth_ == 0) throw Error("rasterizer: EndBatch without a BeginBatch");
    CheckBatchThread();
    if (--batch_depth_ == 0) context_->Release();
  }
  RenderCounters Counters() const override {
    return {pictures_drawn(), shadows_.layers_drawn(), shadows_.layers_reused()};
  }

 protected:
  void DoRender(const RenderWorld& world, const CameraParams& camera, Picture* out,
                unsigned outputs) override {
    WithContext([&] { Draw(world, camera, out, outputs); });
  }

  void DoRenderMany(const RenderWorld& world, const std::vector<CameraParams>& cameras,
                    const std::vector<Picture*>& out, unsigned outputs) override {
    auto draw_all = [&] {
      // the world uploaded once; each picture read into pixel-pack buffers as soon as it is
      // drawn, the copies collected once every picture is drawn
      resources_.Sync(world);
      const Eigen::AlignedBox3d scene_box = resources_.UpdateBounds(world);
      const bool narrow = NarrowIds(world);
      read_back_.BeginQueue();
      for (const CameraParams& camera : cameras) {
        if (DrawTargets(world, camera, scene_box, outputs))
          read_back_.QueueForward(passes_.targets(), camera, outputs);
        else
          read_back_.QueueDeferred(passes_.targets(), outputs, narrow);
      }
      for (size_t i = 0; i < cameras.size(); ++i) read_back_.Collect(i, out[i]);
    };
    WithContext(draw_all);
  }

 private:
  void CheckBatchThread() const {
    if (std::this_thread::get_id() != batch_thread_)
      throw Error(
          "rasterizer: a batch begun on another thread holds the GL context (RenderBatch: "
          "pictures of a batch come from the thread that began it)");
  }

  /// Runs `fn` with the GL context current: kept current since BeginBatch in a batch (made
  /// current again, without a release, in case another backend took this thread's context
  /// meanwhile), else taken for the call and released.
  template <typename Fn>
  void WithContext(const Fn& fn) {
    if (batch_depth_ > 0) {
      CheckBatchThread();
      context_->MakeCurrent();
      fn();
    } else {
      internal::CurrentContextScope current(*context_);
      fn();
    }
  }

  /// Whether every id of the world fits in 16 bits (Segmentation then reads back narrow).
  static bool NarrowIds(const RenderWorld& world) {
    for (const RenderInstance& i : world.instances)
      if (i.visual_id > 0xffff || i.entity_id > 0xffff) return false;
    return true;
  }

  void Draw(const RenderWorld& world, const CameraParams& camera, Picture* out, unsigned outputs) {
    resources_.Sync(world);
    const Eigen::AlignedBox3d scene_box = resources_.UpdateBounds(world);
    if (DrawTargets(world, camera, scene_box, outputs))
      read_back_.Forward(passes_.targets(), camera, outputs, out);
    else
      read_back_.Deferred(passes_.targets(), outputs, NarrowIds(world), out);
  }

  /// Draws a picture of the synced world into the targets; true when it took the forward path.
  bool DrawTargets(const RenderWorld& world, const CameraParams& camera,
                   const Eigen::AlignedBox3d& scene_box, unsigned outputs) {
    passes_.targets().Ensure(camera.width, camera.height);

    // shadows and lights only matter for colour
    int num_shadows = 0;
    if (outputs & kColor) {
      num_shadows = shadows_.Render(world, camera, scene_box, resources_, programs_.shadow(),
                                    programs_.shadow_mvp());
    } else {
      shadows_.Clear(world.lights.size());
    }
    LightUniforms lights = passes_.PrepareLights(world, camera);
    if (UsesForwardPath(outputs)) {
      passes_.Forward(world, camera, lights, num_shadows);
      return true;
    }
    passes_.Gbuffer(world, camera);
    if (outputs & kColor) passes_.Lighting(world, lights, num_shadows);
    return false;
  }

  // the forward path: only Color and Position asked for, and the built-in shaders
  bool UsesForwardPath(unsigned outputs) const {
    return (outputs & ~unsigned{kColor | kPosition}) == 0 &&
           options_.gbuffer_vertex_shader.empty() && options_.gbuffer_fragment_shader.empty() &&
           options_.lighting_fragment_shader.empty();
  }

  void DeleteGlObjects() {
    read_back_.Delete();
    resources_.Delete();
    passes_.Delete();
    shadows_.Delete();
    programs_.Delete();
  }

  RasterOptions options_;
  std::unique_ptr<internal::EglContext> context_;
  int batch_depth_ = 0;           ///< BeginBatch calls not yet ended
  std::thread::id batch_thread_;  ///< the thread that began the batch
  internal::raster::Programs programs_;
  internal::raster::Resources resources_;
  internal::raster::ShadowMaps shadows_;
  internal::raster::Passes passes_;
  internal::raster::ReadBack read_back_;
};

}  // namespace

std::unique_ptr<RenderBackend> MakeRasterBackend(const RasterOptions& options) {
  return std::make_unique<RasterBackend>(options);
}

}  // namespace partsim
