// Reading what `partsim annotate` works on: result.json's part hierarchy, meta.json and the
// leaves' meshes, with an error naming the file and node for every way a user's folder can be
// wrong.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <unordered_map>

#include "core/file_read.h"
#include "core/json_parse.h"
#include "partsim/assets/annotation.h"
#include "partsim/assets/mesh.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

/// Largest result.json read (bytes): a tree of kMaxAnnotationNodes nodes is far smaller.
constexpr std::uintmax_t kMaxResultBytes = 64u << 20;

std::string NodeWhere(const Json& node, size_t position) {
  if (node.is_object() && node.contains("id") && node["id"].is_number_integer())
    return "node id " + std::to_string(node["id"].get<long long>());
  return "node " + std::to_string(position) + " (in pre-order)";
}

std::string StringField(const Json& node, const char* key) {
  auto it = node.find(key);
  return it != node.end() && it->is_string() ? it->get<std::string>() : std::string();
}

/// FNV-1a, 64 bits: the same digest on every build, unlike std::hash.
uint64_t Fnv(const std::string& bytes, uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

/// Why `mesh` is not manifold (an edge shared by three or more triangles, vertices welded by
/// position, as a file's duplicated corners are the same point); "" when it is.
std::string NotManifold(const MeshData& mesh, const std::string& where) {
  std::unordered_map<uint64_t, int> welded;
  std::vector<int> id(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f& v = mesh.vertices[i];
    uint32_t bits[3];
    std::memcpy(bits, v.data(), sizeof(bits));
    const uint64_t key = Fnv(std::string(reinterpret_cast<const char*>(bits), sizeof(bits)));
    id[i] = welded.emplace(key, static_cast<int>(welded.size())).first->second;
  }
  std::unordered_map<uint64_t, int> edges;
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      const int a = id[f[k]], b = id[f[(k + 1) % 3]];
      if (a == b) continue;  // a degenerate triangle's collapsed edge
      const uint64_t key = (uint64_t(std::min(a, b)) << 32) | uint32_t(std::max(a, b));
      if (++edges[key] > 2) {
        const Eigen::Vector3f& p = mesh.vertices[f[k]];
        char at[96];
        std::snprintf(at, sizeof(at), "(%.4g, %.4g, %.4g)", p.x(), p.y(), p.z());
        return where + " is not manifold: an edge at " + at +
               " is shared by three or more triangles";
      }
    }
  }
  return "";
}

}  // namespace

int AnnotationInput::Index(int id) const {
  for (size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].id == id) return static_cast<int>(i);
  throw Error("no part node with id " + std::to_string(id));
}

std::vector<int> AnnotationInput::Leaves(int index) const {
  std::vector<int> out, stack{index};
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    if (nodes[n].children.empty()) out.push_back(n);
    for (auto it = nodes[n].children.rbegin(); it != nodes[n].children.rend(); ++it)
      stack.push_back(*it);
  }
  return out;
}

