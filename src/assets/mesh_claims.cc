#include "assets/mesh_claims.h"

#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string_view>
#include <vector>

#include "core/ascii.h"
#include "core/file_read.h"
#include "core/json_parse.h"
#include "partsim/core/check.h"
#include "partsim/core/error.h"

namespace partsim::internal {
namespace {

namespace fs = std::filesystem;

// Longest PLY header read looking for "end_header".
constexpr size_t kMaxPlyHeaderBytes = 1 << 20;

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

[[noreturn]] void Refuse(const std::string& path, const std::string& what) {
  throw Error("mesh file '" + path + "': " + what);
}

// The first `n` bytes of a file (fewer when it is shorter).
std::string Head(const std::string& path, size_t n) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("mesh file '" + path + "': cannot open the file");
  std::string out(n, '\0');
  in.read(out.data(), static_cast<std::streamsize>(n));
  out.resize(static_cast<size_t>(in.gcount()));
  return out;
}

// A whole number (no sign) of `s`; nullopt when `s` is not one, UINT64_MAX when it overflows.
std::optional<uint64_t> Count(std::string_view s) {
  uint64_t v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec == std::errc::result_out_of_range) return UINT64_MAX;
  if (ec != std::errc() || p != s.data() + s.size()) return std::nullopt;
  return v;
}

uint32_t Le32(const std::string& b, size_t at) {
  uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(b[at + k]);
  return v;
}

// ---- PLY ----

// Bytes of a PLY scalar type in a binary file; 0 for a name that is none.
int PlyTypeBytes(std::string_view t) {
  static const std::map<std::string_view, int> kBytes = {
      {"char", 1},   {"int8", 1},    {"uchar", 1},  {"uint8", 1},  {"short", 2}, {"int16", 2},
      {"ushort", 2}, {"uint16", 2},  {"int", 4},    {"int32", 4},  {"uint", 4},  {"uint32", 4},
      {"float", 4},  {"float32", 4}, {"double", 8}, {"float64", 8}};
  auto it = kBytes.find(t);
  return it == kBytes.end() ? 0 : it->second;
}

// PLY: the header must follow the format's grammar (assimp's reader crashed on headers that did
// not: no end_header, unknown types), and every element needs at least the bytes of its scalar
// properties and of its lists' counts (binary), or 2 bytes per property, a digit and a
// separator (ascii).
void CheckPly(const std::string& path, uint64_t size) {
  const std::string head = Head(path, kMaxPlyHeaderBytes);
  bool ascii = false, format = false;
  struct Element {
    std::string name;
    uint64_t count = 0;
    uint64_t min_bytes = 0;
  };
  std::vector<Element> elements;
  size_t at = 0, end = std::string::npos;
  for (int number = 1; at < head.size() && end == std::string::npos; ++number) {
    size_t nl = head.find('\n', at);
    if (nl == std::string::npos) break;
    std::string_view line(head.data() + at, nl - at);
    at = nl + 1;
    std::vector<std::string_view> words;
    for (size_t i = 0; i < line.size();) {
      while (i < line.size() && IsSpace(line[i])) ++i;
      size_t j = i;
      while (j < line.size() && !IsSpace(line[j])) ++j;
      if (j > i) words.push_back(line.substr(i, j - i));
      i = j;
    }
    auto bad = [&] {
      std::string shown(line.substr(0, 80));
      for (char& c : shown)
        if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
      Refuse(path, "the PLY header's line " + std::to_string(number) + " '" + shown +
                       "' is not a PLY header line");
    };
    if (number == 1) {
      if (words.size() != 1 || words[0] != "ply") bad();
      continue;
    }
    if (words.empty()) bad();
    const std::string_view key = words[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header" && words.size() == 1) {
      end = nl;
    } else if (key == "format" && words.size() == 3 && !format) {
      ascii = words[1] == "ascii";
      if (!ascii && words[1] != "binary_little_endian" && words[1] != "binary_big_endian") bad();
      format = true;
    } else if (key == "element" && words.size() == 3 && format) {
      std::optional<uint64_t> n = Count(words[2]);
      if (!n) bad();
      elements.push_back({std::string(words[1]), *n, 0});
    } else if (key == "property" && !elements.empty() && words.size() == 3 &&
               PlyTypeBytes(words[1]) > 0) {
      elements.back().min_bytes += ascii ? 2 : PlyTypeBytes(words[1]);
    } else if (key == "property" && !elements.empty() && words.size() == 5 && words[1] == "list" &&
               PlyTypeBytes(words[2]) > 0 && PlyTypeBytes(words[3]) > 0 && words[2] != "float" &&
               words[2] != "float32" && words[2] != "double" && words[2] != "float64") {
      // a list costs at least its count
      elements.back().min_bytes += ascii ? 2 : PlyTypeBytes(words[2]);
    } else {
      bad();
    }
  }
  if (end == std::string::npos) {
    Refuse(path, head.size() == kMaxPlyHeaderBytes
                     ? "the PLY header has no end_header line within its first 1 MB"
                     : "the PLY header has no end_header line");
  }
  const uint64_t body = size - (end + 1);
  double needed = 0;
  bool first = true;
  for (const Element& e : elements) {
    const double each = static_cast<double>(std::max<uint64_t>(e.min_bytes, 1));
    needed += each * static_cast<double>(e.count);
    // (the last line of an ASCII file may lack its newline)
    if (needed > static_cast<double>(body) + (ascii ? 1 : 0)) {
      Refuse(path, "the PLY header claims " + std::to_string(e.count) + " '" + e.name +
                       "' elements (" + (ascii ? "ascii" : "binary") + ", at least " +
                       FormatNumber(needed) + " bytes" +
                       (first ? "" : " with the elements before it") + "), but the file holds " +
                       std::to_string(body) + " bytes after its header");
    }
    first = false;
  }
}

