#include "partsim/assets/mesh.h"

#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <tuple>
#include <unordered_map>

#include "assets/mesh_claims.h"
#include "assets/obj_reader.h"
#include "core/ascii.h"
#include "core/file_read.h"
#include "core/number_text.h"
#include "partsim/assets/convex_decomposition.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

// Eigen matrix of an assimp node transform (assimp stores row-major a1..d4).
Eigen::Matrix4d ToEigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d r;
  r << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3,
      m.d4;
  return r;
}

// Whether `path` ends in `ext` (".obj"), in any case.
bool HasExtension(const std::string& path, const char* ext) {
  return internal::AsciiLower(fs::path(path).extension().string()) == ext;
}

// Render material of an assimp material; texture paths made absolute against `dir`.
RenderMaterial ConvertMaterial(const aiMaterial* m, const fs::path& dir) {
  RenderMaterial out;
  if (m == nullptr) return out;
  aiColor4D c;
  // glTF's base colour first, then the classic diffuse colour
  if (m->Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS ||
      m->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS) {
    out.base_color = Eigen::Vector4f(c.r, c.g, c.b, c.a);
  }
  float opacity = 1.0f;
  if (m->Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS && opacity < 1.0f) {
    out.base_color[3] = std::min(out.base_color[3], std::max(opacity, 0.0f));
  }
  float v = 0.0f;
  if (m->Get(AI_MATKEY_ROUGHNESS_FACTOR, v) == AI_SUCCESS) out.roughness = v;
  if (m->Get(AI_MATKEY_METALLIC_FACTOR, v) == AI_SUCCESS) out.metallic = v;

  // diffuse texture; embedded textures ("*0") are not supported
  aiString tex;
  if (m->GetTexture(aiTextureType_BASE_COLOR, 0, &tex) == AI_SUCCESS ||
      m->GetTexture(aiTextureType_DIFFUSE, 0, &tex) == AI_SUCCESS) {
    std::string t = tex.C_Str();
    if (!t.empty() && t[0] != '*') {
      fs::path p(t);
      if (p.is_relative()) p = dir / p;
      out.diffuse_texture = p.lexically_normal().string();
    }
  }
  return out;
}

// A sub-mesh in the file's frame placed by X_FN = `x` and multiplied by `scale`, appended to
// `out` when it has triangles.
void AppendSubMesh(const internal::FileSubMesh& sub, const Eigen::Matrix4d& x,
                   const Eigen::Vector3d& scale, const std::string& path,
                   std::vector<LoadedMesh>* out) {
  if (sub.triangles.empty()) return;
  const Eigen::Matrix3d normal_matrix = x.topLeftCorner<3, 3>().inverse().transpose();
  auto mesh = std::make_shared<MeshData>();
  mesh->source = path;
  mesh->name = sub.name;

  // vertices in the file frame, then scaled
  mesh->vertices.reserve(sub.positions.size());
  for (const Eigen::Vector3f& a : sub.positions) {
    Eigen::Vector3d p = (x * Eigen::Vector4d(a.x(), a.y(), a.z(), 1.0)).head<3>();
    mesh->vertices.push_back(p.cwiseProduct(scale).cast<float>());
  }
  if (!sub.normals.empty()) {
    // normals of a scaled mesh transform with the inverse scale
    const Eigen::Vector3d inv_scale = scale.cwiseInverse();
    mesh->normals.reserve(sub.normals.size());
    for (const Eigen::Vector3f& a : sub.normals) {
      Eigen::Vector3d n = (normal_matrix * a.cast<double>()).cwiseProduct(inv_scale);
      double len = n.norm();
      mesh->normals.push_back((len > 0 ? n / len : n).cast<float>());
    }
  }
  mesh->uvs = sub.uvs;

  // a mirroring scale flips the winding back to counter-clockwise
  const bool flip = (x.topLeftCorner<3, 3>().determinant() * scale.prod()) < 0;
  mesh->faces = sub.triangles;
  if (flip)
    for (Eigen::Vector3i& t : mesh->faces) std::swap(t[1], t[2]);
  out->push_back(LoadedMesh{mesh, sub.material});
}

