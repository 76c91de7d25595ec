#include "render/gl_util.h"

#include <EGL/eglext.h>
#include <jpeglib.h>
#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <mutex>

#include "core/file_read.h"
#include "partsim/core/error.h"

namespace partsim::internal {
namespace {

// the EGL display is process-wide: eglTerminate would destroy every context on it, so it is
// initialised once and never terminated
struct DisplayState {
  EGLDisplay display = EGL_NO_DISPLAY;
  std::string error;
};

bool HasExtension(const char* list, const char* name) {
  if (list == nullptr) return false;
  size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

DisplayState OpenDisplay() {
  DisplayState s;
  const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  auto query_devices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto query_device_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(
      eglGetProcAddress("eglQueryDeviceStringEXT"));
  if (get_platform_display == nullptr) {
    s.error = "eglGetPlatformDisplayEXT is not available";
    return s;
  }
  auto try_init = [&](EGLDisplay d) {
    if (d == EGL_NO_DISPLAY) return false;
    EGLint major = 0, minor = 0;
    return eglInitialize(d, &major, &minor) == EGL_TRUE;
  };

  // EGL devices: hardware ones first (no EGL_MESA_device_software), then software ones
  if (query_devices != nullptr && HasExtension(client_ext, "EGL_EXT_platform_device")) {
    EGLint count = 0;
    query_devices(0, nullptr, &count);
    std::vector<EGLDeviceEXT> devices(count);
    if (count > 0 && query_devices(count, devices.data(), &count) == EGL_TRUE) {
      std::vector<EGLDeviceEXT> ordered;
      for (int pass = 0; pass < 2; ++pass) {
        for (EGLDeviceEXT dev : devices) {
          const char* ext =
              query_device_string ? query_device_string(dev, EGL_EXTENSIONS) : nullptr;
          bool software = HasExtension(ext, "EGL_MESA_device_software");
          if (software == (pass == 1)) ordered.push_back(dev);
        }
      }
      for (EGLDeviceEXT dev : ordered) {
        EGLDisplay d = get_platform_display(EGL_PLATFORM_DEVICE_EXT, dev, nullptr);
        if (try_init(d)) {
          s.display = d;
          return s;
        }
      }
    }
  }
  // Mesa's surfaceless platform
  if (HasExtension(client_ext, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay d =
        get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (try_init(d)) {
      s.display = d;
      return s;
    }
  }
  s.error = "no EGL device or surfaceless display could be initialised (EGL error 0x" + [] {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%x", eglGetError());
    return std::string(buf);
  }() + ")";
  return s;
}

const DisplayState& SharedDisplay() {
  static std::once_flag once;
  static DisplayState state;
  std::call_once(once, [] { state = OpenDisplay(); });
  return state;
}

}  // namespace

EglContext::EglContext() {
  const DisplayState& ds = SharedDisplay();
  if (ds.display == EGL_NO_DISPLAY) throw Error("rasterizer: " + ds.error);
  display_ = ds.display;
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    throw Error("rasterizer: the EGL display does not offer desktop OpenGL");
  }
  // no surface is ever created, so any config that supports OpenGL will do (or none at all)
  EGLConfig config = nullptr;
  const char* ext = eglQueryString(display_, EGL_EXTENSIONS);
  if (!HasExtension(ext, "EGL_KHR_no_config_context")) {
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint n = 0;
    eglChooseConfig(display_, config_attribs, &config, 1, &n);
    if (n < 1) throw Error("rasterizer: no EGL config supports OpenGL");
  }
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                    4,
                                    EGL_CONTEXT_MINOR_VERSION,
                                    5,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                    EGL_NONE};
  context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, context_attribs);
  if (context_ == EGL_NO_CONTEXT) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%x", eglGetError());
    throw Error(std::string("rasterizer: cannot create an OpenGL 4.5 core context (EGL error 0x") +
                buf + ")");
  }
  MakeCurrent();
  const char* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  renderer_ = r ? r : "unknown";
}