// ---- STL ----

// A binary STL is 84 bytes of header and triangle count, then 50 bytes a triangle; a file that
// starts with "solid" may be ASCII (some binary files start so too, and then their size tells).
void CheckStl(const std::string& path, uint64_t size) {
  if (size < 84) return;  // the reader refuses it
  const std::string head = Head(path, 84);
  const uint64_t triangles = Le32(head, 80);
  if (84 + 50 * triangles == size) return;
  size_t i = 0;
  while (i < head.size() && IsSpace(head[i])) ++i;
  if (head.compare(i, 5, "solid") == 0) return;  // ASCII: read line by line
  Refuse(path, "the binary STL header claims " + std::to_string(triangles) +
                   " triangles (84 + 50 x " + std::to_string(triangles) + " = " +
                   std::to_string(84 + 50 * triangles) + " bytes), but the file holds " +
                   std::to_string(size) + " bytes");
}

// ---- COLLADA ----

// Every count="N" attribute (<float_array>, <accessor>, <triangles>, ...) counts values written
// as text: at least 2 bytes each, a digit and a separator.
void CheckCollada(const std::string& path, uint64_t size) {
  const std::string text = ReadWholeFile(path, "mesh file", kMaxDataFileBytes);
  for (size_t at = text.find("count"); at != std::string::npos; at = text.find("count", at + 5)) {
    if (at == 0 || !IsSpace(text[at - 1])) continue;  // vcount, a name
    size_t i = at + 5;
    while (i < text.size() && IsSpace(text[i])) ++i;
    if (i >= text.size() || text[i] != '=') continue;
    ++i;
    while (i < text.size() && IsSpace(text[i])) ++i;
    if (i >= text.size() || (text[i] != '"' && text[i] != '\'')) continue;
    const size_t close = text.find(text[i], i + 1);
    if (close == std::string::npos) break;
    std::optional<uint64_t> n = Count(std::string_view(text).substr(i + 1, close - i - 1));
    if (!n || static_cast<double>(*n) * 2 <= static_cast<double>(size)) continue;
    // the element it belongs to, for the message
    const size_t lt = text.rfind('<', at);
    std::string tag = "element";
    if (lt != std::string::npos && at - lt < 4096) {
      size_t e = lt + 1;
      while (e < at && !IsSpace(text[e])) ++e;
      tag = "<" + text.substr(lt + 1, e - lt - 1) + ">";
    }
    Refuse(path, "COLLADA " + tag + " claims count " + std::to_string(*n) + " (at least " +
                     FormatNumber(2.0 * static_cast<double>(*n)) +
                     " bytes of text), but the file holds " + std::to_string(size) + " bytes");
  }
}

// ---- glTF ----

// A non-negative whole number of `j[key]`, or `fallback` when absent or not one.
std::optional<uint64_t> JsonCount(const nlohmann::json& j, const char* key,
                                  std::optional<uint64_t> fallback = std::nullopt) {
  if (!j.is_object()) return fallback;
  auto it = j.find(key);
  if (it == j.end() || !it->is_number_integer() || it->get<int64_t>() < 0) {
    if (it != j.end() && it->is_number_unsigned()) return it->get<uint64_t>();
    return fallback;
  }
  return it->get<uint64_t>();
}