AnnotationInput ReadAnnotationInput(const std::string& folder, bool strict) {
  AnnotationInput in;
  in.folder = folder;
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw Error("annotate: '" + folder + "' is not a folder");
  const std::string result_path = (fs::path(folder) / "result.json").string();
  in.result_json = internal::ReadWholeFile(result_path, "result.json", kMaxResultBytes);
  Json doc;
  try {
    doc = internal::ParseJsonBounded(in.result_json);
  } catch (const Json::exception& e) {
    throw Error(result_path + ": " + e.what());
  }
  if (doc.is_object()) doc = Json::array({doc});  // a single root without its list
  if (!doc.is_array() || doc.empty())
    throw Error(result_path + ": expected a list of root nodes (PartNet's part hierarchy)");

  // pre-order, with an explicit stack: (JSON node, parent index)
  std::vector<std::pair<const Json*, int>> stack;
  for (auto it = doc.rbegin(); it != doc.rend(); ++it) stack.push_back({&*it, -1});
  std::set<int> ids;
  while (!stack.empty()) {
    auto [j, parent] = stack.back();
    stack.pop_back();
    const std::string where = result_path + ": " + NodeWhere(*j, in.nodes.size());
    if (!j->is_object()) throw Error(where + " is not an object");
    if (in.nodes.size() >= static_cast<size_t>(kMaxAnnotationNodes))
      throw Error(result_path + ": more than " + std::to_string(kMaxAnnotationNodes) +
                  " part nodes (partsim annotate reads at most that many)");
    PartTreeNode n;
    if (!j->contains("id") || !(*j)["id"].is_number_integer())
      throw Error(where + " has no integer \"id\"");
    const long long id = (*j)["id"].get<long long>();
    if (id < 0 || id > (1ll << 30)) throw Error(where + ": id out of range");
    n.id = static_cast<int>(id);
    if (!ids.insert(n.id).second) throw Error(where + ": the id appears twice");
    n.name = StringField(*j, "name");
    n.text = StringField(*j, "text");
    if (n.name.empty()) n.name = n.text;
    if (n.text.empty()) n.text = n.name;
    n.parent = parent;
    const int index = static_cast<int>(in.nodes.size());
    if (parent >= 0) in.nodes[parent].children.push_back(index);
    const auto children = j->find("children");
    const bool has_children = children != j->end() && children->is_array() && !children->empty();
    if (children != j->end() && !children->is_array())
      throw Error(where + ": \"children\" is not a list");
    if (!has_children) {
      const auto objs = j->find("objs");
      if (objs == j->end() || !objs->is_array() || objs->empty())
        throw Error(where + " (\"" + n.name + "\") is a leaf without meshes (no \"objs\")");
      for (const Json& o : *objs) {
        if (!o.is_string() || o.get<std::string>().empty() ||
            o.get<std::string>().find_first_of("/\\") != std::string::npos ||
            o.get<std::string>() == "..")
          throw Error(where + ": \"objs\" holds something that is not a mesh name");
        n.objs.push_back(o.get<std::string>());
      }
    }
    in.nodes.push_back(std::move(n));
    if (parent < 0) in.roots.push_back(index);
    if (has_children)
      for (auto it = children->rbegin(); it != children->rend(); ++it)
        stack.push_back({&*it, index});
  }

  // meta.json (optional)
  const fs::path meta_path = fs::path(folder) / "meta.json";
  if (fs::exists(meta_path, ec)) {
    try {
      const Json meta = internal::ParseJsonBounded(
          internal::ReadWholeFile(meta_path.string(), "meta.json", 1u << 20));
      if (meta.is_object()) {
        in.category = StringField(meta, "model_cat");
        in.model_id = StringField(meta, "model_id");
        in.anno_id = StringField(meta, "anno_id");
      }
    } catch (const Json::exception& e) {
      throw Error(meta_path.string() + ": " + e.what());
    }
  }

  // the meshes of every leaf
  uint64_t digest = Fnv(in.result_json);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (size_t i = 0; i < in.nodes.size(); ++i) {
    PartTreeNode& n = in.nodes[i];
    if (!n.children.empty()) continue;
    AnnotationMesh m;
    m.node = static_cast<int>(i);
    for (const std::string& name : n.objs) {
      const std::string what = "part \"" + n.name + "\" (id " + std::to_string(n.id) + ")";
      fs::path file;
      for (const char* sub : {"objs", "textured_objs"}) {
        const fs::path p = fs::path(folder) / sub / (name + ".obj");
        if (fs::exists(p, ec)) {
          file = p;
          break;
        }
      }
      if (file.empty())
        throw Error("annotate: " + what + ": mesh '" + name + ".obj' is in neither " +
                    (fs::path(folder) / "objs").string() + " nor textured_objs/");
      std::vector<LoadedMesh> loaded;
      try {
        loaded = LoadMeshFile(file.string());
      } catch (const Error& e) {
        throw Error("annotate: " + what + ": " + e.what());
      }
      std::shared_ptr<MeshData> merged = MergeMeshes(loaded, file.string());
      const std::string why = NotManifold(*merged, "annotate: " + what + ": mesh " + file.string());
      if (!why.empty() && strict) throw Error(why + " (strict)");
      if (!why.empty()) in.warnings.push_back(why);
      for (const Eigen::Vector3f& v : merged->vertices) {
        lo = lo.cwiseMin(v.cast<double>());
        hi = hi.cwiseMax(v.cast<double>());
      }
      digest = Fnv(name + ":" + std::to_string(fs::file_size(file, ec)), digest);
      m.files.push_back(file.string());
      m.colors.push_back(
          loaded.empty() ? Eigen::Vector3d(Eigen::Vector3d::Constant(0.8))
                         : Eigen::Vector3d(loaded[0].material.base_color.head<3>().cast<double>()));
      m.meshes.push_back(std::move(merged));
    }
    n.mesh = static_cast<int>(in.meshes.size());
    in.meshes.push_back(std::move(m));
  }
  if (in.meshes.empty()) lo = hi = Eigen::Vector3d::Zero();
  in.bbox_min = lo;
  in.bbox_max = hi;
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(digest));
  in.digest = hex;
  return in;
}

}  // namespace partsim
