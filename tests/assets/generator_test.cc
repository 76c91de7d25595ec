// Tests of the procedural object generator: every category generates and writes a
// PartNet-Mobility folder whose files parse and agree with each other, meshes are closed,
// outward-facing and convex, output is deterministic, moving parts keep clear of everything
// over their range, and objects rest still in a scene.
#include "partsim/assets/generator.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "partsim/assets/urdf.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using V3 = Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path TempDir(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("partsim_generator_test_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

/// A triangle mesh read from an OBJ file (v and f lines).
struct ObjMesh {
  std::vector<V3> v;
  std::vector<std::array<int, 3>> f;
};

ObjMesh ReadObj(const fs::path& p) {
  ObjMesh m;
  std::istringstream in(ReadFile(p));
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::string tag;
    l >> tag;
    if (tag == "v") {
      V3 x;
      l >> x.x() >> x.y() >> x.z();
      m.v.push_back(x);
    } else if (tag == "f") {
      std::array<int, 3> t;
      l >> t[0] >> t[1] >> t[2];
      for (int& i : t) --i;
      m.f.push_back(t);
    }
  }
  return m;
}

// ---------------------------------------------------------------------------------------------
// convex overlap test (GJK on the Minkowski difference, with a margin)

struct Support {
  const std::vector<V3>* a;
  const std::vector<V3>* b;
  double margin;
  V3 operator()(const V3& d) const {
    auto best = [](const std::vector<V3>& pts, const V3& dir) {
      double m = -1e300;
      V3 out = pts[0];
      for (const V3& p : pts) {
        double s = p.dot(dir);
        if (s > m) {
          m = s;
          out = p;
        }
      }
      return out;
    };
    return best(*a, d) - best(*b, -d) + margin * d.normalized();
  }
};

bool SameDir(const V3& a, const V3& b) { return a.dot(b) > 0; }

// reduces the simplex to the feature nearest the origin and sets the next direction; true when
// the simplex contains the origin
bool DoSimplex(std::vector<V3>& s, V3& d) {
  if (s.size() == 2) {
    V3 a = s[1], b = s[0], ab = b - a, ao = -a;
    if (SameDir(ab, ao)) {
      d = ab.cross(ao).cross(ab);
      if (d.squaredNorm() < 1e-30) return true;  // origin on the segment
    } else {
      s = {a};
      d = ao;
    }
    return false;
  }
  if (s.size() == 3) {
    V3 a = s[2], b = s[1], c = s[0], ab = b - a, ac = c - a, ao = -a, abc = ab.cross(ac);
    if (SameDir(abc.cross(ac), ao)) {
      if (SameDir(ac, ao)) {
        s = {c, a};
        d = ac.cross(ao).cross(ac);
      } else {
        s = {b, a};
        return DoSimplex(s, d);
      }
    } else if (SameDir(ab.cross(abc), ao)) {
      s = {b, a};
      return DoSimplex(s, d);
    } else if (SameDir(abc, ao)) {
      d = abc;
    } else if (abc.dot(ao) == 0.0) {
      return true;
    } else {
      s = {b, c, a};
      d = -abc;
    }
    return false;
  }
  // tetrahedron
  V3 a = s[3], b = s[2], c = s[1], dd = s[0], ao = -a;
  V3 abc = (b - a).cross(c - a), acd = (c - a).cross(dd - a), adb = (dd - a).cross(b - a);
  if (SameDir(abc, ao)) {
    s = {c, b, a};
    return DoSimplex(s, d);
  }
  if (SameDir(acd, ao)) {
    s = {dd, c, a};
    return DoSimplex(s, d);
  }
  if (SameDir(adb, ao)) {
    s = {b, dd, a};
    return DoSimplex(s, d);
  }
  return true;
}

/// True when convex hulls of a and b come closer than `margin`.
bool Overlap(const std::vector<V3>& a, const std::vector<V3>& b, double margin) {
  Support sup{&a, &b, margin};
  V3 d = a[0] - b[0];
  if (d.squaredNorm() < 1e-18) d = V3::UnitX();
  std::vector<V3> s = {sup(d)};
  d = -s[0];
  for (int it = 0; it < 100; ++it) {
    if (d.squaredNorm() < 1e-24) return true;
    V3 p = sup(d);
    if (p.dot(d) < 0) return false;
    s.push_back(p);
    if (DoSimplex(s, d)) return true;
  }
  return true;  // no decision: report it
}

