// RenderBackend::Render: the argument checks every backend shares, then the backend's DoRender.
#include "partsim/render/backend.h"

#include <cmath>
#include <string>

#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "render/picture_internal.h"

namespace partsim {

namespace {

[[noreturn]] void Fail(const RenderBackend& backend, const std::string& message) {
  throw Error("render backend '" + backend.Name() + "': " + message);
}

// throws naming the backend and the argument when `camera` cannot be rendered
void CheckCamera(const RenderBackend& backend, const CameraParams& camera) {
  const int max = RenderBackend::kMaxPictureSize;
  if (camera.width < 1 || camera.width > max)
    Fail(backend, "camera.width must be in [1, " + std::to_string(max) + "] pixels, got " +
                      std::to_string(camera.width));
  if (camera.height < 1 || camera.height > max)
    Fail(backend, "camera.height must be in [1, " + std::to_string(max) + "] pixels, got " +
                      std::to_string(camera.height));
  if (!camera.K.allFinite() || !(camera.K(0, 0) > 0) || !(camera.K(1, 1) > 0))
    Fail(backend, "camera.K must be finite with focal lengths > 0, got fx = " +
                      FormatNumber(camera.K(0, 0)) + ", fy = " + FormatNumber(camera.K(1, 1)));
  if (!std::isfinite(camera.near) || !(camera.near > 0))
    Fail(backend, "camera.near must be finite and > 0 (m), got " + FormatNumber(camera.near));
  if (!std::isfinite(camera.far) || !(camera.far > camera.near))
    Fail(backend, "camera.far must be finite and > near (" + FormatNumber(camera.near) +
                      " m), got " + FormatNumber(camera.far));
  if (!camera.X_WC.IsValid())
    Fail(backend, "camera.X_WC must hold finite numbers and a unit quaternion, got " +
                      camera.X_WC.ToString());
  if (!camera.view.allFinite() || !camera.projection.allFinite())
    Fail(backend, "camera.view and camera.projection must be finite");
}

void CheckOutputs(const RenderBackend& backend, unsigned outputs) {
  if (outputs == 0 || (outputs & ~unsigned{kAllOutputs}) != 0)
    Fail(backend,
         "outputs must name at least one of Color, Albedo, Normal, Position, "
         "Segmentation (PictureOutput bits 1 to 31), got " +
             std::to_string(outputs));
}

}  // namespace

void RenderBackend::RenderMany(const RenderWorld& world, const std::vector<CameraParams>& cameras,
                               const std::vector<Picture*>& out, unsigned outputs) {
  if (out.size() != cameras.size())
    Fail(*this, std::to_string(cameras.size()) + " cameras but " + std::to_string(out.size()) +
                    " pictures to fill");
  CheckOutputs(*this, outputs);
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (out[i] == nullptr) Fail(*this, "out[" + std::to_string(i) + "] (a picture) is null");
    try {
      CheckCamera(*this, cameras[i]);
    } catch (const Error& e) {
      throw Error(std::string(e.what()) + " (camera " + std::to_string(i) + " of " +
                  std::to_string(cameras.size()) + ")");
    }
  }
  // every argument checked: now the pictures hold nothing until DoRenderMany has filled them
  for (Picture* p : out) p->outputs = 0;
  DoRenderMany(world, cameras, out, outputs);
  pictures_ += cameras.size();
  for (Picture* p : out) internal::KeepOutputs(outputs, p);
}

void RenderBackend::DoRenderMany(const RenderWorld& world, const std::vector<CameraParams>& cameras,
                                 const std::vector<Picture*>& out, unsigned outputs) {
  for (size_t i = 0; i < cameras.size(); ++i) DoRender(world, cameras[i], out[i], outputs);
}

void RenderBackend::Render(const RenderWorld& world, const CameraParams& camera, Picture* out,
                           unsigned outputs) {
  if (out == nullptr) Fail(*this, "out (the picture to fill) is null");
  CheckOutputs(*this, outputs);
  CheckCamera(*this, camera);
  // the picture holds nothing until DoRender has filled it
  out->outputs = 0;
  DoRender(world, camera, out, outputs);
  ++pictures_;
  // outputs not asked for are dropped whatever the backend filled
  internal::KeepOutputs(outputs, out);
}

}  // namespace partsim
