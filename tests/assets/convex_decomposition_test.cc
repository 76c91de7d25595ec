#include "partsim/assets/convex_decomposition.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

#include "assets/shape_meshes.h"
#include "partsim/assets/mesh.h"
#include "partsim/assets/mesh_builders.h"
#include "partsim/assets/urdf.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"
#include "tools/commands.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;
using Eigen::Vector3f;

using testing::Box;
using testing::Cup;
using testing::LShape;
using testing::Torus;
using testing::VoxelMesh;

bool InsidePiece(const MeshData& p, const Vector3d& x) {
  for (const Eigen::Vector3i& f : p.faces) {
    const Vector3d a = p.vertices[f[0]].cast<double>();
    const Vector3d n =
        (p.vertices[f[1]].cast<double>() - a).cross(p.vertices[f[2]].cast<double>() - a);
    if (n.dot(x - a) > 0) return false;
  }
  return true;
}

// Every vertex on the inner side of every face plane (within `tol`, m), and every edge shared by
// exactly two triangles in opposite directions.
void ExpectConvexAndClosed(const MeshData& m, double tol = 1e-6) {
  ASSERT_GE(m.vertices.size(), 4u);
  for (const Eigen::Vector3i& f : m.faces) {
    const Vector3d a = m.vertices[f[0]].cast<double>(), b = m.vertices[f[1]].cast<double>(),
                   c = m.vertices[f[2]].cast<double>();
    Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-12) continue;  // a sliver has no meaningful plane
    n.normalize();
    for (const Vector3f& v : m.vertices) {
      ASSERT_LE(n.dot(v.cast<double>() - a), tol) << "vertex outside a face plane";
    }
  }
  // edges between vertex positions (a loaded OBJ repeats vertices per face)
  std::map<std::tuple<float, float, float>, int> position_id;
  std::vector<int> id;
  for (const Vector3f& v : m.vertices) {
    id.push_back(position_id.emplace(std::make_tuple(v.x(), v.y(), v.z()), position_id.size())
                     .first->second);
  }
  std::map<std::pair<int, int>, int> directed;
  for (const Eigen::Vector3i& f : m.faces) {
    for (int k = 0; k < 3; ++k) ++directed[{id[f[k]], id[f[(k + 1) % 3]]}];
  }
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << "edge used twice in one direction";
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u) << "open edge";
  }
  EXPECT_GT(MeshVolume(m), 0.0) << "not outward";
}

TEST(ConvexDecompositionTest, LShapeSplitsIntoConvexPiecesThatCoverIt) {
  MeshData l = LShape();
  ConvexDecompositionResult r = DecomposeConvex(l);
  EXPECT_GE(r.pieces.size(), 2u);
  for (const auto& p : r.pieces) ExpectConvexAndClosed(*p);
  // volume: 0.3 * 0.05 * 0.15 + 0.25 * 0.05 * 0.15
  EXPECT_NEAR(r.mesh_volume, 0.55 * 0.05 * 0.15, 1e-9);
  EXPECT_GE(r.coverage, 0.99);
  EXPECT_LE(r.coverage_tolerance, 0.01 * r.diagonal);
  EXPECT_LT(r.excess, 0.10);
  EXPECT_NEAR(r.hull_union_volume_estimate, r.mesh_volume, 0.1 * r.mesh_volume);
}

TEST(ConvexDecompositionTest, HullOfTheWholeLIsMeasuredAsExcess) {
  // one piece forced: the measures see the hull fill the L's inner corner
  ConvexDecompositionOptions o;
  o.max_pieces = 1;
  ConvexDecompositionResult r = DecomposeConvex(LShape(), o);
  ASSERT_EQ(r.pieces.size(), 1u);
  EXPECT_GE(r.coverage, 0.99);
  // the hull adds the triangle between the arms: 0.5 * 0.25^2 * 0.15 over 0.55 * 0.05 * 0.15
  EXPECT_NEAR(r.excess, 0.5 * 0.25 * 0.25 / (0.55 * 0.05), 0.1);
}

TEST(ConvexDecompositionTest, BoxStaysOnePiece) {
  ConvexDecompositionResult r = DecomposeConvex(Box());
  ASSERT_EQ(r.pieces.size(), 1u);
  ExpectConvexAndClosed(*r.pieces[0]);
  EXPECT_EQ(r.pieces[0]->vertices.size(), 8u);
  EXPECT_NEAR(MeshVolume(*r.pieces[0]), 0.2 * 0.1 * 0.05, 1e-9);
  EXPECT_GE(r.coverage, 0.999);
  EXPECT_DOUBLE_EQ(r.max_surface_distance, 0.0);
  EXPECT_LT(r.excess, 0.01);
}