/// A piece with its link and bounding box.
struct Piece {
  int link;
  std::string name;
  std::vector<V3> v;
  V3 lo, hi;
};

void Bound(Piece* p) {
  p->lo = V3::Constant(1e30);
  p->hi = V3::Constant(-1e30);
  for (const V3& x : p->v) {
    p->lo = p->lo.cwiseMin(x);
    p->hi = p->hi.cwiseMax(x);
  }
}

std::vector<Piece> Pieces(const GeneratedObject& o) {
  std::vector<Piece> out;
  for (const GeneratedLink& l : o.links) {
    for (const GeneratedPart& part : l.parts) {
      for (const GeneratedPiece& piece : part.pieces) {
        Piece p{l.id, part.name + "-" + std::to_string(part.id) + "@link_" + std::to_string(l.id),
                piece.vertices, V3(), V3()};
        Bound(&p);
        out.push_back(p);
      }
    }
  }
  return out;
}

/// Pairs of pieces of different links closer than `margin`, with each moving joint driven over
/// its range (the others at rest). Returns descriptions of the first few.
std::vector<std::string> Collisions(const GeneratedObject& o, double margin) {
  std::vector<Piece> rest = Pieces(o);
  const int n = static_cast<int>(o.links.size());
  std::vector<std::string> found;
  auto check = [&](const std::vector<Piece>& pieces, const std::vector<bool>& moved,
                   const std::string& what) {
    for (size_t i = 0; i < pieces.size(); ++i) {
      for (size_t j = i + 1; j < pieces.size(); ++j) {
        const Piece& a = pieces[i];
        const Piece& b = pieces[j];
        if (a.link == b.link) continue;
        if (!moved.empty() && moved[a.link] == moved[b.link]) continue;
        if ((a.lo.array() > b.hi.array() + margin).any() ||
            (b.lo.array() > a.hi.array() + margin).any()) {
          continue;
        }
        if (Overlap(a.v, b.v, margin) && found.size() < 5) {
          found.push_back(o.category + " " + what + ": " + a.name + " / " + b.name);
        }
      }
    }
  };
  check(rest, {}, "at rest");
  for (const GeneratedLink& l : o.links) {
    if (l.joint != "hinge" && l.joint != "slider") continue;
    // the subtree of link l moves
    std::vector<bool> moved(n, false);
    moved[l.id] = true;
    for (const GeneratedLink& k : o.links) {
      if (k.parent >= 0 && moved[k.parent]) moved[k.id] = true;
    }
    std::vector<double> qs;
    if (l.no_limit) {
      for (int k = 1; k < 8; ++k) qs.push_back(k * 45.0);
    } else {
      for (int k = 1; k <= 4; ++k) qs.push_back(l.limit_a + (l.limit_b - l.limit_a) * k / 4.0);
    }
    for (double q : qs) {
      Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
      if (l.joint == "hinge") {
        x.translate(l.axis_origin);
        x.rotate(Eigen::AngleAxisd(q * kPi / 180.0, l.axis_direction));
        x.translate(-l.axis_origin);
      } else {
        x.translate(q * l.axis_direction);
      }
      std::vector<Piece> pieces = rest;
      for (Piece& p : pieces) {
        if (!moved[p.link]) continue;
        for (V3& v : p.v) v = x * v;
        Bound(&p);
      }
      char buf[64];
      std::snprintf(buf, sizeof(buf), "link_%d at %g", l.id, q);
      check(pieces, moved, buf);
    }
  }
  return found;
}

// ---------------------------------------------------------------------------------------------

TEST(GeneratorTest, CategoriesAndPaperCounts) {
  std::vector<std::string> cats = GeneratorCategories();
  EXPECT_EQ(cats.size(), 46u);
  EXPECT_EQ(std::set<std::string>(cats.begin(), cats.end()).size(), 46u);
  int m = 0, p = 0;
  for (const std::string& c : cats) {
    m += PaperModelCount(c);
    p += PaperPartCount(c);
  }
  EXPECT_EQ(m, 2346);
  EXPECT_EQ(p, 14068);
  EXPECT_EQ(PaperModelCount("StorageFurniture"), 345);
  EXPECT_EQ(PaperPartCount("Keyboard"), 3593);
}

