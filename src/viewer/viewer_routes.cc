// The viewer's HTTP routes, answered on the network thread of its RosbridgeServer (which has
// refused requests from origins not allowed): the web bundle's files, and under /api/ (the
// token checked) scene.json, meshes, textures and the routes extensions add.
#include <filesystem>
#include <system_error>

#include "partsim/core/error.h"
#include "partsim/render/image_io.h"
#include "partsim/render/image_read.h"
#include "viewer/http_util.h"
#include "viewer/viewer_impl.h"

namespace partsim {

namespace {

namespace fs = std::filesystem;

// files a texture request may send (bytes)
constexpr std::uintmax_t kMaxTextureBytes = 64u << 20;
// files of the web bundle the viewer sends (bytes)
constexpr std::uintmax_t kMaxBundleFileBytes = 256u << 20;

const char kNoBundlePage[] = R"(<!doctype html>
<html><head><meta charset="utf-8"><title>partsim viewer</title></head>
<body style="font-family: sans-serif; max-width: 40em; margin: 3em auto">
<h1>partsim viewer</h1>
<p>The viewer's web page is not built. In partsim's source folder run</p>
<pre>bash scripts/build_web.sh</pre>
<p>then reload this page (or point <code>PARTSIM_WEB_DIR</code> at a built bundle).
The scene is served meanwhile: <code>/api/scene.json?token=...</code>.</p>
</body></html>
)";

RosbridgeHttpAnswer Text(int status, const std::string& why) {
  return {status, "text/plain; charset=utf-8", why + "\n"};
}

}  // namespace

double Viewer::Impl::HandleHttp(const RosbridgeHttpRequest& request, RosbridgeHttpRespond respond) {
  ++http_requests;
  if (request.method != "GET") {
    respond(Text(405, "only GET is served"));
    return 30;
  }
  if (request.path.rfind("/api/", 0) == 0) {
    if (!request.token_ok) {
      respond(Text(403, "missing or wrong token: add ?token=T (the token of the viewer's URL)"));
      return 30;
    }
    for (const ApiRoute& r : api_routes)
      if (request.path.rfind(r.prefix, 0) == 0) {
        try {
          r.route(request.path, [respond](ViewerHttpAnswer a) {
            respond({a.status, std::move(a.content_type), std::move(a.body)});
          });
        } catch (const std::exception& e) {
          respond(Text(500, std::string("error: ") + e.what()));
        }
        return r.timeout;
      }
    respond(Api(request.path));
    return 30;
  }
  respond(Bundle(request.path));
  return 30;
}

RosbridgeHttpAnswer Viewer::Impl::Bundle(std::string path) const {
  if (path == "/") path = "/index.html";
  if (!internal::SafeBundlePath(path))
    return Text(
        400, "bad path '" + path + "': only files of the web bundle are served (no '..', no '%')");
  // only regular files that stay inside the bundle folder once links are followed: no link out
  // of it, no folder, no device, no FIFO (never opened)
  const std::string file =
      web_root.empty()
          ? ""
          : internal::RegularFileInside((fs::path(web_root) / path.substr(1)).string(), web_root);
  RosbridgeHttpAnswer a;
  if (file.empty() || !internal::ReadRegularFile(file, kMaxBundleFileBytes, &a.body)) {
    // no bundle (or one without its page): say how to build it
    if (path == "/index.html") return {200, "text/html; charset=utf-8", kNoBundlePage};
    return Text(404, "no file '" + path + "' in the web bundle (" +
                         (web_root.empty() ? "none found" : web_root) + ")");
  }
  a.content_type = internal::ContentTypeOf(path);
  return a;
}

RosbridgeHttpAnswer Viewer::Impl::Api(const std::string& path) const {
  std::shared_ptr<const internal::SceneContent> ct;
  std::shared_ptr<const internal::MotionSnapshot> snap;
  Latest(&ct, &snap);
  if (!ct) return Text(503, "no scene yet");
  if (path == "/api/scene.json") {
    Json j = ct->json;
    if (snap && snap->version == ct->version) {
      j["poses"] = snap->poses;
      j["time"] = snap->time;
      j["step"] = snap->step;
    } else {
      j["poses"] = Json::array();  // none yet: the first /partsim/poses message has them all
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      auto vec = [](const std::optional<Eigen::Vector3d>& v) {
        return v ? Json::array({v->x(), v->y(), v->z()}) : Json(nullptr);
      };
      if (camera_position || camera_rpy || camera_fovy)
        j["initial_camera"] = {{"position", vec(camera_position)},
                               {"rpy", vec(camera_rpy)},
                               {"fovy", camera_fovy ? Json(*camera_fovy) : Json(nullptr)}};
      else
        j["initial_camera"] = nullptr;
    }
    return {200, "application/json", internal::DumpJson(j)};
  }
  const long long mesh = internal::PathIndex(path, "/api/mesh/", ".bin");
  if (mesh >= 0) {
    if (mesh >= static_cast<long long>(ct->meshes.size()))
      return Text(404, "no mesh " + std::to_string(mesh) + " (the scene has " +
                           std::to_string(ct->meshes.size()) + ")");
    return {200, "application/octet-stream", internal::EncodeMesh(*ct->meshes[mesh])};
  }
  const long long tex = internal::PathIndex(path, "/api/texture/", ".png");
  if (tex >= 0 && tex < static_cast<long long>(ct->textures.size())) {
    // only images leave: the file decoded as PNG or JPEG and sent as a PNG of its pixels
    const std::string& file = ct->textures[tex];
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(file, ec);
    std::vector<uint8_t> rgba;
    int width = 0;
    int height = 0;
    try {
      if (ec || size > kMaxTextureBytes) throw Error("cannot be read");
      rgba = ReadImageRgba8(file, &width, &height);
    } catch (const Error&) {
      return Text(404, "texture " + std::to_string(tex) + " cannot be read as a PNG or JPEG image");
    }
    return {200, "image/png", EncodePng(width, height, 4, rgba.data(), kFastPngCompression)};
  }
  std::string extra;
  for (const ApiRoute& r : api_routes) extra += ", " + r.prefix + "...";
  return Text(404, "no API path '" + path +
                       "' (there are /api/scene.json, /api/mesh/K.bin, /api/texture/K.png" + extra +
                       ")");
}

}  // namespace partsim