// Buffers, buffer views and accessors of a glTF 2 document: an accessor's elements lie within
// its view, a view within its buffer, and a buffer's byteLength within what its data holds
// (`bin_bytes`: a .glb's BIN chunk, the buffer without a uri).
void CheckGltfJson(const std::string& path, const std::string& text, uint64_t size,
                   uint64_t bin_bytes) {
  nlohmann::json doc;
  try {
    doc = ParseJsonBounded(text);
  } catch (const nlohmann::json::exception&) {
    return;  // the reader says what is wrong
  }
  if (!doc.is_object()) return;
  const fs::path dir = fs::absolute(fs::path(path)).parent_path();
  std::vector<std::optional<uint64_t>> buffers;  // byteLength, when stated
  uint64_t all_data = size;
  if (doc.contains("buffers") && doc["buffers"].is_array()) {
    for (size_t i = 0; i < doc["buffers"].size(); ++i) {
      const nlohmann::json& b = doc["buffers"][i];
      std::optional<uint64_t> claimed = JsonCount(b, "byteLength");
      buffers.push_back(claimed);
      // what the data holds: base64 text decodes to 3 bytes per 4; a file has its size
      uint64_t real = bin_bytes;
      std::string where = "the file's binary chunk";
      if (b.is_object() && b.contains("uri") && b["uri"].is_string()) {
        const std::string uri = b["uri"].get<std::string>();
        if (uri.rfind("data:", 0) == 0) {
          const size_t comma = uri.find(',');
          real = comma == std::string::npos ? 0 : (uri.size() - comma - 1) / 4 * 3 + 2;
          where = "its data uri";
        } else {
          std::error_code ec;
          const fs::path file = dir / uri;
          real = fs::is_regular_file(file, ec) ? fs::file_size(file, ec) : 0;
          if (ec) real = 0;
          where = "'" + file.string() + "'";
        }
      }
      all_data += real;
      if (claimed && *claimed > real)
        Refuse(path, "glTF buffers[" + std::to_string(i) + "] claims byteLength " +
                         std::to_string(*claimed) + ", but " + where + " holds " +
                         std::to_string(real) + " bytes");
    }
  }
  std::vector<std::optional<uint64_t>> views;  // byteLength, when within a stated buffer
  std::vector<uint64_t> strides;
  if (doc.contains("bufferViews") && doc["bufferViews"].is_array()) {
    for (size_t i = 0; i < doc["bufferViews"].size(); ++i) {
      const nlohmann::json& v = doc["bufferViews"][i];
      std::optional<uint64_t> buffer = JsonCount(v, "buffer");
      std::optional<uint64_t> length = JsonCount(v, "byteLength");
      const uint64_t offset = JsonCount(v, "byteOffset", 0).value();
      strides.push_back(JsonCount(v, "byteStride", 0).value());
      views.push_back(length);
      if (!buffer || !length || *buffer >= buffers.size() || !buffers[*buffer]) continue;
      if (static_cast<double>(offset) + static_cast<double>(*length) >
          static_cast<double>(*buffers[*buffer]))
        Refuse(path, "glTF bufferViews[" + std::to_string(i) + "] claims bytes " +
                         std::to_string(offset) + " to " +
                         FormatNumber(double(offset) + double(*length)) + " of buffers[" +
                         std::to_string(*buffer) + "], which holds " +
                         std::to_string(*buffers[*buffer]) + " bytes");
    }
  }
  if (!doc.contains("accessors") || !doc["accessors"].is_array()) return;
  static const std::map<std::string, int> kComponents = {
      {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT2", 4}, {"MAT3", 9}, {"MAT4", 16}};
  for (size_t i = 0; i < doc["accessors"].size(); ++i) {
    const nlohmann::json& a = doc["accessors"][i];
    std::optional<uint64_t> count = JsonCount(a, "count");
    std::optional<uint64_t> type = JsonCount(a, "componentType");
    if (!count || !type || !a.contains("type") || !a["type"].is_string()) continue;
    auto components = kComponents.find(a["type"].get<std::string>());
    if (components == kComponents.end()) continue;
    const uint64_t component = *type == 5120 || *type == 5121   ? 1
                               : *type == 5122 || *type == 5123 ? 2
                                                                : 4;
    const double element = static_cast<double>(component * components->second);
    const std::string claim = "glTF accessors[" + std::to_string(i) + "] claims " +
                              std::to_string(*count) + " " + a["type"].get<std::string>() +
                              " elements";
    std::optional<uint64_t> view = JsonCount(a, "bufferView");
    if (!view) {
      // no data: zeros (or sparse values) the reader allocates in full
      if (element * static_cast<double>(*count) > static_cast<double>(all_data))
        Refuse(path, claim + " without a buffer view (" + FormatNumber(element * double(*count)) +
                         " bytes), more than the file and its buffers hold (" +
                         std::to_string(all_data) + " bytes)");
      continue;
    }
    if (*view >= views.size() || !views[*view]) continue;
    const double stride = strides[*view] > 0 ? static_cast<double>(strides[*view]) : element;
    const double needed = static_cast<double>(JsonCount(a, "byteOffset", 0).value()) +
                          (*count > 0 ? (static_cast<double>(*count) - 1) * stride + element : 0);
    if (needed > static_cast<double>(*views[*view]))
      Refuse(path, claim + " (" + FormatNumber(needed) + " bytes), but bufferViews[" +
                       std::to_string(*view) + "] holds " + std::to_string(*views[*view]) +
                       " bytes");
  }
}

// A .glb: a 12-byte header (magic, version, length), then chunks of a length, a type and data.
void CheckGlb(const std::string& path, uint64_t size) {
  if (size < 20) return;  // the reader refuses it
  const std::string head = Head(path, 20);
  const uint32_t version = Le32(head, 4), length = Le32(head, 8);
  if (length > size)
    Refuse(path, "the GLB header claims " + std::to_string(length) + " bytes, but the file holds " +
                     std::to_string(size) + " bytes");
  if (version == 1) {
    // glTF 1: the JSON content's length follows the header
    const uint64_t content = Le32(head, 12);
    if (20 + content > size)
      Refuse(path, "the GLB header claims " + std::to_string(content) +
                       " bytes of JSON, but the file holds " + std::to_string(size) + " bytes");
    return;
  }
  const uint64_t json_length = Le32(head, 12);
  if (20 + json_length > size)
    Refuse(path, "the GLB JSON chunk claims " + std::to_string(json_length) +
                     " bytes, but the file holds " + std::to_string(size - 20) +
                     " bytes after its header");
  const std::string start = Head(path, 20 + json_length + 8);
  uint64_t bin = 0;
  if (start.size() == 20 + json_length + 8) {
    bin = Le32(start, 20 + json_length);
    const uint64_t left = size - (20 + json_length + 8);
    if (bin > left)
      Refuse(path, "the GLB binary chunk claims " + std::to_string(bin) +
                       " bytes, but the file holds " + std::to_string(left) + " bytes after it");
  }
  if (std::memcmp(head.data() + 16, "JSON", 4) == 0)
    CheckGltfJson(path, start.substr(20, json_length), size, bin);
}

}  // namespace

void CheckMeshClaims(const std::string& path) {
  std::error_code ec;
  const uint64_t size = fs::file_size(path, ec);
  if (ec) return;  // CheckReadableFile has said why
  const std::string ext = AsciiLower(fs::path(path).extension().string());
  const std::string head = Head(path, 4096);
  auto starts = [&](const char* magic) { return head.rfind(magic, 0) == 0; };
  if (ext == ".ply" || starts("ply\n") || starts("ply\r")) {
    CheckPly(path, size);
  } else if (ext == ".stl") {
    CheckStl(path, size);
  } else if (ext == ".glb" || starts("glTF")) {
    CheckGlb(path, size);
  } else if (ext == ".gltf") {
    CheckGltfJson(path, ReadWholeFile(path, "mesh file", kMaxDataFileBytes), size, 0);
  } else if (ext == ".dae" || head.find("<COLLADA") != std::string::npos) {
    CheckCollada(path, size);
  } else {
    // assimp reads some forty other formats, among them archives (.zae, .3mf: a zip bomb
    // unpacks in memory) and formats whose readers size buffers from counts in the file; their
    // claims are not checked here, so they are not read at all
    Refuse(path,
           "partsim reads meshes in OBJ, STL, PLY, COLLADA (.dae), glTF (.gltf, .glb); '" +
               (ext.empty() ? std::string("(no extension)") : ext) +
               "' is not one of them (convert the file, for example with Blender or MeshLab)");
  }
}

}  // namespace partsim::internal