TEST(GeneratorTest, UnknownCategoryNamesIt) {
  try {
    GenerateObject("Spaceship", 0, 0);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("Spaceship"), std::string::npos);
  }
  EXPECT_THROW(PaperModelCount("Cabinet"), Error);
  EXPECT_THROW(GenerateObject("Chair", -1, 0), Error);
}

/// Checks one written folder against the object it came from.
void CheckFolder(const GeneratedObject& o, const fs::path& dir) {
  SCOPED_TRACE(o.category);
  for (const char* f :
       {"mobility.urdf", "mobility_v2.json", "semantics.txt", "meta.json", "bounding_box.json"}) {
    ASSERT_TRUE(fs::exists(dir / f)) << f;
  }
  // meta and bounding box
  nlohmann::json meta = nlohmann::json::parse(ReadFile(dir / "meta.json"));
  EXPECT_EQ(meta["model_cat"], o.category);
  EXPECT_EQ(meta["model_id"], o.model_id);
  EXPECT_TRUE(meta.contains("anno_id"));
  nlohmann::json bbox = nlohmann::json::parse(ReadFile(dir / "bounding_box.json"));
  for (int k = 0; k < 3; ++k) EXPECT_LT(bbox["min"][k].get<double>(), bbox["max"][k].get<double>());

  // mobility_v2.json against semantics.txt
  nlohmann::json mob = nlohmann::json::parse(ReadFile(dir / "mobility_v2.json"));
  ASSERT_EQ(mob.size(), o.links.size());
  std::istringstream sem(ReadFile(dir / "semantics.txt"));
  int heavy = 0;
  std::set<int> part_ids;
  for (size_t i = 0; i < mob.size(); ++i) {
    const nlohmann::json& e = mob[i];
    EXPECT_EQ(e["id"].get<int>(), static_cast<int>(i));
    std::string link, joint, label;
    sem >> link >> joint >> label;
    EXPECT_EQ(link, "link_" + std::to_string(i));
    EXPECT_EQ(joint, e["joint"].get<std::string>());
    EXPECT_EQ(label, e["name"].get<std::string>());
    EXPECT_TRUE(joint == "hinge" || joint == "slider" || joint == "heavy" || joint == "static" ||
                joint == "free")
        << joint;
    if (joint == "heavy") {
      ++heavy;
      EXPECT_EQ(e["parent"].get<int>(), -1);
    }
    EXPECT_LT(e["parent"].get<int>(), static_cast<int>(i));
    for (const auto& p : e["parts"]) EXPECT_TRUE(part_ids.insert(p["id"].get<int>()).second);
  }
  EXPECT_EQ(heavy, 1);

  // the URDF: link_N and joint_N agree with the JSON (types, limits, axes)
  UrdfLoader loader;
  ArticulationDesc art = loader.ParseFile((dir / "mobility.urdf").string());
  std::map<std::string, const LinkDesc*> by_name;
  for (const LinkDesc& l : art.links) by_name[l.name] = &l;
  ASSERT_TRUE(by_name.count("base"));
  EXPECT_EQ(art.links[0].name, "base");
  for (size_t i = 0; i < mob.size(); ++i) {
    const nlohmann::json& e = mob[i];
    const std::string name = "link_" + std::to_string(i);
    ASSERT_TRUE(by_name.count(name)) << name;
    const LinkDesc& l = *by_name[name];
    std::string joint = e["joint"];
    // every part has visuals named <name>-<id>
    std::set<std::string> visual_names;
    for (const VisualShape& v : l.visuals) visual_names.insert(v.name);
    for (const auto& p : e["parts"]) {
      std::string want = p["name"].get<std::string>() + "-" + std::to_string(p["id"].get<int>());
      EXPECT_TRUE(visual_names.count(want)) << name << " lacks visual " << want;
    }
    EXPECT_EQ(l.collisions.size(), l.visuals.size()) << name;
    if (joint != "hinge" && joint != "slider") {
      EXPECT_EQ(l.joint.type, JointType::kFixed) << name;
      EXPECT_TRUE(e["jointData"].empty()) << name;
      continue;
    }
    const nlohmann::json& lim = e["jointData"]["limit"];
    bool rotates = joint == "slider" && lim["rotates"].get<bool>();
    // a rotating slider: prismatic to link_N_helper, then the rotation
    const LinkDesc& moving = rotates ? *by_name[name + "_helper"] : l;
    if (joint == "hinge") {
      bool no_limit = lim["noLimit"].get<bool>();
      EXPECT_EQ(l.joint.type, no_limit ? JointType::kContinuous : JointType::kRevolute) << name;
      if (!no_limit) {
        double a = lim["a"].get<double>(), b = lim["b"].get<double>();
        EXPECT_NEAR(l.joint.lower, std::min(a, b) * kPi / 180, 1e-6) << name;
        EXPECT_NEAR(l.joint.upper, std::max(a, b) * kPi / 180, 1e-6) << name;
        EXPECT_LE(l.joint.lower, 0.0);
        EXPECT_GE(l.joint.upper, 0.0);
      }
    } else {
      EXPECT_EQ(moving.joint.type, JointType::kPrismatic) << name;
      double a = lim["a"].get<double>(), b = lim["b"].get<double>();
      EXPECT_NEAR(moving.joint.lower, std::min(a, b), 1e-6) << name;
      EXPECT_NEAR(moving.joint.upper, std::max(a, b), 1e-6) << name;
      if (rotates) EXPECT_EQ(l.joint.type, JointType::kContinuous) << name;
    }
    // the JSON axis is parallel to the joint axis (the joint frame's x axis), in the file frame
    V3 dir(e["jointData"]["axis"]["direction"][0].get<double>(),
           e["jointData"]["axis"]["direction"][1].get<double>(),
           e["jointData"]["axis"]["direction"][2].get<double>());
    V3 x_axis = moving.joint.pose_in_parent.q * V3::UnitX();
    EXPECT_NEAR(std::abs(x_axis.dot(dir.normalized())), 1.0, 1e-6) << name;
  }

  // meshes: every OBJ closed, outward and convex
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir / "textured_objs")) {
    if (entry.path().extension() != ".obj") continue;
    ++files;
    ObjMesh m = ReadObj(entry.path());
    std::string f = entry.path().filename().string();
    ASSERT_GE(m.f.size(), 4u) << f;
    std::map<std::pair<int, int>, int> edges;
    double volume = 0;
    for (const auto& t : m.f) {
      for (int k = 0; k < 3; ++k) {
        int a = t[k], b = t[(k + 1) % 3];
        ++edges[{std::min(a, b), std::max(a, b)}];
      }
      volume += m.v[t[0]].dot(m.v[t[1]].cross(m.v[t[2]])) / 6;
    }
    for (const auto& [e, count] : edges) {
      ASSERT_EQ(count, 2) << f << " edge " << e.first << "-" << e.second;
    }
    EXPECT_GT(volume, 0.0) << f;
    for (const auto& t : m.f) {
      V3 n = (m.v[t[1]] - m.v[t[0]]).cross(m.v[t[2]] - m.v[t[0]]);
      ASSERT_GT(n.norm(), 0.0) << f << " degenerate triangle";
      n.normalize();
      double worst = -1e30;
      for (const V3& p : m.v) worst = std::max(worst, n.dot(p - m.v[t[0]]));
      ASSERT_LE(worst, 1e-6) << f << " not convex";
    }
  }
  EXPECT_GT(files, 0);
}

