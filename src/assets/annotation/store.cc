// The annotation session on disk (DIR/session.json) and its export as a PartNet-Mobility folder.
#include <chrono>
#include <filesystem>
#include <functional>
#include <map>

#include "assets/generator/categories.h"
#include "assets/generator/writer.h"
#include "core/atomic_file.h"
#include "core/file_read.h"
#include "core/json_parse.h"
#include "partsim/assets/annotation.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr char kFormat[] = "partsim annotation session 1";
constexpr char kAnnotator[] = "partsim annotate";  ///< meta.json "annotator" of an export

double Now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

AnnotationStore::AnnotationStore(std::shared_ptr<const AnnotationInput> input,
                                 const std::string& dir)
    : session_(input), dir_(dir) {
  std::error_code ec;
  const fs::path file = fs::path(dir) / "session.json";
  if (!fs::exists(file, ec)) {
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir, ec)) throw Error("annotate: cannot create the folder '" + dir + "'");
    return;
  }
  // a session that cannot be replayed is refused, and its file left as it is
  const std::string where = file.string();
  Json j;
  try {
    j = internal::ParseJsonBounded(internal::ReadWholeFile(where, "session.json"));
  } catch (const Json::exception& e) {
    throw Error(where + ": " + e.what() + " (the file is left as it is)");
  }
  if (!j.is_object() || j.value("format", "") != kFormat || !j.contains("answers") ||
      !j["answers"].is_array())
    throw Error(where + ": not a partsim annotation session (the file is left as it is)");
  if (j.value("digest", "") != input->digest)
    throw Error(where + ": the session is of another input (" + j.value("input", "?") +
                ", digest " + j.value("digest", "?") + "; this input's is " + input->digest +
                "): give its input, or another --out (the file is left as it is)");
  size_t k = 0;
  try {
    for (const Json& a : j["answers"]) {
      session_.Answer(AnnotationAnswerFromJson(internal::DumpJson(a)));
      ++k;
    }
    if (j.contains("reviews") && j["reviews"].is_array())
      for (const Json& r : j["reviews"])
        session_.Review({r.value("link", -1), r.value("accept", false), r.value("comment", "")});
  } catch (const Error& e) {
    throw Error(where + ": answer " + std::to_string(k) + " does not replay: " + e.what() +
                " (the file is left as it is)");
  } catch (const Json::exception& e) {
    throw Error(where + ": a review is malformed: " + e.what() + " (the file is left as it is)");
  }
}

void AnnotationStore::Save() const {
  Json answers = Json::array(), reviews = Json::array();
  for (const AnnotationAnswer& a : session_.Answers())
    answers.push_back(Json::parse(AnnotationAnswerToJson(a)));
  for (const AnnotationReview& r : session_.Reviews())
    reviews.push_back({{"link", r.link}, {"accept", r.accept}, {"comment", r.comment}});
  const Json j = {{"format", kFormat},
                  {"input", session_.Input().folder},
                  {"digest", session_.Input().digest},
                  {"answers", answers},
                  {"reviews", reviews}};
  internal::WriteFileAtomically((fs::path(dir_) / "session.json").string(), j.dump(1) + "\n");
}

void AnnotationStore::Answer(AnnotationAnswer answer) {
  if (answer.time <= 0) answer.time = Now();
  AnnotationSession before = session_;
  session_.Answer(std::move(answer));
  try {
    Save();
  } catch (...) {
    session_ = std::move(before);  // what the file holds
    throw;
  }
}

bool AnnotationStore::Undo() {
  AnnotationSession before = session_;
  if (!session_.Undo()) return false;
  try {
    Save();
  } catch (...) {
    session_ = std::move(before);
    throw;
  }
  return true;
}

void AnnotationStore::Review(const AnnotationReview& review) {
  AnnotationSession before = session_;
  session_.Review(review);
  try {
    Save();
  } catch (...) {
    session_ = std::move(before);
    throw;
  }
}

