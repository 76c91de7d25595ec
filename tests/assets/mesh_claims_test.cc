// Mesh files whose headers claim more than the file holds (a 218-byte PLY claiming 2e9
// vertices made assimp allocate until the kernel killed partsim): each is refused from its
// header, naming the file, the claim and what the file holds, inside a child process whose
// address space is bounded, so that a regression fails the test instead of filling the machine.
#include "assets/mesh_claims.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <string>

#include "partsim/assets/mesh.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

const std::string kMeshDir = std::string(PARTSIM_TEST_DATA_DIR) + "/meshes/";

// Address space the child may add to what the test process already maps: a reader that
// allocates what a lying header claims (gigabytes) fails inside it.
constexpr uint64_t kHeadroomBytes = 512ull << 20;

// Runs `f` in a child process whose address space is bounded to the parent's plus
// kHeadroomBytes and whose run is bounded to 60 s (a guard against hangs, not a speed check);
// returns partsim::Error's message, "(no error)", "(bad_alloc)" or "(killed by signal N)".
std::string ErrorInBoundedChild(const std::function<void()>& f) {
  uint64_t pages = 0;
  std::ifstream("/proc/self/statm") >> pages;
  const uint64_t mapped = pages * static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
  int fds[2];
  if (pipe(fds) != 0) return "(no pipe)";
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    rlimit limit{mapped + kHeadroomBytes, mapped + kHeadroomBytes};
    setrlimit(RLIMIT_AS, &limit);
    alarm(60);
    std::string out = "(no error)";
    try {
      f();
    } catch (const Error& e) {
      out = e.what();
    } catch (const std::bad_alloc&) {
      out = "(bad_alloc)";
    } catch (const std::exception& e) {
      out = std::string("(other exception) ") + e.what();
    }
    ssize_t unused = write(fds[1], out.data(), out.size());
    (void)unused;
    _exit(0);
  }
  close(fds[1]);
  std::string out;
  char buf[4096];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) out.append(buf, n);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFSIGNALED(status)) return "(killed by signal " + std::to_string(WTERMSIG(status)) + ")";
  return out;
}

class MeshClaimsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("partsim_mesh_claims_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& bytes) const {
    const std::string p = (dir_ / name).string();
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }
  // The error of loading `path` in a bounded child.
  static std::string LoadError(const std::string& path) {
    return ErrorInBoundedChild([&] { LoadMeshFile(path); });
  }
  fs::path dir_;
};

std::string Le32(uint32_t v) {
  return std::string{static_cast<char>(v), static_cast<char>(v >> 8), static_cast<char>(v >> 16),
                     static_cast<char>(v >> 24)};
}

std::string Floats(std::initializer_list<float> v) {
  std::string out;
  for (float f : v) out.append(reinterpret_cast<const char*>(&f), sizeof f);
  return out;
}

// A PLY header of `vertices` float xyz vertices and `faces` uchar/int faces.
std::string PlyHeader(const std::string& format, uint64_t vertices, uint64_t faces) {
  return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

// A tetrahedron's body in binary little-endian PLY.
std::string TetrahedronBinaryBody() {
  std::string body = Floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1});
  for (auto [a, b, c] : {std::tuple{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}})
    body += std::string(1, '\3') + Le32(a) + Le32(b) + Le32(c);
  return body;
}

TEST_F(MeshClaimsTest, PlyClaimingBillionsOfVerticesIsRefusedFromItsHeader) {
  const std::string binary =
      Write("bomb.ply", PlyHeader("binary_little_endian", 2000000000, 1) + std::string(40, '\0'));
  EXPECT_LT(fs::file_size(binary), 300u);
  std::string e = LoadError(binary);
  EXPECT_NE(e.find("mesh file '" + binary +
                   "': the PLY header claims 2000000000 'vertex' "
                   "elements (binary, at least 24000000000 bytes"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("but the file holds 40 bytes after its header"), std::string::npos) << e;

  const std::string ascii =
      Write("bomb_ascii.ply", PlyHeader("ascii", 2000000000, 1) + "0 0 0\n3 0 0 0\n");
  e = LoadError(ascii);
  EXPECT_NE(e.find("the PLY header claims 2000000000 'vertex' elements (ascii"), std::string::npos)
      << e;

  // a face count beyond the file, after honest vertices
  const std::string faces =
      Write("faces.ply", PlyHeader("binary_big_endian", 4, 1u << 31) + TetrahedronBinaryBody());
  e = LoadError(faces);
  EXPECT_NE(e.find("claims 2147483648 'face' elements (binary, at least 2147483696 bytes with "
                   "the elements before it), but the file holds 100 bytes"),
            std::string::npos)
      << e;
  // a count past 64 bits
  std::string text = PlyHeader("ascii", 4, 1);
  text.replace(text.find("vertex 4"), 8, "vertex 99999999999999999999999");
  e = LoadError(Write("huge.ply", text + "0 0 0\n"));
  EXPECT_NE(e.find("claims 18446744073709551615 'vertex' elements"), std::string::npos) << e;
}

TEST_F(MeshClaimsTest, HonestPlyFilesLoadWithinTheSameBound) {
  const std::string binary =
      Write("tet.ply", PlyHeader("binary_little_endian", 4, 4) + TetrahedronBinaryBody());
  EXPECT_EQ(LoadError(binary), "(no error)");
  EXPECT_EQ(LoadMergedMesh(binary)->faces.size(), 4u);
  const std::string ascii = Write(
      "tet_ascii.ply", PlyHeader("ascii", 4, 4) +
                           "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  EXPECT_EQ(LoadError(ascii), "(no error)");
  EXPECT_EQ(LoadMergedMesh(ascii)->faces.size(), 4u);
}

TEST_F(MeshClaimsTest, PlyFacesWithoutIndicesAreRefusedBeforeAssimpsStepsAbort) {
  // four faces whose lists hold 0 indices: assimp's triangulation asserted on them (abort)
  // (found by ply_fuzz)
  const std::string p = Write("empty_faces.ply", PlyHeader("binary_little_endian", 4, 4) +
                                                     Floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}) +
                                                     std::string(4, '\0'));
  const std::string e = LoadError(p);
  EXPECT_NE(e.find("mesh file '" + p + "': face 0 of mesh 0 has no vertex indices"),
            std::string::npos)
      << e;
}

