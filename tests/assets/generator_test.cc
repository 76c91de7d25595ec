// Tests of the procedural object generator: every category generates and writes a
// PartNet-Mobility folder with the real dataset's structure (flat layout, z-up root joint over
// y-up annotations, both label vocabularies, <part>-<id> visuals with one OBJ each, result.json,
// a bounding box centred on the origin) whose files agree with each other and load with no
// warning; meshes are closed, outward-facing, convex and not flat; output is deterministic;
// moving parts keep clear of everything over their range; objects rest still in a scene.
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

#include "partsim/assets/partnet_mobility.h"
#include "partsim/assets/urdf.h"
#include "partsim/core/constants.h"
#include "partsim/core/error.h"
#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using V3 = Eigen::Vector3d;

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

/// Objects per category for the sweeping tests: PARTSIM_GENERATOR_TEST_N, default `n`.
int ObjectsPerCategory(int n) {
  const char* env = std::getenv("PARTSIM_GENERATOR_TEST_N");
  return env ? std::max(1, std::atoi(env)) : n;
}

// ---------------------------------------------------------------------------------------------
// the written folder against the object it came from, and against the real dataset's structure

/// The movable-part vocabulary of semantics.txt (the columns of the SAPIEN paper's tables,
/// written the dataset's way) and the kinds of its joint column.
const std::set<std::string> kMovableLabels = {"rotation_door",
                                              "translation_door",
                                              "drawer",
                                              "rotation_lid",
                                              "translation_lid",
                                              "rotation_handle",
                                              "translation_handle",
                                              "translation_tray",
                                              "rotation_screen",
                                              "screen",
                                              "rotation_bar",
                                              "rotation",
                                              "handle",
                                              "caster",
                                              "wheel",
                                              "seat",
                                              "knob",
                                              "lever",
                                              "button",
                                              "slider",
                                              "switch",
                                              "key",
                                              "leg",
                                              "lens",
                                              "hand",
                                              "spout",
                                              "rotor",
                                              "cap",
                                              "container",
                                              "blade",
                                              "sphere",
                                              "frame",
                                              "head",
                                              "pad",
                                              "window",
                                              "stapler_body"};
const std::set<std::string> kSemanticsKinds = {"hinge", "slider", "slider+",
                                               "free",  "heavy",  "static"};

/// The root joint's rotation in the dataset: rpy (pi/2, 0, -pi/2), F's y up to z, +z to -x.
Eigen::Quaterniond DatasetRootRotation() {
  return Eigen::AngleAxisd(-kPi / 2, V3::UnitZ()) * Eigen::AngleAxisd(kPi / 2, V3::UnitX());
}

/// Poses of the links at q = 0 in the root: X_BL.
std::vector<Pose> RestPoses(const ArticulationDesc& art) {
  std::vector<Pose> X(art.links.size());
  for (size_t i = 0; i < art.links.size(); ++i) {
    const LinkDesc& l = art.links[i];
    X[i] = l.parent < 0 ? Pose()
                        : X[l.parent] * l.joint.pose_in_parent * l.joint.pose_in_child.Inverse();
  }
  return X;
}