TEST(GeneratorTest, EveryCategoryWritesAConsistentFolder) {
  fs::path root = TempDir("all");
  for (const std::string& c : GeneratorCategories()) {
    GeneratedObject o = GenerateObject(c, 0, 0);
    EXPECT_EQ(o.category, c);
    ASSERT_GE(o.links.size(), 2u) << c;
    fs::path dir = root / c / o.model_id;
    WriteObject(o, dir.string());
    CheckFolder(o, dir);
  }
  fs::remove_all(root);
}

/// Objects per category for the sweeping tests: PARTSIM_GENERATOR_TEST_N, default `n`.
int ObjectsPerCategory(int n) {
  const char* env = std::getenv("PARTSIM_GENERATOR_TEST_N");
  return env ? std::max(1, std::atoi(env)) : n;
}

TEST(GeneratorTest, MovingPartsKeepClear) {
  // no two pieces of different links come within 1 mm, at rest or with one joint driven over
  // its range, for a few objects of every category
  const int n = ObjectsPerCategory(3);
  for (const std::string& c : GeneratorCategories()) {
    for (int i = 0; i < n; ++i) {
      GeneratedObject o = GenerateObject(c, i, 7);
      for (const std::string& hit : Collisions(o, 0.001))
        ADD_FAILURE() << "index " << i << ": " << hit;
    }
  }
}

