#include "partsim/assets/mesh.h"

#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <filesystem>
#include <map>
#include <numeric>
#include <tuple>

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

bool IsCollada(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".dae";
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

// Collects the triangles of every mesh instance under `node`, transformed by X_FN.
void CollectNode(const aiScene* scene, const aiNode* node, const Eigen::Matrix4d& parent,
                 const Eigen::Vector3d& scale, const std::string& path, const fs::path& dir,
                 std::vector<LoadedMesh>* out) {
  const Eigen::Matrix4d x = parent * ToEigen(node->mTransformation);
  const Eigen::Matrix3d normal_matrix = x.topLeftCorner<3, 3>().inverse().transpose();
  for (unsigned k = 0; k < node->mNumMeshes; ++k) {
    const aiMesh* am = scene->mMeshes[node->mMeshes[k]];
    auto mesh = std::make_shared<MeshData>();
    mesh->source = path;
    mesh->name = am->mName.length > 0 ? am->mName.C_Str() : node->mName.C_Str();

    // vertices in the file frame, then scaled
    mesh->vertices.reserve(am->mNumVertices);
    for (unsigned i = 0; i < am->mNumVertices; ++i) {
      const aiVector3D& a = am->mVertices[i];
      Eigen::Vector3d p = (x * Eigen::Vector4d(a.x, a.y, a.z, 1.0)).head<3>();
      mesh->vertices.push_back(p.cwiseProduct(scale).cast<float>());
    }
    if (am->HasNormals()) {
      // normals of a scaled mesh transform with the inverse scale
      const Eigen::Vector3d inv_scale = scale.cwiseInverse();
      mesh->normals.reserve(am->mNumVertices);
      for (unsigned i = 0; i < am->mNumVertices; ++i) {
        const aiVector3D& a = am->mNormals[i];
        Eigen::Vector3d n =
            (normal_matrix * Eigen::Vector3d(a.x, a.y, a.z)).cwiseProduct(inv_scale);
        double len = n.norm();
        mesh->normals.push_back((len > 0 ? n / len : n).cast<float>());
      }
    }
    if (am->HasTextureCoords(0)) {
      mesh->uvs.reserve(am->mNumVertices);
      for (unsigned i = 0; i < am->mNumVertices; ++i) {
        mesh->uvs.emplace_back(am->mTextureCoords[0][i].x, am->mTextureCoords[0][i].y);
      }
    }

    // triangles only: points and lines left by triangulation are dropped; a mirroring scale
    // flips the winding back to counter-clockwise
    const bool flip = (x.topLeftCorner<3, 3>().determinant() * scale.prod()) < 0;
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      Eigen::Vector3i t(face.mIndices[0], face.mIndices[1], face.mIndices[2]);
      if (flip) std::swap(t[1], t[2]);
      mesh->faces.push_back(t);
    }
    if (mesh->faces.empty()) continue;

    const aiMaterial* mat =
        am->mMaterialIndex < scene->mNumMaterials ? scene->mMaterials[am->mMaterialIndex] : nullptr;
    out->push_back(LoadedMesh{mesh, ConvertMaterial(mat, dir)});
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) {
    CollectNode(scene, node->mChildren[c], x, scale, path, dir, out);
  }
}

}  // namespace

std::vector<LoadedMesh> LoadMeshFile(const std::string& path, const Eigen::Vector3d& scale) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw Error("mesh file '" + path + "' does not exist or is not a regular file");
  }
  if (!scale.allFinite()) throw Error("mesh file '" + path + "': scale is not finite");

  Assimp::Importer importer;
  // no points or lines: they are not surfaces
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                  aiProcess_GenNormals | aiProcess_SortByPType);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw Error("mesh file '" + path + "' could not be read: " + importer.GetErrorString());
  }

  // assimp scales Collada by its <unit> and turns its up axis into +y; partsim is z-up, so turn
  // +y back into +z: a Z_UP file comes out as written, a Y_UP file stands up
  Eigen::Matrix4d root = Eigen::Matrix4d::Identity();
  if (IsCollada(path)) {
    root.topLeftCorner<3, 3>() << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  }

  std::vector<LoadedMesh> out;
  const fs::path dir = fs::absolute(fs::path(path)).parent_path();
  CollectNode(scene, scene->mRootNode, root, scale, path, dir, &out);
  if (out.empty()) throw Error("mesh file '" + path + "' holds no triangles");
  for (const LoadedMesh& m : out) {
    for (const Eigen::Vector3f& v : m.mesh->vertices) {
      if (!v.allFinite()) throw Error("mesh file '" + path + "' has non-finite vertices");
    }
  }
  return out;
}

std::shared_ptr<MeshData> LoadMergedMesh(const std::string& path, const Eigen::Vector3d& scale) {
  std::vector<LoadedMesh> parts = LoadMeshFile(path, scale);
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
  std::vector<std::shared_ptr<MeshData>> out;
  for (const LoadedMesh& part : LoadMeshFile(path, scale)) {
    for (auto& piece : SplitConnectedComponents(*part.mesh)) out.push_back(std::move(piece));
  }
  return out;
}

}  // namespace partsim