EglContext::~EglContext() {
  if (context_ != EGL_NO_CONTEXT) {
    Release();
    eglDestroyContext(display_, context_);
  }
}

void EglContext::MakeCurrent() {
  if (eglGetCurrentContext() == context_) return;
  if (eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE) {
    throw Error("rasterizer: eglMakeCurrent failed (is the context current on another thread?)");
  }
}

void EglContext::Release() {
  if (eglGetCurrentContext() == context_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
}

namespace {

std::string ShaderLog(GLuint shader) {
  GLint n = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &n);
  std::string log(n > 0 ? n : 0, '\0');
  if (n > 0) glGetShaderInfoLog(shader, n, nullptr, log.data());
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

GLuint Compile(GLenum type, const std::string& pass, const std::string& stage,
               const std::string& origin, const std::string& source) {
  GLuint shader = glCreateShader(type);
  const char* src = source.c_str();
  glShaderSource(shader, 1, &src, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::string log = ShaderLog(shader);
    glDeleteShader(shader);
    throw Error("rasterizer: the " + stage + " shader of the " + pass + " pass (" + origin +
                ") failed to compile:\n" + log);
  }
  return shader;
}

}  // namespace

GLuint BuildProgram(const std::string& pass, const std::string& vertex_source,
                    const std::string& vertex_origin, const std::string& fragment_source,
                    const std::string& fragment_origin) {
  GLuint vs = Compile(GL_VERTEX_SHADER, pass, "vertex", vertex_origin, vertex_source);
  GLuint fs = 0;
  if (!fragment_source.empty()) {
    try {
      fs = Compile(GL_FRAGMENT_SHADER, pass, "fragment", fragment_origin, fragment_source);
    } catch (...) {
      glDeleteShader(vs);
      throw;
    }
  }
  GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  if (fs) glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  if (fs) glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint n = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &n);
    std::string log(n > 0 ? n : 0, '\0');
    if (n > 0) glGetProgramInfoLog(program, n, nullptr, log.data());
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    glDeleteProgram(program);
    throw Error("rasterizer: the shaders of the " + pass + " pass (" + vertex_origin + ", " +
                fragment_origin + ") failed to link:\n" + log);
  }
  return program;
}

namespace {

Image8 DecodePng(const std::string& path, const std::vector<uint8_t>& bytes) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size())) {
    throw Error("texture " + path + ": cannot decode PNG: " + image.message);
  }
  // the header's size, checked before the pixels are allocated (a 74-byte file can claim 16000^2)
  if (static_cast<long long>(image.width) * image.height > kMaxDecodedPixels) {
    png_image_free(&image);
    throw Error("texture " + path + ": PNG of " + std::to_string(image.width) + "x" +
                std::to_string(image.height) + " pixels is larger than partsim decodes (" +
                std::to_string(kMaxDecodedPixels >> 20) + " M pixels); scale it down");
  }
  image.format = PNG_FORMAT_RGBA;
  Image8 out;
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  out.rgba.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.rgba.data(), 0, nullptr)) {
    std::string msg = image.message;
    png_image_free(&image);
    throw Error("texture " + path + ": cannot decode PNG: " + msg);
  }
  return out;
}

struct JpegErrorManager {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void JpegErrorExit(j_common_ptr cinfo) {
  auto* err = reinterpret_cast<JpegErrorManager*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, err->message);
  std::longjmp(err->jump, 1);
}

