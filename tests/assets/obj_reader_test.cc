// partsim's OBJ reader against assimp's importer, which LoadMeshFile used for OBJ before: the
// same sub-meshes, materials, vertices (in order), normals, uvs and triangles on every OBJ file
// of a generated tree, of ../shared/realdata and of the test data, and on a file written to
// exercise the format's corners; then what it does beyond assimp, and its errors.
#include "assets/obj_reader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "partsim/assets/generator.h"
#include "partsim/assets/mesh.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

fs::path Temp(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("partsim_obj_reader_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void Write(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Both readers' sub-meshes of `path`, the same up to the last bits of parsed numbers (assimp's
// own number parser is not correctly rounded).
void ExpectSameAsAssimp(const std::string& path) {
  SCOPED_TRACE(path);
  const std::vector<LoadedMesh> ours = LoadMeshFile(path);
  const std::vector<LoadedMesh> theirs =
      internal::LoadMeshFileWithAssimp(path, Eigen::Vector3d::Ones());
  ASSERT_EQ(ours.size(), theirs.size());
  for (size_t i = 0; i < ours.size(); ++i) {
    SCOPED_TRACE("sub-mesh " + std::to_string(i));
    const MeshData& a = *ours[i].mesh;
    const MeshData& b = *theirs[i].mesh;
    EXPECT_EQ(a.name, b.name);
    ASSERT_EQ(a.vertices.size(), b.vertices.size());
    ASSERT_EQ(a.normals.size(), b.normals.size());
    ASSERT_EQ(a.uvs.size(), b.uvs.size());
    for (size_t k = 0; k < a.vertices.size(); ++k) {
      ASSERT_LE((a.vertices[k] - b.vertices[k]).norm(), 1e-6f * (1.0f + b.vertices[k].norm()))
          << "vertex " << k;
      if (!a.normals.empty()) ASSERT_LE((a.normals[k] - b.normals[k]).norm(), 1e-5f) << k;
      if (!a.uvs.empty()) ASSERT_LE((a.uvs[k] - b.uvs[k]).norm(), 1e-6f) << k;
    }
    // where a corner is within 1e-5 of two vertices at its position (the corners of a fan of
    // thin triangles), the readers may take different ones: corners compare by what they hold
    ASSERT_EQ(a.faces.size(), b.faces.size());
    for (size_t f = 0; f < a.faces.size(); ++f) {
      if (a.faces[f] == b.faces[f]) continue;
      for (int k = 0; k < 3; ++k) {
        const int ia = a.faces[f][k], ib = b.faces[f][k];
        ASSERT_EQ(a.vertices[ia], a.vertices[ib]) << "face " << f;
        if (!a.normals.empty()) ASSERT_LE((a.normals[ia] - b.normals[ib]).norm(), 2e-5f) << f;
        if (!a.uvs.empty()) ASSERT_LE((a.uvs[ia] - b.uvs[ib]).norm(), 2e-5f) << f;
      }
    }
    const RenderMaterial& ma = ours[i].material;
    const RenderMaterial& mb = theirs[i].material;
    EXPECT_LE((ma.base_color - mb.base_color).norm(), 1e-6f)
        << ma.base_color.transpose() << " | " << mb.base_color.transpose();
    EXPECT_FLOAT_EQ(ma.roughness, mb.roughness);
    EXPECT_FLOAT_EQ(ma.metallic, mb.metallic);
    EXPECT_EQ(ma.diffuse_texture, mb.diffuse_texture);
  }
}

std::vector<std::string> ObjFilesUnder(const fs::path& root) {
  std::vector<std::string> out;
  if (!fs::exists(root)) return out;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file() && e.path().extension() == ".obj") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(ObjReaderTest, MatchesAssimpOnGeneratedObjects) {
  const fs::path dir = Temp("generated");
  int i = 0;
  for (const char* category : {"StorageFurniture", "Refrigerator", "Faucet", "Keyboard", "Bucket",
                               "Eyeglasses", "USB", "Table", "Door", "Oven"}) {
    const GeneratedObject o = GenerateObject(category, i++, 11);
    WriteObject(o, (dir / o.anno_id).string());
  }
  const std::vector<std::string> files = ObjFilesUnder(dir);
  ASSERT_GT(files.size(), 40u);
  for (const std::string& f : files) ExpectSameAsAssimp(f);
}

TEST(ObjReaderTest, MatchesAssimpOnTheTestDataAndRealData) {
  std::vector<std::string> files = ObjFilesUnder(PARTSIM_TEST_DATA_DIR);
  ASSERT_GE(files.size(), 3u);
  // ../shared/realdata's PartNet-Mobility object: textured parts, "o" names holding '#'
  const std::vector<std::string> real =
      ObjFilesUnder(fs::path(PARTSIM_SOURCE_DIR) / ".." / "shared" / "realdata");
  files.insert(files.end(), real.begin(), real.end());
  for (const std::string& f : files) ExpectSameAsAssimp(f);
}

// Sub-meshes at o, g and usemtl; faces before any usemtl take the library's last material;
// a name the library lacks is grey; Kd, d, Tr, Pr, Pm, map_Kd with options and a space in the
// name; uvs on some faces only; given and made normals; a quad; negative indices.
TEST(ObjReaderTest, MatchesAssimpOnTheFormatsCorners) {
  const fs::path dir = Temp("corners");
  Write(dir / "a.mtl",
        "newmtl red\nKd 1 0 0\nd 0.5\nnewmtl blue\nKd 0 0 1\nTr 0.25\nPr 0.3\nPm 0.7\n"
        "newmtl tex\nKd 0.5 0.5 0.5\nmap_Kd -s 1 1 1 -o 0 0 0 some dir/tex.png\n");
  Write(dir / "a.obj",
        "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\n"
        "vn 0 0 1\nf 1 2 3\nf 1 3 4\no second\nusemtl red\nf 1/1 2/2 5/3\nf 2 3 5\n"
        "usemtl blue\nf 3//1 4//1 5//1\ng grp\nf 1 2 3 4\nusemtl red\nf -1 -2 -3\n"
        "usemtl tex\nf 1 2 5\nusemtl missing\nf 2 3 4\n");
  ExpectSameAsAssimp((dir / "a.obj").string());
  const std::vector<LoadedMesh> m = LoadMeshFile((dir / "a.obj").string());
  std::vector<std::string> names;
  for (const LoadedMesh& l : m) names.push_back(l.mesh->name);
  EXPECT_EQ(names, (std::vector<std::string>{"defaultobject", "second", "blue", "grp", "red", "tex",
                                             "missing"}));
  EXPECT_FLOAT_EQ(m[2].material.base_color[3], 0.75f);  // Tr 0.25
  EXPECT_FLOAT_EQ(m[6].material.base_color[0], 0.6f);   // unknown: grey
  EXPECT_EQ(m[5].material.diffuse_texture, (dir / "some dir" / "tex.png").string());
}

// Twice the area of every triangle, and the sum of their normals: what a triangulation of the
// same polygons keeps whatever diagonals it takes.
std::pair<double, Eigen::Vector3d> AreaAndNormal(const MeshData& m) {
  double area = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3i& f : m.faces) {
    const Eigen::Vector3d a = m.vertices[f[0]].cast<double>(), b = m.vertices[f[1]].cast<double>(),
                          c = m.vertices[f[2]].cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    area += n.norm();
    normal += n;
  }
  return {area, normal};
}

// Concave polygons are cut into ears, convex ones fanned: the same surface as assimp's, though
// its diagonals may come in another order; every triangle faces the way its polygon does.
TEST(ObjReaderTest, ConcavePolygonsCoverWhatTheyBound) {
  const fs::path dir = Temp("polygons");
  Write(dir / "p.obj",
        "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 0.5 0\nv 0 2 0\n"         // a concave pentagon
        "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0.6 0.3 1\n"                // a concave quad ("arrowhead")
        "v 0 0 2\nv 1 0 2\nv 1.5 1 2\nv 0.5 1.7 2\nv -0.5 1 2\n"  // a convex pentagon
        "f 1 2 3 4 5\nf 6 7 8 9\nf 10 11 12 13 14\n");
  const std::vector<LoadedMesh> ours = LoadMeshFile((dir / "p.obj").string());
  const std::vector<LoadedMesh> theirs =
      internal::LoadMeshFileWithAssimp((dir / "p.obj").string(), Eigen::Vector3d::Ones());
  ASSERT_EQ(ours.size(), 1u);
  ASSERT_EQ(theirs.size(), 1u);
  EXPECT_EQ(ours[0].mesh->faces.size(), 3u + 2u + 3u);
  const auto [area, normal] = AreaAndNormal(*ours[0].mesh);
  const auto [area_ref, normal_ref] = AreaAndNormal(*theirs[0].mesh);
  EXPECT_NEAR(area, area_ref, 1e-6);
  EXPECT_LE((normal - normal_ref).norm(), 1e-6);
  EXPECT_NEAR(area, normal.norm(), 1e-6);  // no triangle folds back: all face +z
  // twice the areas (shoelace): concave pentagon 5, arrowhead 0.7, convex pentagon 4.4
  EXPECT_NEAR(area, 5.0 + 0.7 + 4.4, 1e-5);
}

// A concave face of 2,000 corners (a star) is cut into 1,998 ears that cover exactly its area;
// the cutting walks on from each cut, so such a face costs n^2 checks, not n^3.
TEST(ObjReaderTest, AStarOfTwoThousandCornersIsCutIntoEars) {
  const fs::path dir = Temp("star");
  constexpr int kCorners = 2000;
  std::string obj;
  std::vector<Eigen::Vector2d> corners;
  for (int i = 0; i < kCorners; ++i) {
    const double angle = 2.0 * M_PI * i / kCorners, r = i % 2 ? 0.5 : 1.0;
    corners.emplace_back(r * std::cos(angle), r * std::sin(angle));
    obj += "v " + std::to_string(corners.back().x()) + " " + std::to_string(corners.back().y()) +
           " 0\n";
  }
  obj += "f";
  for (int i = 1; i <= kCorners; ++i) obj += " " + std::to_string(i);
  Write(dir / "star.obj", obj + "\n");
  const std::vector<LoadedMesh> m = LoadMeshFile((dir / "star.obj").string());
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].mesh->faces.size(), static_cast<size_t>(kCorners - 2));
  double twice_area = 0.0;  // shoelace, of the file's rounded corners
  for (int i = 0; i < kCorners; ++i) {
    const Eigen::Vector3f& a = m[0].mesh->vertices[i];
    const Eigen::Vector3f& b = m[0].mesh->vertices[(i + 1) % kCorners];
    twice_area += static_cast<double>(a.x()) * b.y() - static_cast<double>(b.x()) * a.y();
  }
  const auto [area, normal] = AreaAndNormal(*m[0].mesh);
  EXPECT_NEAR(area, twice_area, 1e-4);
  EXPECT_NEAR(normal.z(), area, 1e-4);  // no ear folds back
}

