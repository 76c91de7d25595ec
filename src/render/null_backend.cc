// The null backend: every output is background (zeros). For tests and tools that need cameras,
// ids and matrices but no pixels.
#include <algorithm>
#include <memory>
#include <string>

#include "partsim/render/backend.h"

namespace partsim {
namespace {

class NullBackend : public RenderBackend {
 public:
  std::string Name() const override { return "null"; }
  std::string Device() const override { return "none (null backend: renders nothing)"; }

 protected:
  void DoRender(const RenderWorld& world, const CameraParams& camera, Picture* out,
                unsigned outputs) override {
    size_t n = static_cast<size_t>(camera.width) * static_cast<size_t>(camera.height);
    out->width = camera.width;
    out->height = camera.height;
    // background everywhere
    for (auto* v : {&out->color, &out->albedo, &out->normal, &out->position}) {
      v->resize(4 * n);
      std::fill(v->begin(), v->end(), 0.0f);
    }
    out->segmentation.resize(2 * n);
    std::fill(out->segmentation.begin(), out->segmentation.end(), 0u);
  }
};

}  // namespace

std::unique_ptr<RenderBackend> MakeNullBackend() { return std::make_unique<NullBackend>(); }

}  // namespace partsim