// Collects the triangles of every mesh instance under `node`, transformed by X_FN.
void CollectNode(const aiScene* scene, const aiNode* node, const Eigen::Matrix4d& parent,
                 const Eigen::Vector3d& scale, const std::string& path, const fs::path& dir,
                 std::vector<LoadedMesh>* out) {
  const Eigen::Matrix4d x = parent * ToEigen(node->mTransformation);
  for (unsigned k = 0; k < node->mNumMeshes; ++k) {
    const aiMesh* am = scene->mMeshes[node->mMeshes[k]];
    internal::FileSubMesh sub;
    sub.name = am->mName.length > 0 ? am->mName.C_Str() : node->mName.C_Str();
    sub.positions.reserve(am->mNumVertices);
    for (unsigned i = 0; i < am->mNumVertices; ++i)
      sub.positions.emplace_back(am->mVertices[i].x, am->mVertices[i].y, am->mVertices[i].z);
    if (am->HasNormals()) {
      sub.normals.reserve(am->mNumVertices);
      for (unsigned i = 0; i < am->mNumVertices; ++i)
        sub.normals.emplace_back(am->mNormals[i].x, am->mNormals[i].y, am->mNormals[i].z);
    }
    if (am->HasTextureCoords(0)) {
      sub.uvs.reserve(am->mNumVertices);
      for (unsigned i = 0; i < am->mNumVertices; ++i)
        sub.uvs.emplace_back(am->mTextureCoords[0][i].x, am->mTextureCoords[0][i].y);
    }
    // triangles only: points and lines left by triangulation are dropped
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      sub.triangles.emplace_back(face.mIndices[0], face.mIndices[1], face.mIndices[2]);
    }
    const aiMaterial* mat =
        am->mMaterialIndex < scene->mNumMaterials ? scene->mMaterials[am->mMaterialIndex] : nullptr;
    sub.material = ConvertMaterial(mat, dir);
    AppendSubMesh(sub, x, scale, path, out);
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) {
    CollectNode(scene, node->mChildren[c], x, scale, path, dir, out);
  }
}

// Whether a triangle surface is (nearly) closed and consistently wound, so that its enclosed
// volume means something: after welding equal positions no directed edge appears twice, and at
// most 2% of them lack their reverse (exported meshes often have a few cracks).
bool ClosedAndConsistent(const MeshData& mesh) {
  std::map<std::tuple<float, float, float>, int> ids;
  std::vector<int> id(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f& v = mesh.vertices[i];
    id[i] = ids.emplace(std::make_tuple(v.x(), v.y(), v.z()), static_cast<int>(ids.size()))
                .first->second;
  }
  const int nv = static_cast<int>(mesh.vertices.size());
  std::unordered_map<uint64_t, int> directed;
  auto key = [](int a, int b) {
    return (static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b);
  };
  for (const Eigen::Vector3i& f : mesh.faces) {
    if (f.minCoeff() < 0 || f.maxCoeff() >= nv) return false;
    const int a = id[f[0]], b = id[f[1]], c = id[f[2]];
    if (a == b || b == c || a == c) continue;  // a degenerate triangle bounds nothing
    for (auto [u, w] : {std::make_pair(a, b), std::make_pair(b, c), std::make_pair(c, a)}) {
      if (++directed[key(u, w)] > 1) return false;
    }
  }
  if (directed.empty()) return false;
  size_t open = 0;
  for (const auto& entry : directed) {
    const int u = static_cast<int>(entry.first >> 32);
    const int w = static_cast<int>(entry.first & 0xFFFFFFFFu);
    open += !directed.count(key(w, u));
  }
  return open <= directed.size() / 50;
}