void ExportAnnotation(const AnnotationSession& session, const std::string& dir) {
  if (!session.Done())
    throw Error("export: question " + std::to_string(session.Question().index) +
                " is not answered yet");
  const AnnotationInput& in = session.Input();
  const std::vector<AnnotationLink>& links = session.Links();
  std::map<int, std::vector<int>> children;  // link id -> indices of its child links
  for (size_t i = 0; i < links.size(); ++i)
    if (links[i].parent >= 0) children[links[i].parent].push_back(static_cast<int>(i));

  GeneratedObject o;
  o.category = in.category;
  o.model_id = in.model_id.empty() ? in.digest : in.model_id;
  o.anno_id = in.anno_id.empty() ? fs::path(in.folder).filename().string() : in.anno_id;
  Json outliers = Json::array();
  std::map<int, int> exported_id;  // annotation link id -> N of link_N
  // pre-order of the forest: a parent before its children, as link numbers need
  std::function<void(int, int)> add = [&](int i, int parent) {
    const AnnotationLink& l = links[i];
    GeneratedLink g;
    g.id = static_cast<int>(o.links.size());
    g.parent = parent;
    g.joint = !l.joint.empty() ? l.joint : l.root == "free" ? "free" : "heavy";
    g.partnet_name = in.nodes[l.units[0]].name;
    // the movable-part vocabulary where the generator's tables know the name ("drawer",
    // "rotation_door", "furniture_body", ...), which tasks look links up by; else the name
    g.name =
        internal::gen::SemanticLabelOf(in.category, g.partnet_name, parent < 0, l.joint, l.rotates);
    if (g.name.empty()) g.name = g.partnet_name;
    g.axis_origin = l.origin;
    g.axis_direction = l.direction;
    g.limit_a = l.lower;
    g.limit_b = l.upper;
    g.no_limit = l.no_limit;
    g.rotates = l.rotates;
    g.no_rotation_limit = l.no_rotation_limit;
    g.rotation_limit = l.rotation_limit;
    for (int leaf : l.leaves) {
      const PartTreeNode& node = in.nodes[leaf];
      GeneratedPart part;
      part.id = node.id;
      part.name = node.name;
      const AnnotationMesh& m = in.meshes[node.mesh];
      for (size_t f = 0; f < m.meshes.size(); ++f) {
        GeneratedPiece piece;
        for (const Eigen::Vector3f& v : m.meshes[f]->vertices)
          piece.vertices.push_back(v.cast<double>());
        for (const Eigen::Vector3i& t : m.meshes[f]->faces)
          piece.triangles.push_back({t[0], t[1], t[2]});
        piece.material = "part";
        piece.color = m.colors[f];
        piece.file = node.objs[f];
        part.pieces.push_back(std::move(piece));
      }
      g.parts.push_back(std::move(part));
    }
    const int id = g.id;
    exported_id[l.id] = id;
    o.links.push_back(std::move(g));
    for (int c : children[l.id]) add(c, id);
  };
  for (size_t i = 0; i < links.size(); ++i) {
    if (links[i].parent >= 0) continue;
    if (links[i].root == "outlier") {
      std::function<void(int)> skip = [&](int k) {
        for (int leaf : links[k].leaves) outliers.push_back(in.nodes[leaf].id);
        for (int c : children[links[k].id]) skip(c);
      };
      skip(static_cast<int>(i));
      continue;
    }
    add(static_cast<int>(i), -1);
  }
  if (o.links.empty()) throw Error("export: every root is an outlier: there is nothing to export");

  double first = 0, last = 0;
  for (const AnnotationAnswer& a : session.Answers()) {
    if (a.time <= 0) continue;
    if (first == 0) first = a.time;
    last = a.time;
  }
  // the reviews of joints exported, by their link's name in the export
  Json reviews = Json::array();
  for (const AnnotationReview& r : session.Reviews()) {
    const auto it = exported_id.find(r.link);
    if (it == exported_id.end()) continue;
    reviews.push_back({{"link", "link_" + std::to_string(it->second)},
                       {"accept", r.accept},
                       {"comment", r.comment}});
  }
  Json meta = {{"model_id", o.model_id},
               {"anno_id", o.anno_id},
               {"user_id", "partsim"},
               {"time_in_sec", std::to_string(static_cast<long long>(last - first + 0.5))},
               {"version", "3"},
               {"model_cat", o.category},
               {"annotator", kAnnotator},
               {"outlier_parts", outliers}};
  if (!reviews.empty()) meta["reviews"] = reviews;
  internal::ObjectFolderOptions options;
  options.meta_json = meta.dump() + "\n";
  options.result_json = in.result_json;
  options.writer = "partsim annotate";
  options.replaceable = [](const std::string& folder) {
    try {
      const Json m = internal::ParseJsonBounded(
          internal::ReadWholeFile((fs::path(folder) / "meta.json").string(), "meta.json"));
      return m.is_object() && m.value("annotator", "") == kAnnotator;
    } catch (const std::exception&) {
      return false;
    }
  };
  internal::WriteObjectFolder(o, dir, options);
}

}  // namespace partsim