V3 Vec(const nlohmann::json& j) {
  return V3(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
}

/// Every node of a result.json tree: leaves have objs and no children, internal nodes children
/// and no objs; collects leaf ids -> (name, objs).
void CollectLeaves(const nlohmann::json& node, std::set<int>* ids,
                   std::map<int, std::pair<std::string, std::set<std::string>>>* leaves) {
  ASSERT_TRUE(node.is_object());
  for (const char* key : {"text", "name", "id"}) ASSERT_TRUE(node.contains(key)) << node.dump();
  EXPECT_TRUE(node["text"].is_string());
  EXPECT_TRUE(node["name"].is_string());
  EXPECT_TRUE(ids->insert(node["id"].get<int>()).second) << "id " << node["id"] << " twice";
  if (node.contains("children")) {
    EXPECT_FALSE(node.contains("objs")) << node["name"];
    ASSERT_FALSE(node["children"].empty()) << node["name"];
    for (const auto& c : node["children"]) CollectLeaves(c, ids, leaves);
    return;
  }
  ASSERT_TRUE(node.contains("objs")) << node["name"];
  std::set<std::string> objs;
  for (const auto& o : node["objs"]) objs.insert(o.get<std::string>());
  (*leaves)[node["id"].get<int>()] = {node["name"].get<std::string>(), objs};
}

/// Checks one written folder against the object it came from.
void CheckFolder(const GeneratedObject& o, const fs::path& dir) {
  SCOPED_TRACE(o.category);
  for (const char* f : {"mobility.urdf", "mobility_v2.json", "semantics.txt", "meta.json",
                        "bounding_box.json", "result.json", "result_after_merging.json"}) {
    ASSERT_TRUE(fs::exists(dir / f)) << f;
  }
  // meta.json: the dataset's keys, string values; the folder is named by anno_id
  nlohmann::json meta = nlohmann::json::parse(ReadFile(dir / "meta.json"));
  for (const char* key : {"model_id", "anno_id", "user_id", "time_in_sec", "version", "model_cat"})
    ASSERT_TRUE(meta.contains(key) && meta[key].is_string()) << key;
  EXPECT_EQ(meta["model_cat"], o.category);
  EXPECT_EQ(meta["model_id"], o.model_id);
  EXPECT_EQ(meta["anno_id"], o.anno_id);
  EXPECT_EQ(o.model_id.size(), 32u);
  EXPECT_EQ(o.model_id.find_first_not_of("0123456789abcdef"), std::string::npos) << o.model_id;
  // bounding box: centred on the origin (to the generator's 0.1 mm grid)
  nlohmann::json bbox = nlohmann::json::parse(ReadFile(dir / "bounding_box.json"));
  const V3 lo = Vec(bbox["min"]), hi = Vec(bbox["max"]);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(lo[k], hi[k]);
    EXPECT_NEAR(lo[k] + hi[k], 0.0, 2.1e-4) << "axis " << k;
  }

  // mobility_v2.json: PartNet names; semantics.txt: movable-part labels and kinds
  nlohmann::json mob = nlohmann::json::parse(ReadFile(dir / "mobility_v2.json"));
  ASSERT_EQ(mob.size(), o.links.size());
  std::istringstream sem(ReadFile(dir / "semantics.txt"));
  int heavy = 0;
  std::set<int> part_ids;
  for (size_t i = 0; i < mob.size(); ++i) {
    const nlohmann::json& e = mob[i];
    const GeneratedLink& l = o.links[i];
    EXPECT_EQ(e["id"].get<int>(), static_cast<int>(i));
    const std::string joint = e["joint"];
    EXPECT_TRUE(joint == "hinge" || joint == "slider" || joint == "heavy" || joint == "static" ||
                joint == "free")
        << joint;
    const bool rotates = joint == "slider" && e["jointData"]["limit"]["rotates"].get<bool>();
    std::string link, kind, label;
    sem >> link >> kind >> label;
    EXPECT_EQ(link, "link_" + std::to_string(i));
    EXPECT_TRUE(kSemanticsKinds.count(kind)) << kind;
    EXPECT_EQ(kind, rotates ? "slider+" : joint) << link;
    EXPECT_EQ(label, l.name) << link;
    EXPECT_EQ(e["name"].get<std::string>(), l.partnet_name) << link;
    if (joint == "heavy") {
      ++heavy;
      EXPECT_EQ(e["parent"].get<int>(), -1);
      EXPECT_FALSE(kMovableLabels.count(label) && label != "leg") << label;
    } else {
      EXPECT_GE(e["parent"].get<int>(), 0) << link << ": only the body hangs from base";
      EXPECT_TRUE(kMovableLabels.count(label)) << link << " '" << label << "'";
    }
    EXPECT_LT(e["parent"].get<int>(), static_cast<int>(i));
    for (const auto& p : e["parts"]) EXPECT_TRUE(part_ids.insert(p["id"].get<int>()).second);
  }
  EXPECT_EQ(heavy, 1);

  // mobility.urdf: base -> body turned z-up as the dataset does, everything below in F
  UrdfLoader loader;
  ArticulationDesc art = loader.ParseFile((dir / "mobility.urdf").string());
  EXPECT_TRUE(loader.LastReport().Empty()) << loader.LastReport().ToString();
  std::map<std::string, int> index;
  for (size_t i = 0; i < art.links.size(); ++i) index[art.links[i].name] = static_cast<int>(i);
  ASSERT_TRUE(index.count("base"));
  const LinkDesc& base = art.links[index["base"]];
  EXPECT_LT(base.parent, 0);
  EXPECT_TRUE(base.visuals.empty() && base.collisions.empty());
  std::vector<Pose> X = RestPoses(art);
  int body = -1;
  for (size_t i = 0; i < art.links.size(); ++i) {
    if (art.links[i].parent != index["base"]) continue;
    EXPECT_EQ(body, -1) << "base has a second child " << art.links[i].name;
    body = static_cast<int>(i);
  }
  ASSERT_GE(body, 0);
  EXPECT_EQ(art.links[body].joint.type, JointType::kFixed);
  EXPECT_LT(X[body].p.norm(), 1e-9);
  EXPECT_NEAR(std::abs(X[body].q.dot(DatasetRootRotation())), 1.0, 1e-9);
  const Pose X_FB = X[body].Inverse();
  // every joint_N has child link_N (a rotating slider: the turn; its slide comes after the
  // links); every link is link_N or link_N_helper
  std::map<std::string, std::string> joint_child;
  for (const LinkDesc& l : art.links)
    if (l.parent >= 0) joint_child[l.joint.name] = l.name;
  for (size_t i = 0; i < o.links.size(); ++i)
    EXPECT_EQ(joint_child["joint_" + std::to_string(i)], "link_" + std::to_string(i));
  std::set<std::string> files_in_urdf;
  std::map<int, std::set<std::string>> part_files;  // part id -> OBJ names of its visuals
  for (size_t i = 0; i < mob.size(); ++i) {
    const nlohmann::json& e = mob[i];
    const std::string name = "link_" + std::to_string(i);
    ASSERT_TRUE(index.count(name)) << name;
    const LinkDesc& l = art.links[index[name]];
    const Pose X_FL = X_FB * X[index[name]];
    // visuals <part>-<id>, one OBJ each, the same files as collisions, all in F
    EXPECT_EQ(l.collisions.size(), l.visuals.size()) << name;
    std::set<std::string> visual_names;
    for (const VisualShape& v : l.visuals) {
      visual_names.insert(v.name);
      ASSERT_TRUE(v.mesh) << name << " " << v.name;
      const std::string file = fs::path(v.mesh->source).stem().string();
      EXPECT_TRUE(files_in_urdf.insert(file).second) << file << " in two visuals";
      const size_t dash = v.name.rfind('-');
      ASSERT_NE(dash, std::string::npos) << v.name;
      part_files[std::stoi(v.name.substr(dash + 1))].insert(file);
      const Pose X_FV = X_FL * v.pose;
      EXPECT_LT(X_FV.p.norm(), 1e-6) << name << " " << v.name << " is not in F";
      EXPECT_NEAR(std::abs(X_FV.q.w()), 1.0, 1e-9) << name << " " << v.name;
    }
    for (const CollisionShape& c : l.collisions) {
      ASSERT_TRUE(c.mesh) << name;
      EXPECT_TRUE(files_in_urdf.count(fs::path(c.mesh->source).stem().string())) << name;
      EXPECT_LT((X_FL * c.pose).p.norm(), 1e-6) << name;
    }
    for (const auto& p : e["parts"]) {
      std::string want = p["name"].get<std::string>() + "-" + std::to_string(p["id"].get<int>());
      EXPECT_TRUE(visual_names.count(want)) << name << " lacks visual " << want;
    }
    const std::string joint = e["joint"];
    if (joint != "hinge" && joint != "slider") {
      EXPECT_EQ(l.joint.type, JointType::kFixed) << name;
      EXPECT_TRUE(e["jointData"].empty()) << name;
      continue;
    }
    const nlohmann::json& lim = e["jointData"]["limit"];
    const bool rotates = joint == "slider" && lim["rotates"].get<bool>();
    // a rotating slider: prismatic to link_N_helper, then the turn about the same axis
    const int motion = rotates ? l.parent : index[name];
    const LinkDesc& moving = art.links[motion];
    if (rotates) {
      EXPECT_EQ(moving.name, name + "_helper");
      EXPECT_TRUE(moving.visuals.empty() && moving.collisions.empty());
      EXPECT_EQ(l.joint.type,
                lim["noRotationLimit"].get<bool>() ? JointType::kContinuous : JointType::kRevolute);
    }
    const std::string parent =
        e["parent"].get<int>() < 0 ? "base" : "link_" + std::to_string(e["parent"].get<int>());
    EXPECT_EQ(art.links[moving.parent].name, parent) << name;
    if (joint == "hinge") {
      const bool no_limit = lim["noLimit"].get<bool>();
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
    }
    // the joint frame sits at the JSON axis origin, its x axis along the JSON direction (in F)
    const Pose X_FJ = X_FB * X[moving.parent] * moving.joint.pose_in_parent;
    const V3 dir = Vec(e["jointData"]["axis"]["direction"]).normalized();
    EXPECT_NEAR(std::abs((X_FJ.q * V3::UnitX()).dot(dir)), 1.0, 1e-6) << name;
    EXPECT_LT((X_FJ.p - Vec(e["jointData"]["axis"]["origin"])).norm(), 2e-6) << name;
  }
  // links are link_N and link_N_helper only
  for (const LinkDesc& l : art.links) {
    if (l.name == "base") continue;
    std::string n = l.name;
    if (n.size() > 7 && n.compare(n.size() - 7, 7, "_helper") == 0) n.resize(n.size() - 7);
    EXPECT_EQ(n.rfind("link_", 0), 0u) << l.name;
    EXPECT_LT(std::stoul(n.substr(5)), o.links.size()) << l.name;
  }

  // result.json: the PartNet part hierarchy, leaves = the parts of mobility_v2.json with the
  // OBJ files of their visuals
  nlohmann::json result = nlohmann::json::parse(ReadFile(dir / "result.json"));
  ASSERT_TRUE(result.is_array());
  ASSERT_EQ(result.size(), 1u);
  EXPECT_EQ(result[0]["id"], 0);
  EXPECT_EQ(result[0]["text"], o.category);
  std::set<int> ids;
  std::map<int, std::pair<std::string, std::set<std::string>>> leaves;
  CollectLeaves(result[0], &ids, &leaves);
  EXPECT_EQ(leaves.size(), part_ids.size());
  std::set<std::string> leaf_files;
  for (const auto& e : mob) {
    for (const auto& p : e["parts"]) {
      const int id = p["id"].get<int>();
      ASSERT_TRUE(leaves.count(id)) << "part " << id << " is no leaf of result.json";
      EXPECT_EQ(leaves[id].first, p["name"].get<std::string>());
      EXPECT_EQ(leaves[id].second, part_files[id]) << "part " << id;
      leaf_files.insert(leaves[id].second.begin(), leaves[id].second.end());
    }
  }
  EXPECT_EQ(leaf_files, files_in_urdf);
  nlohmann::json merged = nlohmann::json::parse(ReadFile(dir / "result_after_merging.json"));
  ASSERT_TRUE(merged.is_array() && merged.size() == 1u);
  EXPECT_EQ(merged[0]["objs"].size(), files_in_urdf.size());
  EXPECT_EQ(merged[0]["ori_id"], 0);

  // meshes: every OBJ closed, outward and convex, a plate at least 0.5 mm thick (no flat pieces)
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir / "textured_objs")) {
    if (entry.path().extension() != ".obj") continue;
    ++files;
    EXPECT_TRUE(fs::exists(fs::path(entry.path()).replace_extension(".mtl")));
    ObjMesh m = ReadObj(entry.path());
    std::string f = entry.path().filename().string();
    EXPECT_TRUE(files_in_urdf.count(entry.path().stem().string())) << f << " is not used";
    ASSERT_GE(m.v.size(), 4u) << f;
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
    double thickness = 1e30;
    for (const auto& t : m.f) {
      V3 n = (m.v[t[1]] - m.v[t[0]]).cross(m.v[t[2]] - m.v[t[0]]);
      ASSERT_GT(n.norm(), 0.0) << f << " degenerate triangle";
      n.normalize();
      double worst = -1e30, depth = 1e30;
      for (const V3& p : m.v) {
        worst = std::max(worst, n.dot(p - m.v[t[0]]));
        depth = std::min(depth, n.dot(p - m.v[t[0]]));
      }
      ASSERT_LE(worst, 1e-6) << f << " not convex";
      thickness = std::min(thickness, -depth);
    }
    EXPECT_GE(thickness, 0.0005 - 1e-9) << f << " is a flat piece";
  }
  EXPECT_EQ(files, static_cast<int>(files_in_urdf.size()));

  // partsim's reader takes it with no warning, even strict, with both vocabularies
  PartNetMobilityLoader reader;
  reader.strict = true;
  PartNetMobilityObject obj = reader.Parse(dir.string());
  EXPECT_TRUE(obj.report.Empty()) << obj.report.ToString();
  EXPECT_EQ(obj.category, o.category);
  ASSERT_EQ(obj.links.size(), o.links.size());
  for (const GeneratedLink& l : o.links) {
    EXPECT_EQ(obj.Link(l.id).semantic_label, l.name);
    EXPECT_EQ(obj.Link(l.id).partnet_name, l.partnet_name);
  }
}

