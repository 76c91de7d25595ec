// Backends by name, and the scene's default backend. This is the one place that names the
// rasterizer and path tracer factories for the scene, so code that only ever uses the null
// backend (SetRenderBackend("null") before any picture) never starts EGL or Embree.
#include <memory>
#include <string>

#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "physics/scene_internal.h"

namespace partsim {

void Scene::SetRenderBackend(const std::string& name) {
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
  impl().render_backend = std::move(backend);
}

RenderBackend& Scene::GetRenderBackend() {
  // the rasterizer is the default, created on first use
  if (!impl().render_backend) impl().render_backend = MakeRasterBackend();
  return *impl().render_backend;
}

}  // namespace partsim