// Where assimp refuses or guesses: CRLF line ends, a statement continued with '\', comments
// after numbers, a vertex colour, points and lines among faces, and faces without normals next
// to faces with them (assimp leaves those normals zero; partsim gives them their face's).
TEST(ObjReaderTest, ReadsWhatAssimpRefusesOrLeavesWithoutNormals) {
  const fs::path dir = Temp("beyond");
  Write(dir / "b.obj",
        "v 0 0 0\r\nv 1 0 0 0.5 0.5 0.5\r\nv 0 1 0 # third\r\nv 0 0 1\r\nvn 0 0 1\r\n"
        "f 1//1 2//1 \\\r\n 3//1\r\nl 1 2\r\np 3\r\nf 1 2 4\r\n");
  const std::vector<LoadedMesh> m = LoadMeshFile((dir / "b.obj").string());
  ASSERT_EQ(m.size(), 1u);
  const MeshData& mesh = *m[0].mesh;
  ASSERT_EQ(mesh.faces.size(), 2u);
  ASSERT_EQ(mesh.vertices.size(), 6u);  // the faces' normals differ: no corner is shared
  EXPECT_TRUE(mesh.vertices[1].isApprox(Eigen::Vector3f(1, 0, 0)));
  EXPECT_TRUE(mesh.vertices[2].isApprox(Eigen::Vector3f(0, 1, 0)));
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(mesh.normals[mesh.faces[0][k]].isApprox(Eigen::Vector3f(0, 0, 1)));
    EXPECT_TRUE(mesh.normals[mesh.faces[1][k]].isApprox(Eigen::Vector3f(0, -1, 0)));
  }
  EXPECT_TRUE(mesh.uvs.empty());
}