TEST(GeneratorTest, SameSeedSameBytes) {
  fs::path a = TempDir("det_a"), b = TempDir("det_b"), c = TempDir("det_c");
  GeneratorOptions opt;
  opt.categories = {"StorageFurniture", "Faucet", "Bottle", "Keyboard"};
  opt.per_category = 2;
  opt.seed = 42;
  opt.out_dir = a.string();
  EXPECT_EQ(GenerateDataset(opt), 8);
  opt.out_dir = b.string();
  opt.jobs = 2;
  EXPECT_EQ(GenerateDataset(opt), 8);
  // a subset in another order writes the same bytes for the objects it shares
  opt.out_dir = c.string();
  opt.categories = {"Faucet"};
  opt.jobs = 1;
  EXPECT_EQ(GenerateDataset(opt), 2);
  int compared = 0;
  for (const auto& e : fs::recursive_directory_iterator(a)) {
    if (!e.is_regular_file()) continue;
    fs::path rel = fs::relative(e.path(), a);
    ASSERT_TRUE(fs::exists(b / rel)) << rel;
    EXPECT_EQ(ReadFile(e.path()), ReadFile(b / rel)) << rel;
    if (fs::exists(c / rel)) {
      EXPECT_EQ(ReadFile(e.path()), ReadFile(c / rel)) << rel;
      ++compared;
    }
  }
  EXPECT_GT(compared, 0);
  // another seed gives another object
  GeneratedObject o1 = GenerateObject("StorageFurniture", 0, 1),
                  o2 = GenerateObject("StorageFurniture", 0, 2);
  EXPECT_NE(o1.links[0].parts[0].pieces[0].vertices[0], o2.links[0].parts[0].pieces[0].vertices[0]);
  for (const fs::path& p : {a, b, c}) fs::remove_all(p);
}

TEST(GeneratorTest, ObjectsRestStillInAScene) {
  // gravity along the file frame's -y (the reader turns y up into z up)
  fs::path root = TempDir("scene");
  const int n = ObjectsPerCategory(1);
  for (const std::string& c : GeneratorCategories()) {
    for (int i = 0; i < n; ++i) {
      SCOPED_TRACE(c + " " + std::to_string(i));
      GeneratedObject o = GenerateObject(c, i, 0);
      fs::path dir = root / (c + std::to_string(i));
      WriteObject(o, dir.string());
      SceneConfig config;
      config.gravity = V3(0, -9.81, 0);
      Scene scene(config);
      UrdfLoader loader(&scene);
      loader.fix_root_link = true;
      loader.load_multiple_collisions_from_file = true;
      Articulation art = loader.Load((dir / "mobility.urdf").string());
      Eigen::VectorXd q0 = art.GetQpos();
      scene.Step(100);
      Eigen::VectorXd q1 = art.GetQpos();
      ASSERT_EQ(q0.size(), q1.size());
      for (int k = 0; k < q0.size(); ++k) {
        EXPECT_LE(std::abs(q1[k] - q0[k]), 1e-3)
            << art.GetActiveJoints()[k].GetName() << " moved from " << q0[k] << " to " << q1[k];
      }
      fs::remove_all(dir);
    }
  }
  fs::remove_all(root);
}

TEST(GeneratorTest, PartCountsNearThePaper) {
  // links per model (body included, as the paper counts them), over 20 objects per category,
  // within a factor 1.6 of the paper's #P / #M
  for (const std::string& c : GeneratorCategories()) {
    double links = 0;
    const int n = 20;
    for (int i = 0; i < n; ++i) links += GenerateObject(c, i, 3).links.size();
    double ours = links / n, paper = double(PaperPartCount(c)) / PaperModelCount(c);
    EXPECT_GT(ours, paper / 1.6) << c << ": " << ours << " links per model, paper " << paper;
    EXPECT_LT(ours, paper * 1.6) << c << ": " << ours << " links per model, paper " << paper;
  }
}

}  // namespace
}  // namespace partsim