TEST(GeneratorTest, EveryCategoryWritesAConsistentFolder) {
  fs::path root = TempDir("all");
  for (const std::string& c : GeneratorCategories()) {
    GeneratedObject o = GenerateObject(c, 0, 0);
    EXPECT_EQ(o.category, c);
    ASSERT_GE(o.links.size(), 2u) << c;
    fs::path dir = root / o.anno_id;
    WriteObject(o, dir.string());
    CheckFolder(o, dir);
  }
  fs::remove_all(root);
}

TEST(GeneratorTest, FoldersHoldWhatTheRealDatasetHolds) {
  // the same files, keys and root joint as the real object in ../shared/realdata
  const fs::path real =
      fs::path(PARTSIM_SOURCE_DIR) / ".." / "shared" / "realdata" / "partnet-mobility-3763";
  if (!fs::exists(real / "mobility.urdf")) GTEST_SKIP() << "no " << real;
  fs::path dir = TempDir("like_real");
  GeneratedObject o = GenerateObject("Bottle", 0, 0);
  WriteObject(o, dir.string());
  for (const char* f : {"mobility.urdf", "mobility_v2.json", "semantics.txt", "meta.json",
                        "bounding_box.json", "result.json", "result_after_merging.json"}) {
    EXPECT_TRUE(fs::exists(real / f)) << f;
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  }
  auto keys = [](const nlohmann::json& j) {
    std::set<std::string> k;
    for (const auto& [key, value] : j.items()) k.insert(key);
    return k;
  };
  // meta.json: every key of the real one
  nlohmann::json rm = nlohmann::json::parse(ReadFile(real / "meta.json"));
  nlohmann::json gm = nlohmann::json::parse(ReadFile(dir / "meta.json"));
  for (const std::string& k : keys(rm)) EXPECT_TRUE(gm.contains(k)) << k;
  // mobility_v2.json: the same keys per entry and in jointData
  nlohmann::json rj = nlohmann::json::parse(ReadFile(real / "mobility_v2.json"));
  nlohmann::json gj = nlohmann::json::parse(ReadFile(dir / "mobility_v2.json"));
  EXPECT_EQ(keys(gj[0]), keys(rj[0]));
  EXPECT_EQ(keys(gj[1]["jointData"]), keys(rj[0]["jointData"]));
  EXPECT_EQ(keys(gj[1]["jointData"]["axis"]), keys(rj[0]["jointData"]["axis"]));
  EXPECT_EQ(keys(gj[0]["parts"][0]), keys(rj[0]["parts"][0]));
  // result.json and result_after_merging.json: the same keys on the root, internal nodes and
  // leaves
  for (const char* f : {"result.json", "result_after_merging.json"}) {
    nlohmann::json r = nlohmann::json::parse(ReadFile(real / f));
    nlohmann::json g = nlohmann::json::parse(ReadFile(dir / f));
    EXPECT_EQ(keys(g[0]), keys(r[0])) << f;
    EXPECT_EQ(keys(g[0]["children"][0]), keys(r[0]["children"][0]["children"][0])) << f;
  }
  // mobility.urdf: the same rotation from base to the body
  UrdfLoader loader;
  for (const fs::path& d : {real, dir}) {
    ArticulationDesc art = loader.ParseFile((d / "mobility.urdf").string());
    std::vector<Pose> X = RestPoses(art);
    int children = 0;
    for (size_t i = 0; i < art.links.size(); ++i) {
      if (art.links[i].parent != 0) continue;
      ++children;
      EXPECT_EQ(art.links[i].joint.type, JointType::kFixed) << d;
      EXPECT_NEAR(std::abs(X[i].q.dot(DatasetRootRotation())), 1.0, 1e-9) << d;
    }
    EXPECT_EQ(children, 1) << d;
  }
  fs::remove_all(dir);
}