TEST(ConvexDecompositionTest, TorusGivesSeveralPiecesCoveringIt) {
  MeshData torus = Torus(0.1, 0.03);
  ConvexDecompositionResult r = DecomposeConvex(torus);
  EXPECT_GE(r.pieces.size(), 4u);
  EXPECT_LE(r.pieces.size(), 32u);
  for (const auto& p : r.pieces) ExpectConvexAndClosed(*p);
  EXPECT_GE(r.coverage, 0.99);
  EXPECT_LT(r.excess, 0.15);
  // the hole stays empty: its centre is in no piece
  for (const auto& p : r.pieces) {
    EXPECT_FALSE(InsidePiece(*p, Vector3d::Zero())) << "a piece fills the torus's hole";
  }
}

TEST(ConvexDecompositionTest, ThinWalledCupKeepsItsCavityEmpty) {
  MeshData cup = Cup(0.04, 0.1, 0.004, 24);
  ASSERT_GT(MeshVolume(cup), 0.0);
  ConvexDecompositionResult r = DecomposeConvex(cup);
  EXPECT_GE(r.pieces.size(), 4u);
  for (const auto& p : r.pieces) ExpectConvexAndClosed(*p);
  EXPECT_GE(r.coverage, 0.99);
  // the flat bottom faces join each other, not a wall: nothing fills the cup
  EXPECT_LT(r.excess, 0.5);
  for (double z : {0.02, 0.05, 0.09}) {
    for (const auto& p : r.pieces) {
      EXPECT_FALSE(InsidePiece(*p, Vector3d(0, 0, z))) << "a piece fills the cup at z = " << z;
    }
  }
}

TEST(ConvexDecompositionTest, MaxPiecesCapsTheCount) {
  ConvexDecompositionOptions o;
  o.max_pieces = 3;
  ConvexDecompositionResult r = DecomposeConvex(Torus(0.1, 0.03), o);
  EXPECT_LE(r.pieces.size(), 3u);
  EXPECT_GE(r.pieces.size(), 1u);
  // fewer pieces fit worse
  EXPECT_GT(r.excess, DecomposeConvex(Torus(0.1, 0.03)).excess);
}

TEST(ConvexDecompositionTest, SimplifiedHullsReportTheirCoverage) {
  ConvexDecompositionOptions o;
  o.max_hull_vertices = 6;
  ConvexDecompositionResult r = DecomposeConvex(Torus(0.1, 0.03), o);
  for (const auto& p : r.pieces) {
    EXPECT_LE(p->vertices.size(), 6u);
    ExpectConvexAndClosed(*p);
  }
  // hulls of 6 vertices cut the round surface: the distance says by how much
  EXPECT_GT(r.max_surface_distance, 0.0);
  EXPECT_LT(r.max_surface_distance, 0.03);
}

TEST(ConvexDecompositionTest, BadInputThrowsNamingTheCause) {
  auto message = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([] { DecomposeConvexFile("/nonexistent/part.obj"); }).find("part.obj"),
            std::string::npos);

  MeshData nan = LShape();
  nan.source = "bad_part.obj";
  nan.vertices[3].x() = std::numeric_limits<float>::quiet_NaN();
  std::string m = message([&] { DecomposeConvex(nan); });
  EXPECT_NE(m.find("bad_part.obj"), std::string::npos) << m;
  EXPECT_NE(m.find("vertex 3"), std::string::npos) << m;

  // a single square: a flat open surface has no volume
  MeshData flat;
  flat.vertices = {Vector3f(0, 0, 0), Vector3f(1, 0, 0), Vector3f(1, 1, 0), Vector3f(0, 1, 0)};
  flat.faces = {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 2, 3)};
  m = message([&] { DecomposeConvex(flat); });
  EXPECT_NE(m.find("no volume"), std::string::npos) << m;

  MeshData empty;
  EXPECT_NE(message([&] { DecomposeConvex(empty); }).find("no triangles"), std::string::npos);

  MeshData out_of_range = Box();
  out_of_range.faces[0][1] = 1000;
  EXPECT_NE(message([&] { DecomposeConvex(out_of_range); }).find("face 0"), std::string::npos);

  ConvexDecompositionOptions o;
  o.max_pieces = 0;
  EXPECT_NE(message([&] { DecomposeConvex(Box(), o); }).find("max_pieces"), std::string::npos);
}

// Drops a ball of radius 0.02 m above the L's inner corner onto the given static collision and
// returns where it rests.
Vector3d DropBallIntoCorner(Scene& scene) {
  Actor ball = scene.CreateActorBuilder()
                   .AddSphereCollision(Pose(), 0.02)
                   .SetInitialPose(Pose(Vector3d(0.1, 0.075, 0.4)))
                   .Build();
  scene.Step(1500);
  return ball.GetPose().p;
}