TEST_F(MeshClaimsTest, PlyHeadersOutsideTheGrammarAreRefused) {
  // assimp's reader crashed (SIGSEGV) on a header without its end and on one with a property
  // of no known type (found by ply_fuzz)
  std::string header = PlyHeader("binary_little_endian", 4, 4);
  header.resize(header.find("end_header") + 8);
  std::string e = LoadError(Write("cut.ply", header + std::string("\0\0\3\0\0\0\0", 7)));
  EXPECT_NE(e.find("the PLY header has no end_header line"), std::string::npos) << e;
  header = PlyHeader("binary_little_endian", 4, 4);
  header.replace(header.find("list uchar"), 10, "tis luchar");
  e = LoadError(Write("type.ply", header + TetrahedronBinaryBody()));
  EXPECT_NE(e.find("the PLY header's line 8 'property tis luchar int vertex_indices' is not a PLY "
                   "header line"),
            std::string::npos)
      << e;
}

TEST_F(MeshClaimsTest, BinaryStlWhoseTriangleCountDisagreesWithItsSizeIsRefused) {
  const std::string bomb =
      Write("bomb.stl", std::string(80, 'x') + Le32(2000000000) + std::string(50, '\0'));
  const std::string e = LoadError(bomb);
  EXPECT_NE(e.find("mesh file '" + bomb +
                   "': the binary STL header claims 2000000000 triangles "
                   "(84 + 50 x 2000000000 = 100000000084 bytes), but the file holds 134 bytes"),
            std::string::npos)
      << e;
  // a binary STL whose header starts with "solid" is told by its size, and loads
  std::string tet = "solid but binary" + std::string(64, ' ') + Le32(4);
  const Eigen::Vector3f p[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (auto [a, b, c] : {std::tuple{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}) {
    tet += Floats({0, 0, 0, p[a].x(), p[a].y(), p[a].z(), p[b].x(), p[b].y(), p[b].z(), p[c].x(),
                   p[c].y(), p[c].z()}) +
           std::string(2, '\0');
  }
  const std::string solid = Write("solid.stl", tet);
  EXPECT_EQ(LoadError(solid), "(no error)");
  EXPECT_EQ(LoadMergedMesh(solid)->faces.size(), 4u);
}

// The text of a test mesh with `from` replaced by `to`.
std::string Edited(const std::string& name, const std::string& from, const std::string& to) {
  std::ifstream in(kMeshDir + name, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST_F(MeshClaimsTest, ColladaCountsBeyondTheFileAreRefused) {
  const std::string bomb =
      Write("bomb.dae", Edited("box_cm.dae", "count=\"24\"", "count=\"2000000000\""));
  const std::string e = LoadError(bomb);
  EXPECT_NE(e.find("mesh file '" + bomb +
                   "': COLLADA <float_array> claims count 2000000000 "
                   "(at least 4000000000 bytes of text), but the file holds"),
            std::string::npos)
      << e;
  EXPECT_EQ(LoadError(kMeshDir + "box_cm.dae"), "(no error)");
}

TEST_F(MeshClaimsTest, GltfAccessorsViewsAndBuffersBeyondTheirDataAreRefused) {
  std::string e =
      LoadError(Write("count.gltf", Edited("box.gltf", "\"count\": 8,", "\"count\": 2000000000,")));
  EXPECT_NE(e.find("glTF accessors[0] claims 2000000000 VEC3 elements (24000000000 bytes), but "
                   "bufferViews[0] holds 96 bytes"),
            std::string::npos)
      << e;
  e = LoadError(
      Write("view.gltf", Edited("box.gltf", "\"byteLength\": 96,", "\"byteLength\": 4000000000,")));
  EXPECT_NE(
      e.find("glTF bufferViews[0] claims bytes 0 to 4000000000 of buffers[0], which holds 168"),
      std::string::npos)
      << e;
  e = LoadError(Write("buffer.gltf",
                      Edited("box.gltf", "\"byteLength\": 168,", "\"byteLength\": 4000000000,")));
  EXPECT_NE(e.find("glTF buffers[0] claims byteLength 4000000000, but its data uri holds 170"),
            std::string::npos)
      << e;
  // an accessor without a buffer view is zeros, which the reader allocates in full
  std::string zeros = Edited("box.gltf", "\"count\": 8,", "\"count\": 2000000000,");
  zeros.replace(zeros.find("\"bufferView\": 0,"), 16, "");
  e = LoadError(Write("zeros.gltf", zeros));
  EXPECT_NE(e.find("glTF accessors[0] claims 2000000000 VEC3 elements without a buffer view"),
            std::string::npos)
      << e;
  EXPECT_EQ(LoadError(kMeshDir + "box.gltf"), "(no error)");
}

// A .glb of a tetrahedron: header, JSON chunk, BIN chunk.
std::string Glb(uint32_t json_chunk_claim = 0) {
  const std::string bin = Floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1});
  std::string json =
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
      "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},"
      "\"mode\":4}]}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,"
      "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,1]}],\"bufferViews\":[{\"buffer\":0,"
      "\"byteLength\":48}],\"buffers\":[{\"byteLength\":48}]}";
  json.append((4 - json.size() % 4) % 4, ' ');
  const uint32_t total = static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin.size());
  return "glTF" + Le32(2) + Le32(total) +
         Le32(json_chunk_claim ? json_chunk_claim : static_cast<uint32_t>(json.size())) + "JSON" +
         json + Le32(static_cast<uint32_t>(bin.size())) + std::string("BIN\0", 4) + bin;
}

TEST_F(MeshClaimsTest, GlbChunksBeyondTheFileAreRefused) {
  const std::string ok = Write("tet.glb", Glb());
  EXPECT_EQ(LoadError(ok), "(no error)");
  const std::string bomb = Write("bomb.glb", Glb(4000000000u));
  std::string e = LoadError(bomb);
  EXPECT_NE(e.find("mesh file '" + bomb + "': the GLB JSON chunk claims 4000000000 bytes"),
            std::string::npos)
      << e;
  std::string lying_header = Glb();
  lying_header.replace(8, 4, Le32(4000000000u));
  e = LoadError(Write("header.glb", lying_header));
  EXPECT_NE(e.find("the GLB header claims 4000000000 bytes, but the file holds"), std::string::npos)
      << e;
  // the JSON inside is held to the BIN chunk
  std::string count = Glb();
  count.replace(count.find("\"count\":4,"), 10, "\"count\":9,");
  e = LoadError(Write("count.glb", count));
  EXPECT_NE(e.find("glTF accessors[0] claims 9 VEC3 elements (108 bytes), but bufferViews[0] "
                   "holds 48 bytes"),
            std::string::npos)
      << e;
}

TEST_F(MeshClaimsTest, ObjIndicesAndCountsAllocateNothingFromTheFile) {
  // partsim's OBJ reader sizes nothing from the file: an index of 2e9 costs one line
  const std::string obj =
      Write("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2000000000\n# 2000000000 vertices\n");
  const std::string e = LoadError(obj);
  EXPECT_NE(e.find("line 4: face refers to vertex 2000000000 of 3"), std::string::npos) << e;
}

TEST_F(MeshClaimsTest, FormatsWhoseClaimsAreNotCheckedAreRefusedBeforeAssimpReadsThem) {
  // an OFF file claiming 2e9 vertices and a zipped COLLADA: assimp reads both, unchecked
  const std::string off = Write("big.off", "OFF\n2000000000 1 0\n0 0 0\n");
  std::string e = LoadError(off);
  EXPECT_NE(e.find("mesh file '" + off + "'"), std::string::npos) << e;
  EXPECT_NE(e.find("'.off' is not one of them"), std::string::npos) << e;
  EXPECT_NE(e.find("OBJ, STL, PLY, COLLADA (.dae), glTF (.gltf, .glb)"), std::string::npos) << e;
  e = LoadError(Write("part.ZAE", "PK\3\4"));
  EXPECT_NE(e.find("'.zae' is not one of them"), std::string::npos) << e;
  e = LoadError(Write("noext", "solid x\nendsolid x\n"));
  EXPECT_NE(e.find("'(no extension)' is not one of them"), std::string::npos) << e;
  // a checked format is told by its first bytes whatever the name
  std::ifstream in(kMeshDir + "box_yup.dae", std::ios::binary);
  const std::string dae = Write("copy.xml", std::string(std::istreambuf_iterator<char>(in), {}));
  EXPECT_EQ(LoadMeshFile(dae).size(), 1u);
}

}  // namespace
}  // namespace partsim