// ConvexPieceCheck::simplified for a hull of `points` that qhull may have stopped at
// kMaxConvexPieceVertices vertices: how far points lie outside it (at most 20000 of them
// sampled), or "" for a hull that was not cut short.
std::string Simplified(const MeshData& hull, const std::vector<Eigen::Vector3d>& points) {
  if (points.size() <= static_cast<size_t>(kMaxConvexPieceVertices)) return "";
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> offsets;
  for (const Eigen::Vector3i& f : hull.faces) {
    const Eigen::Vector3d a = hull.vertices[f[0]].cast<double>();
    Eigen::Vector3d n =
        (hull.vertices[f[1]].cast<double>() - a).cross(hull.vertices[f[2]].cast<double>() - a);
    if (n.norm() < 1e-300) continue;
    n.normalize();
    normals.push_back(n);
    offsets.push_back(n.dot(a));
  }
  double outside = 0.0;
  const size_t stride = std::max<size_t>(1, points.size() / 20000);
  for (size_t i = 0; i < points.size(); i += stride) {
    double d = 0.0;
    for (size_t k = 0; k < normals.size(); ++k)
      d = std::max(d, normals[k].dot(points[i]) - offsets[k]);
    outside = std::max(outside, d);
  }
  // qhull's merges can leave fewer vertices than the limit, so a cut-short hull also shows as
  // points outside it (beyond rounding)
  if (hull.vertices.size() < static_cast<size_t>(kMaxConvexPieceVertices) && outside < 1e-9)
    return "";
  return "has a convex hull of over " + std::to_string(kMaxConvexPieceVertices) + " vertices (" +
         std::to_string(points.size()) + " distinct points): collides as the hull of " +
         std::to_string(hull.vertices.size()) + " of them, which leaves points up to " +
         internal::Significant(outside, 3) + " m outside" + (stride > 1 ? " (of a sample)" : "");
}

}  // namespace

