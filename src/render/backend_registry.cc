// Backends by name, and the scene's default backend. This is the one place that names the
// rasterizer and path tracer factories for the scene, so code that only ever uses the null
// backend (SetRenderBackend(scene, "null") before any picture) never starts EGL or Embree.
#include <memory>
#include <string>

#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "partsim/render/scene_render.h"
#include "render/render_state.h"

namespace partsim {

void SetRenderBackend(Scene& scene, const std::string& name) {
  std::unique_ptr<RenderBackend> backend;
  if (name == "rasterizer") {
    backend = MakeRasterBackend();
  } else if (name == "pathtracer") {
    backend = MakePathTracerBackend();
  } else if (name == "null") {
    backend = MakeNullBackend();
  } else {
    throw Error("set_render_backend: unknown backend '" + name +
                "' (expected rasterizer, pathtracer or null)");
  }
  internal::RenderOf(scene).render_backend = std::move(backend);
}

RenderBackend& GetRenderBackend(Scene& scene) {
  // the rasterizer is the default, created on first use
  internal::RenderState& s = internal::RenderOf(scene);
  if (!s.render_backend) s.render_backend = MakeRasterBackend();
  return *s.render_backend;
}

}  // namespace partsim