TEST(GeneratorTest, LinksCarryBothVocabularies) {
  // semantics labels from the movable-part vocabulary, PartNet names beside them; where the
  // dataset's two names differ, the generator's do too
  std::map<std::string, std::set<std::string>> names_of;  // label -> PartNet names
  for (const std::string& c : GeneratorCategories()) {
    for (int i = 0; i < ObjectsPerCategory(8); ++i) {
      GeneratedObject o = GenerateObject(c, i, 11);
      for (const GeneratedLink& l : o.links) {
        EXPECT_FALSE(l.partnet_name.empty()) << c << " link_" << l.id;
        names_of[l.name].insert(l.partnet_name);
        if (l.parent < 0) continue;
        EXPECT_TRUE(kMovableLabels.count(l.name)) << c << " '" << l.name << "'";
        // the motion prefix follows the motion
        if (l.name.rfind("translation_", 0) == 0) EXPECT_TRUE(l.joint == "slider" && !l.rotates);
        if (l.name.rfind("rotation_", 0) == 0) EXPECT_TRUE(l.joint == "hinge" || l.rotates);
      }
    }
  }
  EXPECT_EQ(names_of["drawer"], std::set<std::string>{"drawer"});
  EXPECT_TRUE(names_of["rotation_door"].count("cabinet_door"));
  EXPECT_TRUE(names_of["rotation_door"].count("door"));
  EXPECT_EQ(names_of["rotation_lid"].count("lid"), 1u);
  EXPECT_EQ(names_of["translation_lid"].count("lid"), 1u);
  EXPECT_EQ(names_of["furniture_body"], (std::set<std::string>{"cabinet_frame", "table_frame"}));
  EXPECT_EQ(names_of["bottle_body"], std::set<std::string>{"body"});
  // the bottle's screw cap is a slider that also turns, labelled as the dataset's
  int screw = 0;
  for (int i = 0; i < 12; ++i) {
    for (const GeneratedLink& l : GenerateObject("Bottle", i, 0).links) {
      if (!l.rotates) continue;
      ++screw;
      EXPECT_EQ(l.name, "rotation_lid");
      EXPECT_EQ(l.partnet_name, "lid");
    }
  }
  EXPECT_GT(screw, 0);
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
  // the dataset's flat layout: one folder per object named by its anno_id, the category in
  // meta.json; unique ids across categories
  std::set<std::string> categories;
  int folders = 0;
  for (const auto& e : fs::directory_iterator(a)) {
    ++folders;
    const std::string id = e.path().filename().string();
    EXPECT_EQ(id.find_first_not_of("0123456789"), std::string::npos) << id;
    nlohmann::json meta = nlohmann::json::parse(ReadFile(e.path() / "meta.json"));
    EXPECT_EQ(meta["anno_id"], id);
    categories.insert(meta["model_cat"].get<std::string>());
  }
  EXPECT_EQ(folders, 8);
  EXPECT_EQ(categories.size(), 4u);
  // the old layout on request: <out>/<category>/<anno_id>/, same bytes
  fs::path d = TempDir("det_d");
  opt.out_dir = d.string();
  opt.by_category = true;
  EXPECT_EQ(GenerateDataset(opt), 2);
  GeneratedObject faucet = GenerateObject("Faucet", 1, 42);
  EXPECT_EQ(ReadFile(d / "Faucet" / faucet.anno_id / "mobility.urdf"),
            ReadFile(a / faucet.anno_id / "mobility.urdf"));
  // ids: anno_id from (category, index), model_id from the seed as well
  EXPECT_EQ(GenerateObject("Faucet", 1, 7).anno_id, faucet.anno_id);
  EXPECT_NE(GenerateObject("Faucet", 1, 7).model_id, faucet.model_id);
  EXPECT_NE(GenerateObject("Faucet", 2, 42).anno_id, faucet.anno_id);
  EXPECT_NE(GenerateObject("Knife", 1, 42).anno_id, faucet.anno_id);
  fs::remove_all(d);
  // another seed gives another object
  GeneratedObject o1 = GenerateObject("StorageFurniture", 0, 1),
                  o2 = GenerateObject("StorageFurniture", 0, 2);
  EXPECT_NE(o1.links[0].parts[0].pieces[0].vertices[0], o2.links[0].parts[0].pieces[0].vertices[0]);
  for (const fs::path& p : {a, b, c}) fs::remove_all(p);
}

TEST(GeneratorTest, ObjectsLoadWithoutWarningAndRestStillInAScene) {
  // through partsim's reader, strict: any warning would be an error; mobility.urdf turns the file
  // frame's y up into the world's z up, so gravity is along world -z
  fs::path root = TempDir("scene");
  const int n = ObjectsPerCategory(1);
  for (const std::string& c : GeneratorCategories()) {
    for (int i = 0; i < n; ++i) {
      SCOPED_TRACE(c + " " + std::to_string(i));
      GeneratedObject o = GenerateObject(c, i, 0);
      fs::path dir = root / o.anno_id;
      WriteObject(o, dir.string());
      Scene scene;
      PartNetMobilityLoader loader(&scene);
      loader.strict = true;
      loader.urdf.fix_root_link = true;
      loader.urdf.load_multiple_collisions_from_file = true;
      Articulation art = loader.Load(dir.string());
      EXPECT_TRUE(loader.LastReport().Empty()) << loader.LastReport().ToString();
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
