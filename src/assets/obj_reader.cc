#include "assets/obj_reader.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <string_view>
#include <unordered_map>

#include "core/ascii.h"
#include "core/file_read.h"
#include "partsim/core/error.h"

namespace partsim::internal {
namespace {

namespace fs = std::filesystem;

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

std::string_view Trim(std::string_view s) {
  while (!s.empty() && IsSpace(s.front())) s.remove_prefix(1);
  while (!s.empty() && IsSpace(s.back())) s.remove_suffix(1);
  return s;
}

// The next whitespace-separated token of `s`, removed from it ("" at the end).
std::string_view Token(std::string_view* s) {
  *s = Trim(*s);
  size_t end = 0;
  while (end < s->size() && !IsSpace((*s)[end])) ++end;
  std::string_view t = s->substr(0, end);
  s->remove_prefix(end);
  return t;
}

bool ToFloat(std::string_view t, float* out, bool* out_of_range = nullptr) {
  const char* b = t.data();
  const char* e = b + t.size();
  if (b != e && *b == '+') ++b;
  auto [p, ec] = std::from_chars(b, e, *out);
  if (out_of_range) *out_of_range = ec == std::errc::result_out_of_range && p == e;
  return ec == std::errc() && p == e;
}

bool ToInt(std::string_view t, long long* out) {
  const char* b = t.data();
  const char* e = b + t.size();
  if (b != e && *b == '+') ++b;
  auto [p, ec] = std::from_chars(b, e, *out);
  return ec == std::errc() && p == e;
}

// Logical lines of a text: a line that ends with '\' goes on in the next one.
class Lines {
 public:
  explicit Lines(std::string_view text) : text_(text) {}

  // The next line without its end, and its (first) line number; false at the end.
  bool Next(std::string_view* line, int* number) {
    if (at_ >= text_.size()) return false;
    *number = ++count_;
    std::string_view piece = Physical();
    if (piece.empty() || piece.back() != '\\') {
      *line = piece;
      return true;
    }
    joined_.assign(piece.data(), piece.size() - 1);
    while (at_ < text_.size()) {
      ++count_;
      piece = Physical();
      const bool more = !piece.empty() && piece.back() == '\\';
      joined_.push_back(' ');
      joined_.append(piece.data(), piece.size() - (more ? 1 : 0));
      if (!more) break;
    }
    *line = joined_;
    return true;
  }

 private:
  std::string_view Physical() {
    size_t end = text_.find('\n', at_);
    if (end == std::string_view::npos) end = text_.size();
    std::string_view piece = text_.substr(at_, end - at_);
    at_ = end + 1;
    while (!piece.empty() && IsSpace(piece.back())) piece.remove_suffix(1);
    return piece;
  }