TEST(ConvexDecompositionTest, WrittenPiecesLoadAndMakeANonConvexCollisionShape) {
  const fs::path dir = fs::temp_directory_path() / "partsim_convex_decomposition_test";
  fs::remove_all(dir);
  ConvexDecompositionResult r = DecomposeConvex(LShape());
  std::vector<std::string> files = WriteConvexPieces(r, dir.string(), "ell");
  ASSERT_EQ(files.size(), r.pieces.size() + 1);

  // OBJ files load back with the same vertices
  for (size_t k = 0; k < r.pieces.size(); ++k) {
    EXPECT_EQ(files[k], (dir / ("ell_" + std::to_string(k) + ".obj")).string());
    std::shared_ptr<MeshData> back = LoadMergedMesh(files[k]);
    EXPECT_NEAR(MeshVolume(*back), MeshVolume(*r.pieces[k]), 1e-9);
    ExpectConvexAndClosed(*back);
  }

  // a URDF around the snippet, its link fixed to the world
  std::ifstream snippet(files.back());
  std::stringstream text;
  text << "<robot name=\"ell\"><link name=\"base\">" << snippet.rdbuf() << "</link></robot>";
  {
    Scene scene;
    scene.AddGround(0.0);
    UrdfLoader loader(&scene);
    Articulation ell = loader.LoadFromString(text.str(), dir.string());
    ASSERT_EQ(ell.GetLinks().size(), 1u);
    EXPECT_EQ(ell.GetLinks()[0].GetDesc().collisions.size(), r.pieces.size());
    // the ball lands on the L's floor, inside the corner
    Vector3d p = DropBallIntoCorner(scene);
    EXPECT_NEAR(p.z(), 0.05 + 0.02, 0.003);
    EXPECT_GT(p.x(), 0.05);
    EXPECT_LT(p.x(), 0.3);
  }
  {
    // the hull of the whole L fills the corner with a slope: the ball rolls off onto the ground
    Scene scene;
    scene.AddGround(0.0);
    const std::string whole = (dir / "whole.obj").string();
    ConvexDecompositionResult one = r;
    one.pieces = {ConvexHull([&] {
      std::vector<Vector3d> pts;
      MeshData l = LShape();
      for (const Vector3f& v : l.vertices) pts.push_back(v.cast<double>());
      return pts;
    }())};
    WriteConvexPieces(one, dir.string(), "whole");
    ActorBuilder wall = scene.CreateActorBuilder();
    AddConvexCollisionFromFile(wall, (dir / "whole_0.obj").string()).BuildStatic();
    Vector3d p = DropBallIntoCorner(scene);
    EXPECT_FALSE(std::abs(p.z() - 0.07) < 0.003 && p.x() > 0.05 && p.x() < 0.3)
        << "ball at " << p.transpose();
  }
  fs::remove_all(dir);
}

TEST(ConvexDecompositionTest, CommandWritesPiecesAndRejectsBadArguments) {
  const fs::path dir = fs::temp_directory_path() / "partsim_decompose_command_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // the L as an OBJ file
  MeshData l = LShape();
  const std::string obj = (dir / "ell.obj").string();
  {
    std::ofstream out(obj);
    for (const Vector3f& v : l.vertices)
      out << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
    for (const Eigen::Vector3i& f : l.faces) {
      out << "f " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << "\n";
    }
  }
  const std::string out_dir = (dir / "pieces").string();
  std::vector<std::string> args = {"decompose", obj, "--out", out_dir, "--max-pieces", "4"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  EXPECT_EQ(RunDecomposeCommand(static_cast<int>(argv.size()), argv.data()), 0);
  EXPECT_TRUE(fs::exists(fs::path(out_dir) / "ell_0.obj"));
  EXPECT_TRUE(fs::exists(fs::path(out_dir) / "ell_1.obj"));
  EXPECT_TRUE(fs::exists(fs::path(out_dir) / "ell_collision.urdf.xml"));

  std::vector<std::string> bad = {"decompose", obj, "--max-pieces", "x"};
  argv.clear();
  for (std::string& a : bad) argv.push_back(a.data());
  EXPECT_EQ(RunDecomposeCommand(static_cast<int>(argv.size()), argv.data()), 2);

  std::vector<std::string> missing = {"decompose", (dir / "nope.obj").string(), "--out", out_dir};
  argv.clear();
  for (std::string& a : missing) argv.push_back(a.data());
  EXPECT_EQ(RunDecomposeCommand(static_cast<int>(argv.size()), argv.data()), 1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace partsim