Image8 DecodeJpeg(const std::string& path, const std::vector<uint8_t>& bytes) {
  jpeg_decompress_struct cinfo;
  JpegErrorManager err;
  cinfo.err = jpeg_std_error(&err.base);
  err.base.error_exit = JpegErrorExit;
  err.message[0] = '\0';
  // rows decode into a plain buffer so that nothing with a destructor lives across setjmp
  uint8_t* rgb = nullptr;
  int width = 0, height = 0;
  if (setjmp(err.jump)) {
    jpeg_destroy_decompress(&cinfo);
    std::free(rgb);
    throw Error("texture " + path + ": cannot decode JPEG: " + err.message);
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, bytes.data(), static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&cinfo, TRUE);
  cinfo.out_color_space = JCS_RGB;
  // decode big images scaled down (1/2, 1/4 or 1/8, done by the DCT), and refuse what would
  // still be too big before any pixel memory is taken
  const unsigned side = std::max(cinfo.image_width, cinfo.image_height);
  cinfo.scale_num = 1;
  cinfo.scale_denom = 1;
  while (cinfo.scale_denom < 8 && side / cinfo.scale_denom > kMaxTextureSide)
    cinfo.scale_denom *= 2;
  jpeg_calc_output_dimensions(&cinfo);
  if (static_cast<long long>(cinfo.output_width) * cinfo.output_height > kMaxDecodedPixels) {
    const std::string size =
        std::to_string(cinfo.image_width) + "x" + std::to_string(cinfo.image_height);
    jpeg_destroy_decompress(&cinfo);
    throw Error("texture " + path + ": JPEG of " + size +
                " pixels is larger than partsim decodes (" +
                std::to_string(kMaxDecodedPixels >> 20) + " M pixels at 1/8 scale); scale it down");
  }
  jpeg_start_decompress(&cinfo);
  width = static_cast<int>(cinfo.output_width);
  height = static_cast<int>(cinfo.output_height);
  rgb = static_cast<uint8_t*>(std::malloc(static_cast<size_t>(width) * height * 3));
  if (!rgb) {
    jpeg_destroy_decompress(&cinfo);
    throw Error("texture " + path + ": out of memory for " + std::to_string(width) + "x" +
                std::to_string(height) + " pixels");
  }
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = rgb + static_cast<size_t>(cinfo.output_scanline) * width * 3;
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  Image8 out;
  out.width = width;
  out.height = height;
  out.rgba.resize(static_cast<size_t>(width) * height * 4);
  for (size_t i = 0, n = static_cast<size_t>(width) * height; i < n; ++i) {
    out.rgba[4 * i + 0] = rgb[3 * i + 0];
    out.rgba[4 * i + 1] = rgb[3 * i + 1];
    out.rgba[4 * i + 2] = rgb[3 * i + 2];
    out.rgba[4 * i + 3] = 255;
  }
  std::free(rgb);
  return out;
}

}  // namespace

Image8 LoadImageRgba8(const std::string& path) {
  const std::string text = ReadWholeFile(path, "texture", kMaxDataFileBytes);
  const std::vector<uint8_t> bytes(text.begin(), text.end());
  static const uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), kPngSignature, 8) == 0) {
    return DownscaleToFit(DecodePng(path, bytes), kMaxTextureSide);
  }
  if (bytes.size() >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) {
    return DownscaleToFit(DecodeJpeg(path, bytes), kMaxTextureSide);
  }
  throw Error("texture " + path + ": not a PNG or JPEG image");
}

Image8 DownscaleToFit(const Image8& image, int max_side) {
  int f = 1;
  while ((image.width + f - 1) / f > max_side || (image.height + f - 1) / f > max_side) ++f;
  if (f == 1) return image;
  Image8 out;
  out.width = (image.width + f - 1) / f;
  out.height = (image.height + f - 1) / f;
  out.rgba.assign(static_cast<size_t>(out.width) * out.height * 4, 0);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      unsigned sum[4] = {0, 0, 0, 0};
      int n = 0;
      for (int v = y * f; v < std::min(image.height, (y + 1) * f); ++v)
        for (int u = x * f; u < std::min(image.width, (x + 1) * f); ++u, ++n)
          for (int k = 0; k < 4; ++k)
            sum[k] += image.rgba[(static_cast<size_t>(v) * image.width + u) * 4 + k];
      for (int k = 0; k < 4; ++k)
        out.rgba[(static_cast<size_t>(y) * out.width + x) * 4 + k] =
            static_cast<uint8_t>((sum[k] + n / 2) / n);
    }
  return out;
}

}  // namespace partsim::internal
