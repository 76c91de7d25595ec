#include "partsim/viewer/annotator.h"

#include <chrono>
#include <filesystem>
#include <utility>

#include "core/json_parse.h"
#include "partsim/core/error.h"
#include "viewer/http_util.h"
#include "viewer/scene_content.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

Json Vec(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

ViewerHttpAnswer NotFound(const std::string& why) {
  return {404, "text/plain; charset=utf-8", why + "\n"};
}

}  // namespace

Annotator::Annotator(const AnnotatorOptions& options) : options_(options) {
  if (options.out.empty()) throw Error("annotate: no session folder (--out DIR)");
  input_ = std::make_shared<AnnotationInput>(ReadAnnotationInput(options.input, options.strict));
  store_ = std::make_unique<AnnotationStore>(input_, options.out);
  std::error_code ec;
  exported_ = fs::exists(fs::path(ExportFolder()) / "mobility.urdf", ec);
  // the object, once: its tree and its meshes, as the page asks for them
  const AnnotationInput& in = *input_;
  Json nodes = Json::array(), roots = Json::array();
  for (const PartTreeNode& n : in.nodes) {
    Json children = Json::array();
    for (int c : n.children) children.push_back(in.nodes[c].id);
    nodes.push_back({{"id", n.id},
                     {"name", n.name},
                     {"text", n.text},
                     {"parent", n.parent >= 0 ? in.nodes[n.parent].id : -1},
                     {"children", children},
                     {"mesh", n.mesh >= 0 ? Json(n.mesh) : Json(nullptr)}});
  }
  for (int r : in.roots) roots.push_back(in.nodes[r].id);
  object_json_ =
      internal::DumpJson({{"category", in.category},
                          {"model_id", in.model_id},
                          {"input", in.folder},
                          {"nodes", nodes},
                          {"roots", roots},
                          {"bbox", {{"min", Vec(in.bbox_min)}, {"max", Vec(in.bbox_max)}}}});
  for (const AnnotationMesh& m : in.meshes) {
    MeshData merged;
    for (const auto& part : m.meshes) {
      const int base = static_cast<int>(merged.vertices.size());
      merged.vertices.insert(merged.vertices.end(), part->vertices.begin(), part->vertices.end());
      for (const Eigen::Vector3i& f : part->faces)
        merged.faces.push_back(f + Eigen::Vector3i::Constant(base));
    }
    meshes_.push_back(internal::EncodeMesh(merged));
  }
}

Annotator::~Annotator() = default;

std::string Annotator::ExportFolder() const { return (fs::path(options_.out) / "object").string(); }

std::string Annotator::StateJson() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Json j = Json::parse(store_->Session().StateJson(options_.review));
  j["exported"] = exported_ ? Json(ExportFolder()) : Json(nullptr);
  j["warnings"] = input_->warnings;
  j["review_mode"] = options_.review;
  return internal::DumpJson(j);
}

void Annotator::Post(std::function<void()> task) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    queue_.push_back(std::move(task));
  }
  queue_cv_.notify_one();
}

void Annotator::AttachTo(Viewer* viewer) {
  if (!viewer) throw Error("Annotator::AttachTo: the viewer is null");
  viewer->AddApiRoute("/api/annotate/", [this](const std::string& path, ViewerHttpRespond r) {
    if (path == "/api/annotate/object.json") return r({200, "application/json", object_json_});
    if (path == "/api/annotate/state.json") return r({200, "application/json", StateJson()});
    const long long k = internal::PathIndex(path, "/api/annotate/mesh/", ".bin");
    if (k >= 0 && k < static_cast<long long>(meshes_.size()))
      return r({200, "application/octet-stream", meshes_[k]});
    r(NotFound("no API path '" + path +
               "' (there are /api/annotate/object.json, /api/annotate/state.json and "
               "/api/annotate/mesh/K.bin for K from 0 to " +
               std::to_string(static_cast<long long>(meshes_.size()) - 1) + ")"));
  });
  // each service runs on Run()'s thread and replies with the state after it
  auto serve = [this](std::function<Json(const Json& args)> body) {
    return [this, body](const std::string& args_text, ViewerServiceReply reply) {
      Post([this, body, args_text, reply] {
        Json values;
        try {
          const Json args = internal::ParseJsonBounded(args_text.empty() ? "{}" : args_text);
          values = body(args);
          values["success"] = true;
          if (!values.contains("message")) values["message"] = "";
        } catch (const std::exception& e) {
          values = {{"success", false}, {"message", e.what()}};
        }
        values["state"] = Json::parse(StateJson());
        reply(true, internal::DumpJson(values));
      });
    };
  };
  viewer->AddService("/partsim/annotate/answer", serve([this](const Json& args) {
                       AnnotationAnswer a = AnnotationAnswerFromJson(internal::DumpJson(args));
                       a.time = 0;  // the server's clock, not the page's
                       std::lock_guard<std::mutex> lock(mutex_);
                       store_->Answer(a);
                       return Json::object();
                     }));
  viewer->AddService("/partsim/annotate/undo", serve([this](const Json&) {
                       std::lock_guard<std::mutex> lock(mutex_);
                       if (!store_->Undo()) throw Error("there is no answer to undo");
                       return Json::object();
                     }));
  viewer->AddService("/partsim/annotate/export", serve([this](const Json&) {
                       {
                         std::lock_guard<std::mutex> lock(mutex_);
                         ExportAnnotation(store_->Session(), ExportFolder());
                         exported_ = true;
                       }
                       return Json{{"folder", ExportFolder()}};
                     }));
  viewer->AddService(
      "/partsim/annotate/review", serve([this](const Json& args) {
        if (!options_.review)
          throw Error("not in review mode (start partsim annotate with --review)");
        if (!args.is_object() || !args.contains("link") || !args["link"].is_number_integer() ||
            !args.contains("accept") || !args["accept"].is_boolean())
          throw Error("a review needs an integer \"link\" and \"accept\": true or false");
        if (args.contains("comment") && !args["comment"].is_string())
          throw Error("a review's \"comment\" is text");
        std::lock_guard<std::mutex> lock(mutex_);
        store_->Review({static_cast<int>(args["link"].get<long long>()), args["accept"].get<bool>(),
                        args.value("comment", "")});
        return Json::object();
      }));
}

void Annotator::Run(const std::function<bool()>& keep_going) {
  while (keep_going()) {
    std::function<void()> task;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_cv_.wait_for(lock, std::chrono::milliseconds(100), [this] { return !queue_.empty(); });
      if (queue_.empty()) continue;
      task = std::move(queue_.front());
      queue_.pop_front();
    }
    task();
  }
}

}  // namespace partsim