ConvexPieceCheck CheckConvexPiece(const std::shared_ptr<const MeshData>& mesh) {
  // sizes in metres: below kTiny a piece is dropped; hulls under kMinVolume, or thinner than
  // kFlat of their size, are what MuJoCo's qhull and volume checks refuse (with margin)
  constexpr double kTiny = 1e-4, kMinVolume = 1e-13, kFlat = 1e-6;
  ConvexPieceCheck out;
  out.piece = mesh;
  out.volume_ratio = std::numeric_limits<double>::quiet_NaN();

  // distinct finite points
  std::vector<Eigen::Vector3d> points;
  {
    std::set<std::tuple<float, float, float>> seen;
    for (const Eigen::Vector3f& v : mesh->vertices) {
      if (v.allFinite() && seen.insert(std::make_tuple(v.x(), v.y(), v.z())).second)
        points.push_back(v.cast<double>());
    }
  }
  if (points.empty()) {
    out.piece = nullptr;
    out.repair = "has no vertices: dropped";
    return out;
  }

  // principal directions, and the extents along them, largest first
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) cov += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Matrix3d& axes = eig.eigenvectors();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d x = axes.transpose() * (p - mean);
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const Eigen::Vector3d extent = hi - lo;
  std::array<int, 3> order = {0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int a, int b) { return extent[a] > extent[b]; });
  const double size = extent[order[0]], middle = extent[order[1]], thin = extent[order[2]];
  const std::string counted = std::to_string(points.size()) + " distinct point" +
                              (points.size() == 1 ? "" : "s") + ", " +
                              internal::Significant(size, 3) + " m across";
  if (size < kTiny) {
    out.piece = nullptr;
    out.repair = "is under 0.1 mm across (" + counted + "): dropped";
    return out;
  }

  std::shared_ptr<MeshData> hull;
  try {
    hull = ConvexHull(points, kMaxConvexPieceVertices);
  } catch (const Error&) {
    // flat, line-like or fewer than 4 points: repaired below
  }
  const double hull_volume = hull ? std::abs(MeshVolume(*hull)) : 0.0;
  if (!hull || hull_volume < kMinVolume || thin < kFlat * size) {
    // a thin hull: the points pushed out along the thin direction, and along the middle one
    // too when the piece is a line. Not thinner than needed: MuJoCo 2.2.2's plane-mesh contact
    // can hold a hull 1 mm thick that a fall pushed through the plane (depending on the order
    // of its vertices); from 4 mm on it pushes every such hull back out
    const double t = std::clamp(0.03 * size, 2e-5, 5e-3);
    const bool line = middle < kFlat * size || middle < t;
    std::vector<Eigen::Vector3d> offsets = {Eigen::Vector3d::Zero()};
    for (int k : {order[2], order[1]}) {
      if (k == order[1] && !line) continue;
      std::vector<Eigen::Vector3d> next;
      for (const Eigen::Vector3d& o : offsets) {
        next.push_back(o + 0.5 * t * axes.col(k));
        next.push_back(o - 0.5 * t * axes.col(k));
      }
      offsets = next;
    }
    std::vector<Eigen::Vector3d> pushed;
    pushed.reserve(points.size() * offsets.size());
    for (const Eigen::Vector3d& p : points)
      for (const Eigen::Vector3d& o : offsets) pushed.push_back(p + o);
    std::string what = points.size() < 4 ? "has fewer than 4 distinct points"
                       : line            ? "lies on a line"
                       : !hull           ? "is flat"
                                         : "is nearly flat";
    what += " (" + counted + ", " + internal::Significant(thin, 3) + " m thick)";
    try {
      std::shared_ptr<MeshData> thick = ConvexHull(pushed, kMaxConvexPieceVertices);
      thick->source = mesh->source;
      thick->name = mesh->name;
      out.piece = thick;
      out.thickness = t;
      out.repair = what + ": given a convex hull " + internal::Significant(t, 3) + " m thick";
      out.simplified = Simplified(*thick, pushed);
    } catch (const Error&) {
      out.piece = nullptr;
      out.repair = what + ": dropped";
    }
    return out;
  }

  // many points: MuJoCo gets the hull's vertices, not all of them
  out.simplified = Simplified(*hull, points);
  if (points.size() > static_cast<size_t>(kMaxConvexPieceVertices)) {
    hull->source = mesh->source;
    hull->name = mesh->name;
    out.piece = hull;
  }

  // convexity. A closed surface: the volume it encloses against its hull's. An open one: how
  // much of its area lies deeper inside the hull than 5% of its size (at triangle centroids, a
  // sample of at most 20000 triangles); vertices alone would not do, as every vertex of an
  // extruded shape lies on one of its hull's end faces
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> offsets;
  for (const Eigen::Vector3i& f : hull->faces) {
    const Eigen::Vector3d a = hull->vertices[f[0]].cast<double>();
    Eigen::Vector3d n =
        (hull->vertices[f[1]].cast<double>() - a).cross(hull->vertices[f[2]].cast<double>() - a);
    if (n.norm() < 1e-300) continue;
    n.normalize();
    normals.push_back(n);
    offsets.push_back(n.dot(a));
  }
  const double deep = 0.05 * extent.norm();
  const int nv = static_cast<int>(mesh->vertices.size());
  const size_t stride = std::max<size_t>(1, mesh->faces.size() / 20000);
  double area = 0.0, deep_area = 0.0;
  for (size_t t = 0; t < mesh->faces.size(); t += stride) {
    const Eigen::Vector3i& f = mesh->faces[t];
    if (f.minCoeff() < 0 || f.maxCoeff() >= nv) continue;
    const Eigen::Vector3d a = mesh->vertices[f[0]].cast<double>();
    const Eigen::Vector3d b = mesh->vertices[f[1]].cast<double>();
    const Eigen::Vector3d c = mesh->vertices[f[2]].cast<double>();
    const double triangle = 0.5 * (b - a).cross(c - a).norm();
    if (!std::isfinite(triangle)) continue;
    const Eigen::Vector3d centroid = (a + b + c) / 3.0;
    double depth = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < normals.size(); ++k)
      depth = std::min(depth, offsets[k] - normals[k].dot(centroid));
    area += triangle;
    if (depth > deep) deep_area += triangle;
  }
  out.deep_area_fraction = area > 0 ? deep_area / area : 0.0;
  if (ClosedAndConsistent(*mesh)) {
    out.volume_ratio = std::abs(MeshVolume(*mesh)) / hull_volume;
    out.non_convex = out.volume_ratio < 0.8;
  } else {
    out.non_convex = out.deep_area_fraction > 0.1;
  }
  return out;
}

