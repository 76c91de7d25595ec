// Internal helpers of the rasterizer: a headless EGL context for OpenGL 4.5 core, shader
// compilation with errors that name the pass, and image loading for textures. The rasterizer
// backend and the renderer benchmark (its bare OpenGL baseline) share them.
#pragma once

#include <EGL/egl.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES
#endif
#include <GL/glcorearb.h>

namespace partsim::internal {

/// An OpenGL 4.5 core context on a headless EGL display, without any surface (render into
/// framebuffer objects). The display is an EGL device: a hardware one (e.g. an NVIDIA GPU) when
/// there is one, else Mesa's software device, else Mesa's surfaceless platform. One context per
/// object; MakeCurrent binds it to the calling thread.
class EglContext {
 public:
  /// Throws partsim::Error when no display or context can be created.
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// Makes the context current on this thread (cheap when it already is).
  void MakeCurrent();
  /// Releases the context from this thread if it is current here.
  void Release();
  /// GL_RENDERER of the context (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
  const std::string& Renderer() const { return renderer_; }

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string renderer_;
};

/// Makes a context current on this thread for a scope and releases it at the end, so that the
/// scene that owns it can render from another thread next time (a context may be current on one
/// thread at a time).
class CurrentContextScope {
 public:
  explicit CurrentContextScope(EglContext& context) : context_(context) { context_.MakeCurrent(); }
  ~CurrentContextScope() { context_.Release(); }
  CurrentContextScope(const CurrentContextScope&) = delete;
  CurrentContextScope& operator=(const CurrentContextScope&) = delete;

 private:
  EglContext& context_;
};

/// Compiles and links a program from vertex and fragment sources (fragment may be empty for a
/// depth-only pass). On failure throws partsim::Error naming `pass` and quoting the GL info log.
GLuint BuildProgram(const std::string& pass, const std::string& vertex_source,
                    const std::string& vertex_origin, const std::string& fragment_source,
                    const std::string& fragment_origin);

/// An 8-bit RGBA image, row 0 at the top.
struct Image8 {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba;  ///< height x width x 4
};

/// Largest side of a texture as loaded: bigger images are scaled down (JPEG while decoding,
/// PNG by averaging after it).
constexpr int kMaxTextureSide = 4096;
/// Largest image partsim decodes at all, in pixels (after JPEG's decode-time scaling): 32 M,
/// 128 MB as RGBA (8192 x 4096).
constexpr long long kMaxDecodedPixels = 32ll << 20;

/// Loads a PNG or JPEG file (by content, not by extension) as RGBA8, at most kMaxTextureSide
/// on a side. Throws partsim::Error naming the file when it is missing, not a regular file,
/// cannot be decoded, or claims more than kMaxDecodedPixels (checked from its header, before
/// anything is allocated for the pixels).
Image8 LoadImageRgba8(const std::string& path);
/// `image` scaled down by the smallest whole factor that brings both sides to at most
/// `max_side` (each pixel the mean of a factor x factor block); unchanged when it fits.
Image8 DownscaleToFit(const Image8& image, int max_side);

}  // namespace partsim::internal