std::string ErrorOf(const std::string& obj) {
  const fs::path dir = Temp("errors");
  Write(dir / "bad.obj", obj);
  try {
    LoadMeshFile((dir / "bad.obj").string());
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Each unreadable statement is named with its file and line; the process goes on.
TEST(ObjReaderTest, BadStatementsAreNamedByLine) {
  auto expect = [](const std::string& obj, const std::string& line, const std::string& words) {
    const std::string e = ErrorOf(obj);
    EXPECT_NE(e.find("bad.obj', line " + line + ":"), std::string::npos) << e;
    EXPECT_NE(e.find(words), std::string::npos) << e;
  };
  expect("v 0 0 0\nv 1 zero 0\n", "2", "'v' needs 3 numbers, got 'zero'");
  expect("v 0 0 0\nv 1 0\n", "2", "'v' needs 3 numbers, got 2");
  // huge numbers: a coordinate past a float, an index past an int or a long
  expect("v 0 0 0\nv 1e50 0 0\n", "2", "'1e50' is beyond the range of a float");
  expect("v 0 0 0\nvt 0.5 -1e39\n", "2", "'-1e39' is beyond the range of a float");
  expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n", "4",
         "indices are whole numbers from 1");
  expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3000000000\n", "4",
         "face refers to vertex 3000000000 of 3");
  // non-ASCII bytes where a number belongs
  expect("v 0 0 0\nv \xc3\xa9 0 0\n", "2", "'v' needs 3 numbers");
  expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "4", "indices are whole numbers from 1");
  expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "4", "indices are whole numbers from 1");
  expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "4", "face refers to vertex 9 of 3");
  expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", "4", "refers before the first vertex");
  expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n", "4",
         "face refers to texture coordinate 1 of 0");
  expect("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1//2 2//2 3//2\n", "5", "face refers to normal 2 of 0");
  expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", "4", "has more than 3 fields");
  EXPECT_NE(ErrorOf("v 0 0 0\nv 1 0 0\nl 1 2\n").find("holds no triangles"), std::string::npos);
  EXPECT_NE(ErrorOf("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n").find("non-finite vertices"),
            std::string::npos);
  // a library that cannot be read leaves the faces grey, as assimp does
  const fs::path dir = Temp("nolib");
  Write(dir / "m.obj", "mtllib nowhere.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::vector<LoadedMesh> m = LoadMeshFile((dir / "m.obj").string());
  ASSERT_EQ(m.size(), 1u);
  EXPECT_FLOAT_EQ(m[0].material.base_color[1], 0.6f);
  // so does one whose name the system refuses (longer than a file name may be: found by
  // tests/fuzz/obj_fuzz.cc)
  Write(dir / "long.obj",
        "mtllib " + std::string(5000, 'x') + " y.mtl\nv 0 0 0\nv 1 0 0\n" + "v 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(LoadMeshFile((dir / "long.obj").string()).size(), 1u);
}

}  // namespace
}  // namespace partsim