namespace internal {

std::vector<LoadedMesh> LoadMeshFileWithAssimp(const std::string& path,
                                               const Eigen::Vector3d& scale) {
  Assimp::Importer importer;
  // no points or lines: they are not surfaces
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(path, 0);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw Error("mesh file '" + path + "' could not be read: " + importer.GetErrorString());
  }
  // faces as read, before the post-processing steps, which abort the process on a face without
  // indices (a PLY whose face lists lie, found by tests/fuzz/ply_fuzz.cc) or index past the
  // vertices
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      bool ok = face.mNumIndices > 0 && face.mIndices != nullptr;
      for (unsigned k = 0; ok && k < face.mNumIndices; ++k)
        ok = face.mIndices[k] < am->mNumVertices;
      if (!ok)
        throw Error("mesh file '" + path + "': face " + std::to_string(f) + " of mesh " +
                    std::to_string(m) + " has " +
                    (face.mNumIndices == 0 ? std::string("no vertex indices")
                                           : "a vertex index past its " +
                                                 std::to_string(am->mNumVertices) + " vertices"));
    }
  }
  scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                       aiProcess_GenNormals | aiProcess_SortByPType);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw Error("mesh file '" + path + "' could not be read: " + importer.GetErrorString());
  }

  // assimp scales Collada by its <unit> and turns its up axis into +y; partsim is z-up, so turn
  // +y back into +z: a Z_UP file comes out as written, a Y_UP file stands up
  Eigen::Matrix4d root = Eigen::Matrix4d::Identity();
  if (HasExtension(path, ".dae")) {
    root.topLeftCorner<3, 3>() << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  }

  std::vector<LoadedMesh> out;
  const fs::path dir = fs::absolute(fs::path(path)).parent_path();
  CollectNode(scene, scene->mRootNode, root, scale, path, dir, &out);
  return out;
}

}  // namespace internal

std::vector<LoadedMesh> LoadMeshFile(const std::string& path, const Eigen::Vector3d& scale) {
  internal::CheckReadableFile(path, "mesh file", internal::kMaxDataFileBytes);
  if (!scale.allFinite()) throw Error("mesh file '" + path + "': scale is not finite");

  std::vector<LoadedMesh> out;
  if (HasExtension(path, ".obj")) {
    // partsim's own reader: the sub-meshes assimp gave, without its 48 MB of buffers per file
    for (const internal::FileSubMesh& sub : internal::ReadObjFile(path))
      AppendSubMesh(sub, Eigen::Matrix4d::Identity(), scale, path, &out);
  } else {
    // assimp allocates what a header claims: the claims are held to the file's size first
    internal::CheckMeshClaims(path);
    out = internal::LoadMeshFileWithAssimp(path, scale);
  }
  if (out.empty()) throw Error("mesh file '" + path + "' holds no triangles");
  for (const LoadedMesh& m : out) {
    for (const Eigen::Vector3f& v : m.mesh->vertices) {
      if (!v.allFinite()) throw Error("mesh file '" + path + "' has non-finite vertices");
    }
  }
  return out;
}

std::shared_ptr<MeshData> LoadMergedMesh(const std::string& path, const Eigen::Vector3d& scale) {
  return MergeMeshes(LoadMeshFile(path, scale), path);
}

std::shared_ptr<MeshData> MergeMeshes(const std::vector<LoadedMesh>& parts,
                                      const std::string& path) {
  auto merged = std::make_shared<MeshData>();
  merged->source = path;
  merged->name = fs::path(path).stem().string();

  // normals and uvs survive only when every part has them
  bool normals = true, uvs = true;
  for (const LoadedMesh& p : parts) {
    normals = normals && p.mesh->normals.size() == p.mesh->vertices.size();
    uvs = uvs && p.mesh->uvs.size() == p.mesh->vertices.size();
  }
  for (const LoadedMesh& p : parts) {
    const int base = static_cast<int>(merged->vertices.size());
    const MeshData& m = *p.mesh;
    merged->vertices.insert(merged->vertices.end(), m.vertices.begin(), m.vertices.end());
    if (normals) merged->normals.insert(merged->normals.end(), m.normals.begin(), m.normals.end());
    if (uvs) merged->uvs.insert(merged->uvs.end(), m.uvs.begin(), m.uvs.end());
    for (const Eigen::Vector3i& f : m.faces)
      merged->faces.push_back(f + Eigen::Vector3i::Constant(base));
  }
  return merged;
}