  std::string_view text_;
  size_t at_ = 0;
  int count_ = 0;
  std::string joined_;
};

// Everything before a '#' comment (numeric statements only: names may hold '#').
std::string_view Uncommented(std::string_view s) {
  const size_t hash = s.find('#');
  return hash == std::string_view::npos ? s : s.substr(0, hash);
}

constexpr float kDefaultGrey = 0.6f;

RenderMaterial DefaultMaterial() {
  RenderMaterial m;
  m.base_color = Eigen::Vector4f(kDefaultGrey, kDefaultGrey, kDefaultGrey, 1.0f);
  return m;
}

// The file name that ends a map_* statement, after its options.
std::string_view TextureName(std::string_view rest) {
  // options and how many arguments each takes (-o, -s, -t: one to three numbers)
  static const std::map<std::string_view, int> kArgs = {
      {"-blendu", 1}, {"-blendv", 1},  {"-bm", 1}, {"-boost", 1},  {"-cc", 1},
      {"-clamp", 1},  {"-imfchan", 1}, {"-mm", 2}, {"-texres", 1}, {"-type", 1},
      {"-o", -3},     {"-s", -3},      {"-t", -3}};
  for (;;) {
    std::string_view probe = rest;
    const std::string_view option = Token(&probe);
    auto it = kArgs.find(option);
    if (it == kArgs.end()) break;
    rest = probe;
    if (it->second > 0) {
      for (int k = 0; k < it->second; ++k) Token(&rest);
    } else {
      for (int k = 0; k < -it->second; ++k) {
        std::string_view next = rest;
        float unused = 0.0f;
        if (!ToFloat(Token(&next), &unused)) break;
        rest = next;
      }
    }
  }
  return Trim(rest);
}

// Reads the materials of an MTL library into `materials`, in order; `dir` resolves textures.
void ReadMtl(const std::string& path, const fs::path& dir,
             std::vector<std::pair<std::string, RenderMaterial>>* materials) {
  const std::string text = ReadWholeFile(path, "material library", kMaxTextFileBytes);
  Lines lines(text);
  std::string_view line;
  int number = 0;
  RenderMaterial* current = nullptr;
  auto numbers = [](std::string_view rest, float* out, int most) {
    int n = 0;
    for (std::string_view t = Token(&rest); !t.empty() && n < most; t = Token(&rest)) {
      if (!ToFloat(t, &out[n])) return n;
      ++n;
    }
    return n;
  };
  while (lines.Next(&line, &number)) {
    std::string_view rest = line;
    const std::string key = AsciiLower(Token(&rest));
    if (key == "newmtl") {
      materials->emplace_back(std::string(Trim(rest)), DefaultMaterial());
      current = &materials->back().second;
      continue;
    }
    if (current == nullptr) continue;
    rest = key.rfind("map_", 0) == 0 ? rest : Uncommented(rest);
    float v[3] = {0, 0, 0};
    if (key == "kd") {
      const int n = numbers(rest, v, 3);
      if (n == 1) v[1] = v[2] = v[0];
      if (n == 1 || n == 3) current->base_color.head<3>() = Eigen::Vector3f(v[0], v[1], v[2]);
    } else if (key == "d" || key == "tr") {
      // the last number: "d -halo 0.5" states the opacity after an option
      float value = 0.0f;
      bool found = false;
      for (std::string_view t = Token(&rest); !t.empty(); t = Token(&rest))
        found = ToFloat(t, &value) || found;
      if (found) current->base_color[3] = key == "d" ? value : 1.0f - value;
    } else if (key == "pr") {
      if (numbers(rest, v, 1) == 1) current->roughness = v[0];
    } else if (key == "pm") {
      if (numbers(rest, v, 1) == 1) current->metallic = v[0];
    } else if (key == "map_kd") {
      const std::string_view name = TextureName(rest);
      if (!name.empty() && name[0] != '*') {
        fs::path p{std::string(name)};
        if (p.is_relative()) p = dir / p;
        current->diffuse_texture = p.lexically_normal().string();
      }
    }
  }
}

// Opacity as a render material holds it: only below 1 counts, never under 0.
void SettleOpacity(RenderMaterial* m) {
  const float opacity = m->base_color[3];
  m->base_color[3] = opacity < 1.0f ? std::max(opacity, 0.0f) : 1.0f;
}

struct Corner {
  int v = -1, t = -1, n = -1;  // indices into the file's arrays, -1 for none
};

struct Face {
  int first = 0;  // into the corners
  int count = 0;
  int line = 0;
};

struct Group {
  std::string name;
  bool has_material = false;  // false: the last material the libraries define
  std::string material;
  std::vector<Face> faces;
};

// Triangles of a polygon (indices into `p`): a fan when it is convex, else ears cut off its
// projection on the plane it most faces.
void Triangulate(const std::vector<Eigen::Vector3f>& p, std::vector<Eigen::Vector3i>* out) {
  const int n = static_cast<int>(p.size());
  if (n == 3) {
    out->emplace_back(0, 1, 2);
    return;
  }
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // Newell's
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d a = p[i].cast<double>(), b = p[(i + 1) % n].cast<double>();
    normal += Eigen::Vector3d((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                              (a.x() - b.x()) * (a.y() + b.y()));
  }
  bool convex = true;
  for (int i = 0; i < n && convex; ++i) {
    const Eigen::Vector3d a = p[(i + n - 1) % n].cast<double>(), b = p[i].cast<double>(),
                          c = p[(i + 1) % n].cast<double>();
    convex = (b - a).cross(c - b).dot(normal) >= 0.0;
  }
  if (convex || normal.squaredNorm() == 0.0) {
    for (int i = 1; i + 1 < n; ++i) out->emplace_back(0, i, i + 1);
    return;
  }
  // 2D coordinates, counter-clockwise about the normal
  int drop = 0;
  normal.cwiseAbs().maxCoeff(&drop);
  const int u = (drop + 1) % 3, w = (drop + 2) % 3;
  const double sign = normal[drop] > 0 ? 1.0 : -1.0;
  std::vector<Eigen::Vector2d> q(n);
  for (int i = 0; i < n; ++i) q[i] = Eigen::Vector2d(p[i][u], sign * p[i][w]);
  auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  };
  std::vector<int> left(n);
  for (int i = 0; i < n; ++i) left[i] = i;
  // walk round the polygon cutting ears; the walk goes on from the corner after a cut, so a
  // polygon of n corners costs O(n^2), and a whole round without a cut ends it
  int k = 0, misses = 0;
  while (left.size() > 3 && misses < static_cast<int>(left.size())) {
    const int m = static_cast<int>(left.size());
    k %= m;
    const int a = left[(k + m - 1) % m], b = left[k], c = left[(k + 1) % m];
    bool ear = cross(q[a], q[b], q[c]) > 0.0;  // not a reflex or flat corner
    for (size_t j = 0; ear && j < left.size(); ++j) {
      const int x = left[j];
      if (x == a || x == b || x == c) continue;
      ear = !(cross(q[a], q[b], q[x]) >= 0 && cross(q[b], q[c], q[x]) >= 0 &&
              cross(q[c], q[a], q[x]) >= 0);
    }
    if (!ear) {
      ++k;
      ++misses;
      continue;
    }
    out->emplace_back(a, b, c);
    left.erase(left.begin() + k);
    misses = 0;
  }
  // a self-intersecting rest, if any, as a fan
  for (size_t i = 1; i + 1 < left.size(); ++i) out->emplace_back(left[0], left[i], left[i + 1]);
}

// A position as a hash key (-0 and +0 alike).
struct PositionHash {
  size_t operator()(const Eigen::Vector3f& p) const {
    uint64_t h = 1469598103934665603ull;
    for (int k = 0; k < 3; ++k) {
      float f = p[k];
      if (f == 0.0f) f = 0.0f;
      uint32_t bits;
      std::memcpy(&bits, &f, sizeof bits);
      h = (h ^ bits) * 1099511628211ull;
    }
    return static_cast<size_t>(h);
  }
};

// Corners merged into vertices: a corner is the first vertex at its position whose normal and
// uv are within 1e-5 of its own (assimp's JoinIdenticalVertices rule, which merges the corners
// of coplanar triangles although their computed normals differ in the last bits).
class VertexJoiner {
 public:
  explicit VertexJoiner(FileSubMesh* mesh, bool uvs) : mesh_(mesh), uvs_(uvs) {}

