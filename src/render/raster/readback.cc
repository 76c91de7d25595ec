// The rasterizer's read-back: glReadnPixels of each target asked for, straight into the Picture
// (the flipped projection put the image's top row in framebuffer row 0: no flip).
#include "render/raster/readback.h"

#include <algorithm>
#include <cstdint>
#include <system_error>
#include <thread>

#include "partsim/core/error.h"
#include "render/depth_to_position.h"
#include "render/picture_internal.h"

namespace partsim::internal::raster {

namespace {

// one target of `fbo` into `dst` (`bytes` long)
void Read(const Targets& targets, GLuint fbo, GLenum attachment, GLenum format, GLenum type,
          void* dst, size_t bytes) {
  glNamedFramebufferReadBuffer(fbo, attachment);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
  glReadnPixels(0, 0, targets.width(), targets.height(), format, type, static_cast<GLsizei>(bytes),
                dst);
}

// Position read back as x, y, z triples at the front of `p` (n pixels): spread to x, y, z, w
// with w = -z, the depth the built-in G-buffer shader writes (0 where nothing was drawn), from
// the last pixel back so that no triple is overwritten before it is read.
void SpreadPosition(std::vector<float>* p, size_t n) {
  float* d = p->data();
  for (size_t i = n; i-- > 0;) {
    const float x = d[3 * i], y = d[3 * i + 1], z = d[3 * i + 2];
    d[4 * i] = x;
    d[4 * i + 1] = y;
    d[4 * i + 2] = z;
    d[4 * i + 3] = z < 0 ? -z : 0.0f;
  }
}

}  // namespace

// The depth buffer is read back first and converted on worker threads while this thread reads the
// colour back (on a GPU the conversion would otherwise be most of the frame's time at 512 x 512:
// bench/README.md).
void ReadBack::Forward(const Targets& targets, const CameraParams& camera, unsigned outputs,
                       Picture* out) {
  const int width = targets.width(), height = targets.height();
  size_t n = static_cast<size_t>(width) * height;
  out->width = width;
  out->height = height;
  internal::KeepOutputs(outputs, out);
  if (outputs & kColor) out->color.resize(n * 4);
  if (outputs & kPosition) {
    out->position.resize(n * 4);
    window_depth_.resize(n);
  }
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  const Eigen::Matrix4d P = FlippedProjection(camera);
  const int parts = (outputs & kPosition) ? ConversionParts(n) : 0;
  auto convert = [&](int part) { ConvertRows(P, width, height, part, parts, out); };
  bool started = false;
  if (outputs & kPosition) {
    Read(targets, targets.forward_fbo(), GL_COLOR_ATTACHMENT0, GL_DEPTH_COMPONENT, GL_FLOAT,
         window_depth_.data(), window_depth_.size() * sizeof(float));
    if (parts > 1) {
      try {
        conversion_workers_.Start(parts, convert);
        started = true;
      } catch (const std::system_error&) {
        // no thread to be had: this thread converts after the colour
      }
    }
  }
  if (outputs & kColor) {
    Read(targets, targets.forward_fbo(), GL_COLOR_ATTACHMENT0, GL_RGBA, GL_FLOAT, out->color.data(),
         out->color.size() * sizeof(float));
  }
  if (started) {
    conversion_workers_.Wait();
  } else if (outputs & kPosition) {
    for (int part = 0; part < parts; ++part) convert(part);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  GLenum err = glGetError();
  if (err == GL_OUT_OF_MEMORY) throw Error("rasterizer: out of GPU memory");
}

// the parts the depth of n pixels is converted in: one below 64 x 64 (converted on this
// thread), else one per 16k pixels, from 2 to twice the workers. (Converting 128 x 128 on this
// thread instead made the frame slower on a GPU machine: bench/README.md.)
int ReadBack::ConversionParts(size_t n) const {
  if (n < 64 * 64) return 1;
  return std::clamp(static_cast<int>(n / 16384), 2, 2 * conversion_workers_.size());
}

// threads converting the depth buffer to Position while this one reads the colour back: at most
// 4, one fewer than the cores
int ReadBack::ConversionWorkers() {
  int cores = static_cast<int>(std::thread::hardware_concurrency());
  return std::clamp(cores - 1, 1, 4);
}

void ReadBack::ConvertRows(const Eigen::Matrix4d& P, int width, int height, int part, int parts,
                           Picture* out) const {
  internal::PositionFromDepth(P, width, height, window_depth_.data(), out->position.data(),
                              static_cast<int>(static_cast<int64_t>(height) * part / parts),
                              static_cast<int>(static_cast<int64_t>(height) * (part + 1) / parts));
}

void ReadBack::ConvertDepth(const CameraParams& camera, int width, int height, Picture* out) {
  const Eigen::Matrix4d P = FlippedProjection(camera);
  const int parts = ConversionParts(static_cast<size_t>(width) * height);
  auto convert = [&](int part) { ConvertRows(P, width, height, part, parts, out); };
  if (parts > 1) {
    try {
      conversion_workers_.Start(parts, convert);
      conversion_workers_.Wait();
      return;
    } catch (const std::system_error&) {
      // no thread to be had: this thread converts
    }
  }
  for (int part = 0; part < parts; ++part) convert(part);
}

std::vector<ReadBack::TargetRead> ReadBack::DeferredReads(const Targets& targets, unsigned outputs,
                                                          bool narrow_ids) const {
  const GLuint g = targets.gbuffer_fbo();
  const size_t rgba = 4 * sizeof(float);
  std::vector<TargetRead> reads;
  if (outputs & kColor)
    reads.push_back({kColor, targets.color_fbo(), GL_COLOR_ATTACHMENT0, GL_RGBA, GL_FLOAT, rgba});
  if (outputs & kAlbedo)
    reads.push_back({kAlbedo, g, GL_COLOR_ATTACHMENT0 + kTargetAlbedo, GL_RGBA, GL_FLOAT, rgba});
  if (outputs & kNormal)
    reads.push_back({kNormal, g, GL_COLOR_ATTACHMENT0 + kTargetNormal, GL_RGBA, GL_FLOAT, rgba});
  if (outputs & kPosition)
    reads.push_back({kPosition, g, GL_COLOR_ATTACHMENT0 + kTargetPosition,
                     GLenum(xyz_position_ ? GL_RGB : GL_RGBA), GL_FLOAT,
                     (xyz_position_ ? 3 : 4) * sizeof(float), xyz_position_});
  // ids below 65536 come back exactly as 16-bit numbers: half the bytes
  if (outputs & kSegmentation)
    reads.push_back({kSegmentation, g, GL_COLOR_ATTACHMENT0 + kTargetSegmentation, GL_RG_INTEGER,
                     GLenum(narrow_ids ? GL_UNSIGNED_SHORT : GL_UNSIGNED_INT),
                     2 * (narrow_ids ? sizeof(uint16_t) : sizeof(uint32_t)), narrow_ids});
  return reads;
}

void* ReadBack::Destination(unsigned what, bool narrow, size_t n, Picture* out) {
  switch (what) {
    case kColor:
      out->color.resize(n * 4);
      return out->color.data();
    case kAlbedo:
      out->albedo.resize(n * 4);
      return out->albedo.data();
    case kNormal:
      out->normal.resize(n * 4);
      return out->normal.data();
    case kPosition:
      out->position.resize(n * 4);
      return out->position.data();
    case kSegmentation:
      out->segmentation.resize(n * 2);
      if (!narrow) return out->segmentation.data();
      narrow_ids_.resize(n * 2);
      return narrow_ids_.data();
    default:  // the forward path's depth
      window_depth_.resize(n);
      return window_depth_.data();
  }
}

void ReadBack::Widen(unsigned what, bool narrow, size_t n, Picture* out) {
  if (!narrow) return;
  if (what == kSegmentation)
    std::copy(narrow_ids_.begin(), narrow_ids_.end(), out->segmentation.begin());
  if (what == kPosition) SpreadPosition(&out->position, n);
}

void ReadBack::Deferred(const Targets& targets, unsigned outputs, bool narrow_ids, Picture* out) {
  const size_t n = static_cast<size_t>(targets.width()) * targets.height();
  out->width = targets.width();
  out->height = targets.height();
  internal::KeepOutputs(outputs, out);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  for (const TargetRead& r : DeferredReads(targets, outputs, narrow_ids)) {
    Read(targets, r.fbo, r.attachment, r.format, r.type, Destination(r.what, r.narrow, n, out),
         n * r.bytes_per_pixel);
    Widen(r.what, r.narrow, n, out);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  GLenum err = glGetError();
  if (err == GL_OUT_OF_MEMORY) throw Error("rasterizer: out of GPU memory");
}

void ReadBack::BeginQueue() {
  queued_.clear();
  pool_used_ = 0;
}

void ReadBack::Queue(const Targets& targets, const TargetRead& r, Queued* q) {
  const size_t bytes = static_cast<size_t>(targets.width()) * targets.height() * r.bytes_per_pixel;
  if (pool_used_ == pool_.size()) {
    GLuint b = 0;
    glCreateBuffers(1, &b);
    pool_.push_back({b, 0});
  }
  auto& [buffer, size] = pool_[pool_used_++];
  if (size < bytes) {
    glNamedBufferData(buffer, static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_READ);
    size = bytes;
  }
  glNamedFramebufferReadBuffer(r.fbo, r.attachment);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, r.fbo);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, buffer);
  glReadnPixels(0, 0, targets.width(), targets.height(), r.format, r.type,
                static_cast<GLsizei>(bytes), nullptr);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  q->reads.push_back({r.what, buffer, bytes, r.narrow});
}

void ReadBack::QueueForward(const Targets& targets, const CameraParams& camera, unsigned outputs) {
  Queued q;
  q.forward = true;
  q.camera = camera;
  q.outputs = outputs;
  q.width = targets.width();
  q.height = targets.height();
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  const GLuint f = targets.forward_fbo();
  if (outputs & kPosition)  // the depth buffer, converted to Position by Collect
    Queue(targets, {0, f, GL_COLOR_ATTACHMENT0, GL_DEPTH_COMPONENT, GL_FLOAT, sizeof(float)}, &q);
  if (outputs & kColor)
    Queue(targets, {kColor, f, GL_COLOR_ATTACHMENT0, GL_RGBA, GL_FLOAT, 4 * sizeof(float)}, &q);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  queued_.push_back(std::move(q));
}

void ReadBack::QueueDeferred(const Targets& targets, unsigned outputs, bool narrow_ids) {
  Queued q;
  q.outputs = outputs;
  q.width = targets.width();
  q.height = targets.height();
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  for (const TargetRead& r : DeferredReads(targets, outputs, narrow_ids)) Queue(targets, r, &q);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  queued_.push_back(std::move(q));
}

void ReadBack::Collect(size_t index, Picture* out) {
  const Queued& q = queued_.at(index);
  const size_t n = static_cast<size_t>(q.width) * q.height;
  out->width = q.width;
  out->height = q.height;
  internal::KeepOutputs(q.outputs, out);
  for (const QueuedRead& r : q.reads) {
    glGetNamedBufferSubData(r.buffer, 0, static_cast<GLsizeiptr>(r.bytes),
                            Destination(r.what, r.narrow, n, out));
    Widen(r.what, r.narrow, n, out);
  }
  if (q.forward && (q.outputs & kPosition)) {
    out->position.resize(n * 4);
    ConvertDepth(q.camera, q.width, q.height, out);
  }
  GLenum err = glGetError();
  if (err == GL_OUT_OF_MEMORY) throw Error("rasterizer: out of GPU memory");
}

void ReadBack::Delete() {
  for (auto& [buffer, size] : pool_) glDeleteBuffers(1, &buffer);
  pool_.clear();
  queued_.clear();
  pool_used_ = 0;
}

}  // namespace partsim::internal::raster