std::vector<std::shared_ptr<MeshData>> SplitConnectedComponents(const MeshData& mesh) {
  const int nv = static_cast<int>(mesh.vertices.size());

  // weld vertices whose positions agree within 1e-7 m: quantise to a grid and map each
  // vertex to the first one in its cell (good enough as cells are tiny)
  constexpr double kWeld = 1e-7;
  std::map<std::tuple<long long, long long, long long>, int> cells;
  std::vector<int> weld(nv);
  for (int i = 0; i < nv; ++i) {
    const Eigen::Vector3f& v = mesh.vertices[i];
    auto key = std::make_tuple(std::llround(v.x() / kWeld), std::llround(v.y() / kWeld),
                               std::llround(v.z() / kWeld));
    weld[i] = cells.emplace(key, i).first->second;
  }

  // union-find over vertices joined by triangles
  std::vector<int> parent(nv);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int a) {
    while (parent[a] != a) {
      parent[a] = parent[parent[a]];
      a = parent[a];
    }
    return a;
  };
  auto valid = [nv](const Eigen::Vector3i& f) { return f.minCoeff() >= 0 && f.maxCoeff() < nv; };
  for (const Eigen::Vector3i& f : mesh.faces) {
    if (!valid(f)) continue;
    int a = find(weld[f[0]]);
    for (int k = 1; k < 3; ++k) {
      int b = find(weld[f[k]]);
      if (a != b) parent[b] = a;
    }
  }

  // one output mesh per root, in order of first triangle; vertices renumbered per piece
  std::map<int, int> piece_of_root;
  std::vector<std::shared_ptr<MeshData>> pieces;
  std::vector<std::map<int, int>> remap;
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  const bool uvs = mesh.uvs.size() == mesh.vertices.size();
  for (const Eigen::Vector3i& f : mesh.faces) {
    if (!valid(f)) continue;
    int root = find(weld[f[0]]);
    auto [it, inserted] = piece_of_root.emplace(root, static_cast<int>(pieces.size()));
    if (inserted) {
      auto piece = std::make_shared<MeshData>();
      piece->source = mesh.source;
      piece->name = mesh.name + "_" + std::to_string(pieces.size());
      pieces.push_back(piece);
      remap.emplace_back();
    }
    MeshData& piece = *pieces[it->second];
    std::map<int, int>& ids = remap[it->second];
    Eigen::Vector3i g;
    for (int k = 0; k < 3; ++k) {
      auto [jt, fresh] = ids.emplace(f[k], static_cast<int>(piece.vertices.size()));
      if (fresh) {
        piece.vertices.push_back(mesh.vertices[f[k]]);
        if (normals) piece.normals.push_back(mesh.normals[f[k]]);
        if (uvs) piece.uvs.push_back(mesh.uvs[f[k]]);
      }
      g[k] = jt->second;
    }
    piece.faces.push_back(g);
  }
  if (pieces.size() == 1) pieces[0]->name = mesh.name;
  return pieces;
}

std::vector<std::shared_ptr<MeshData>> LoadConvexPieces(const std::string& path,
                                                        const Eigen::Vector3d& scale) {
  return ConnectedPieces(LoadMeshFile(path, scale));
}

std::vector<std::shared_ptr<MeshData>> ConnectedPieces(const std::vector<LoadedMesh>& parts) {
  std::vector<std::shared_ptr<MeshData>> out;
  for (const LoadedMesh& part : parts) {
    for (auto& piece : SplitConnectedComponents(*part.mesh)) out.push_back(std::move(piece));
  }
  return out;
}

}  // namespace partsim