  int Add(const Eigen::Vector3f& p, const Eigen::Vector3f& n, const Eigen::Vector2f& uv) {
    constexpr float kSquaredEpsilon = 1e-5f * 1e-5f;
    std::vector<int>& here = at_[p];
    for (int i : here) {
      if ((mesh_->normals[i] - n).squaredNorm() > kSquaredEpsilon) continue;
      if (uvs_ && (mesh_->uvs[i] - uv).squaredNorm() > kSquaredEpsilon) continue;
      return i;
    }
    const int i = static_cast<int>(mesh_->positions.size());
    mesh_->positions.push_back(p);
    mesh_->normals.push_back(n);
    if (uvs_) mesh_->uvs.push_back(uv);
    here.push_back(i);
    return i;
  }

 private:
  FileSubMesh* mesh_;
  bool uvs_;
  std::unordered_map<Eigen::Vector3f, std::vector<int>, PositionHash> at_;
};

}  // namespace

std::vector<FileSubMesh> ReadObjFile(const std::string& path) {
  return ParseObj(ReadWholeFile(path, "mesh file", kMaxDataFileBytes),
                  fs::absolute(fs::path(path)).parent_path().string(), path);
}

std::vector<FileSubMesh> ParseObj(std::string_view text, const std::string& folder,
                                  const std::string& path) {
  const fs::path dir(folder);
  auto fail = [&path](int line, const std::string& what) {
    throw Error("mesh file '" + path + "', line " + std::to_string(line) + ": " + what);
  };

  std::vector<Eigen::Vector3f> v, vn;
  std::vector<Eigen::Vector2f> vt;
  std::vector<Corner> corners;
  std::vector<Group> groups(1);
  groups[0].name = "defaultobject";
  std::vector<std::pair<std::string, RenderMaterial>> materials;

  Lines lines(text);
  std::string_view line;
  int number = 0;
  while (lines.Next(&line, &number)) {
    std::string_view rest = line;
    const std::string_view key = Token(&rest);
    if (key.empty() || key[0] == '#') continue;
    if (key == "v" || key == "vn" || key == "vt") {
      rest = Uncommented(rest);
      float x[3] = {0, 0, 0};
      const int need = key == "vt" ? 1 : 3;
      int n = 0;
      for (std::string_view t = Token(&rest); !t.empty() && n < 3; t = Token(&rest), ++n) {
        bool huge = false;
        if (!ToFloat(t, &x[n], &huge)) {
          if (huge) fail(number, "'" + std::string(t) + "' is beyond the range of a float");
          if (n >= need) break;  // e.g. a colour after "v x y z" is numbers too; anything else ends
          fail(number, "'" + std::string(key) + "' needs " + std::to_string(need) + " number" +
                           (need > 1 ? "s" : "") + ", got '" + std::string(t) + "'");
        }
      }
      if (n < need)
        fail(number, "'" + std::string(key) + "' needs " + std::to_string(need) + " numbers, got " +
                         std::to_string(n));
      if (key == "v")
        v.emplace_back(x[0], x[1], x[2]);
      else if (key == "vn")
        vn.emplace_back(x[0], x[1], x[2]);
      else
        vt.emplace_back(x[0], x[1]);
    } else if (key == "f") {
      rest = Uncommented(rest);
      Face face;
      face.first = static_cast<int>(corners.size());
      face.line = number;
      for (std::string_view t = Token(&rest); !t.empty(); t = Token(&rest)) {
        Corner c;
        int* slots[3] = {&c.v, &c.t, &c.n};
        const int sizes[3] = {static_cast<int>(v.size()), static_cast<int>(vt.size()),
                              static_cast<int>(vn.size())};
        std::string_view field = t;
        for (int k = 0; k < 3; ++k) {
          const size_t slash = field.find('/');
          const std::string_view part = field.substr(0, slash);
          if (!part.empty() || k == 0) {
            long long index = 0;
            if (!ToInt(part, &index) || index == 0)
              fail(number, "face corner '" + std::string(t) +
                               "': indices are whole numbers from 1 (or negative, counting back)");
            // relative indices count back from the data read so far; positive ones are
            // checked once the whole file is read
            const long long resolved = index > 0 ? index - 1 : sizes[k] + index;
            const char* what = k == 0 ? "vertex" : k == 1 ? "texture coordinate" : "normal";
            if (resolved < 0)
              fail(number, "face corner '" + std::string(t) + "' refers before the first " + what);
            if (resolved > std::numeric_limits<int>::max())  // more than a file can hold
              fail(number, "face refers to " + std::string(what) + " " + std::to_string(index) +
                               " of " + std::to_string(sizes[k]));
            *slots[k] = static_cast<int>(resolved);
          }
          if (slash == std::string_view::npos) break;
          field.remove_prefix(slash + 1);
          if (k == 2) fail(number, "face corner '" + std::string(t) + "' has more than 3 fields");
        }
        corners.push_back(c);
        ++face.count;
      }
      if (face.count >= 3)
        groups.back().faces.push_back(face);
      else
        corners.resize(face.first);  // a point or line: no surface
    } else if (key == "o" || key == "g") {
      const std::string name(Trim(rest));
      Group& current = groups.back();
      if (current.faces.empty()) {
        current.name = name;
      } else if (name != current.name) {
        Group next;
        next.name = name;
        next.has_material = current.has_material;
        next.material = current.material;
        groups.push_back(std::move(next));
      }
    } else if (key == "usemtl") {
      const std::string name(Trim(rest));
      Group& current = groups.back();
      if (current.has_material && current.material == name) continue;
      if (current.faces.empty()) {
        current.has_material = true;
        current.material = name;
      } else {
        Group next;
        next.name = name;
        next.has_material = true;
        next.material = name;
        groups.push_back(std::move(next));
      }
    } else if (key == "mtllib") {
      // one library named by the whole rest (names may hold spaces), else several
      const std::string_view names = Trim(rest);
      std::vector<std::string> files;
      std::error_code unreadable;  // a name too long for the system, say
      if (fs::is_regular_file(dir / std::string(names), unreadable)) {
        files.emplace_back(names);
      } else {
        std::string_view list = names;
        for (std::string_view t = Token(&list); !t.empty(); t = Token(&list)) files.emplace_back(t);
      }
      for (const std::string& f : files) {
        fs::path p(f);
        if (p.is_relative()) p = dir / p;
        try {
          ReadMtl(p.string(), dir, &materials);
        } catch (const Error&) {
          // a library that cannot be read leaves its materials grey, as other readers do
        }
      }
    }
    // l, p, s, vp, cstype and the rest: no surface partsim draws
  }

  std::unordered_map<std::string, int> by_name;
  for (size_t i = 0; i < materials.size(); ++i) {
    SettleOpacity(&materials[i].second);
    by_name.emplace(materials[i].first, static_cast<int>(i));  // the first of a name counts
  }

  std::vector<FileSubMesh> out;
  std::vector<Eigen::Vector3f> polygon;
  std::vector<Eigen::Vector3i> triangles;
  for (const Group& g : groups) {
    if (g.faces.empty()) continue;
    FileSubMesh mesh;
    mesh.name = g.name;
    if (!g.has_material) {
      mesh.material = materials.empty() ? DefaultMaterial() : materials.back().second;
    } else {
      auto it = by_name.find(g.material);
      mesh.material = it == by_name.end() ? DefaultMaterial() : materials[it->second].second;
    }
    bool uvs = false;
    for (const Face& f : g.faces)
      for (int k = 0; k < f.count && !uvs; ++k) uvs = corners[f.first + k].t >= 0;

    VertexJoiner joiner(&mesh, uvs);
    for (const Face& f : g.faces) {
      bool normals = true;
      for (int k = 0; k < f.count; ++k) {
        const Corner& c = corners[f.first + k];
        if (c.v >= static_cast<int>(v.size()))
          fail(f.line, "face refers to vertex " + std::to_string(c.v + 1) + " of " +
                           std::to_string(v.size()));
        if (c.t >= static_cast<int>(vt.size()))
          fail(f.line, "face refers to texture coordinate " + std::to_string(c.t + 1) + " of " +
                           std::to_string(vt.size()));
        if (c.n >= static_cast<int>(vn.size()))
          fail(f.line, "face refers to normal " + std::to_string(c.n + 1) + " of " +
                           std::to_string(vn.size()));
        normals = normals && c.n >= 0;
      }
      polygon.clear();
      for (int k = 0; k < f.count; ++k) polygon.push_back(v[corners[f.first + k].v]);
      triangles.clear();
      Triangulate(polygon, &triangles);
      for (const Eigen::Vector3i& t : triangles) {
        Eigen::Vector3f flat = Eigen::Vector3f::Zero();
        if (!normals) {
          flat = (polygon[t[1]] - polygon[t[0]]).cross(polygon[t[2]] - polygon[t[0]]);
          const float len =
              std::sqrt(flat.x() * flat.x() + flat.y() * flat.y() + flat.z() * flat.z());
          if (len > 0.0f) flat *= 1.0f / len;
        }
        Eigen::Vector3i tri;
        for (int k = 0; k < 3; ++k) {
          const Corner& c = corners[f.first + t[k]];
          const Eigen::Vector3f& n = normals ? vn[c.n] : flat;
          const Eigen::Vector2f uv = c.t >= 0 ? vt[c.t] : Eigen::Vector2f::Zero();
          tri[k] = joiner.Add(v[c.v], n, uv);
        }
        mesh.triangles.push_back(tri);
      }
    }
    out.push_back(std::move(mesh));
  }
  return out;
}

}  // namespace partsim::internal
