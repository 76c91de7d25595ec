// Tests of the annotation procedure (docs/annotation.md) on generated objects of every category:
// each object written in the unannotated form is annotated by answering the questions from the
// generator's ground truth; the export matches that truth (joint types and parents exact, axes
// and limits as written) and loads with the strict PartNet-Mobility loader; the number of
// questions equals the minimum the procedure needs, counted here from the truth; answers that
// contradict earlier ones, or would break the tree, are refused and change nothing; undo and the
// saved session replay to the same question; hostile inputs get an error naming what is wrong.
#include "partsim/assets/annotation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "partsim/assets/generator.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/core/constants.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("partsim_annotation_test_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

void WriteText(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

std::string ReadText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The generator's answer to an object: each part's rigid link (a "static" link is fixed to its
/// parent, so it is the same rigid body), and the joints between rigid links.
struct Truth {
  const GeneratedObject* object = nullptr;
  std::map<int, int> rigid_of_part;  ///< part id -> id of the rigid link's top link
  std::map<int, int> rigid_of_link;  ///< link id -> the same

  explicit Truth(const GeneratedObject& o) : object(&o) {
    for (const GeneratedLink& l : o.links) {
      int top = l.id;
      while (o.links[top].joint == "static" && o.links[top].parent >= 0) top = o.links[top].parent;
      rigid_of_link[l.id] = top;
      for (const GeneratedPart& p : l.parts) rigid_of_part[p.id] = top;
    }
  }
  std::set<int> RigidOf(const AnnotationInput& in, int node_index) const {
    std::set<int> r;
    for (int leaf : in.Leaves(node_index)) r.insert(rigid_of_part.at(in.nodes[leaf].id));
    return r;
  }
  /// The link of `session` holding the parts of rigid link `rigid`.
  static int CurrentLink(const AnnotationSession& s, const Truth& t, int rigid) {
    for (const AnnotationLink& l : s.Links())
      if (t.rigid_of_part.at(s.Input().nodes[l.leaves[0]].id) == rigid) return l.id;
    return -1;
  }
};

/// The answer the truth gives to the session's question.
AnnotationAnswer Oracle(const AnnotationSession& s, const Truth& t) {
  const AnnotationInput& in = s.Input();
  const AnnotationQuestion& q = s.Question();
  AnnotationAnswer a;
  a.index = q.index;
  switch (q.phase) {
    case AnnotationPhase::kMotion:
      a.moves = t.RigidOf(in, in.Index(q.node)).size() > 1;
      return a;
    case AnnotationPhase::kFixed: {
      std::map<int, std::vector<int>> by_rigid;
      for (const AnnotationLink& l : s.Links())
        by_rigid[t.rigid_of_part.at(in.nodes[l.leaves[0]].id)].push_back(l.id);
      for (const auto& [rigid, links] : by_rigid)
        if (links.size() > 1) {
          a.links = links;
          return a;
        }
      a.none = true;
      return a;
    }
    case AnnotationPhase::kHinge:
    case AnnotationPhase::kSlider: {
      const std::string kind = q.phase == AnnotationPhase::kHinge ? "hinge" : "slider";
      for (const GeneratedLink& l : t.object->links) {
        if (l.joint != kind) continue;
        const int child = Truth::CurrentLink(s, t, t.rigid_of_link.at(l.id));
        if (s.Link(child).parent >= 0) continue;
        a.child = child;
        a.parent = Truth::CurrentLink(s, t, t.rigid_of_link.at(l.parent));
        a.origin = l.axis_origin;
        a.direction = l.axis_direction;
        a.lower = l.limit_a;
        a.upper = l.limit_b;
        a.no_limit = l.no_limit;
        a.rotates = l.rotates;
        a.rotation_limit = l.rotation_limit;
        a.no_rotation_limit = l.no_rotation_limit;
        return a;
      }
      a.none = true;
      return a;
    }
    case AnnotationPhase::kRoot: {
      const int rigid = t.rigid_of_part.at(in.nodes[s.Link(q.link).leaves[0]].id);
      a.kind = t.object->links[rigid].joint == "free" ? "free" : "fixed";
      return a;
    }
    case AnnotationPhase::kDone:
      break;
  }
  ADD_FAILURE() << "no question to answer";
  return a;
}

/// The fewest questions the procedure asks for this object, counted from the truth alone.
int MinimumQuestions(const AnnotationInput& in, const Truth& t) {
  int n = 0;
  // 1. each node reached whose subtree is not a chain down to one leaf; below it when it moves
  std::vector<int> moving;
  std::function<void(int)> visit = [&](int i) {
    int m = i;
    while (in.nodes[m].children.size() == 1) m = in.nodes[m].children[0];
    if (in.nodes[m].children.empty()) return;
    ++n;
    if (t.RigidOf(in, m).size() > 1) {
      moving.push_back(m);
      for (int c : in.nodes[m].children) visit(c);
    }
  };
  std::set<int> rigid;
  for (const auto& [part, r] : t.rigid_of_part) rigid.insert(r);
  int units = 0;
  std::function<void(int)> count_units = [&](int i) {
    int m = i;
    while (in.nodes[m].children.size() == 1) m = in.nodes[m].children[0];
    if (in.nodes[m].children.empty() || t.RigidOf(in, m).size() == 1) {
      ++units;
      return;
    }
    for (int c : in.nodes[m].children) count_units(c);
  };
  for (int r : in.roots) {
    visit(r);
    count_units(r);
  }
  // 2. one merge per rigid link made of several units, then "none" unless no merge is left:
  // with two rigid links, a moving node holding both forbids the only merge
  const int links = static_cast<int>(rigid.size());
  std::map<int, int> units_of_rigid;
  std::function<void(int)> unit_rigids = [&](int i) {
    int m = i;
    while (in.nodes[m].children.size() == 1) m = in.nodes[m].children[0];
    if (in.nodes[m].children.empty() || t.RigidOf(in, m).size() == 1) {
      ++units_of_rigid[*t.RigidOf(in, m).begin()];
      return;
    }
    for (int c : in.nodes[m].children) unit_rigids(c);
  };
  for (int r : in.roots) unit_rigids(r);
  for (const auto& [r, k] : units_of_rigid) n += k > 1;
  bool merge_left = links > 2 || (links == 2 && moving.empty());
  if (units > 1 && merge_left) ++n;
  // 3. and 4. one question per joint; "none" for hinges only when sliders remain after them
  int hinges = 0, sliders = 0;
  for (const GeneratedLink& l : t.object->links) {
    hinges += l.joint == "hinge";
    sliders += l.joint == "slider";
  }
  n += hinges + sliders + (sliders > 0 ? 1 : 0);
  // 5. one root
  return n + 1;
}

struct Annotated {
  std::shared_ptr<AnnotationInput> input;
  int questions = 0;
};

/// Writes object `o` unannotated into `dir`/task, annotates it from the truth, exports it into
/// `dir`/object.
Annotated AnnotateFromTruth(const GeneratedObject& o, const fs::path& dir) {
  WriteUnannotatedObject(o, (dir / "task").string());
  Annotated r;
  r.input = std::make_shared<AnnotationInput>(ReadAnnotationInput((dir / "task").string()));
  AnnotationSession s(r.input);
  const Truth t(o);
  while (!s.Done() && r.questions < 1000) {
    s.Answer(Oracle(s, t));
    ++r.questions;
  }
  ExportAnnotation(s, (dir / "object").string());
  return r;
}

TEST(AnnotationTest, EveryCategoryAnnotatedFromItsTruthExportsTheTruth) {
  const fs::path root = TempDir("all");
  int hinges = 0, sliders = 0, screws = 0, named = 0;
  for (const std::string& category : GeneratorCategories()) {
    SCOPED_TRACE(category);
    const GeneratedObject o = GenerateObject(category, 0, 7);
    const fs::path dir = root / category;
    const Annotated a = AnnotateFromTruth(o, dir);
    const Truth t(o);
    EXPECT_EQ(a.questions, MinimumQuestions(*a.input, t));

    // the export loads strictly; its links are the truth's rigid links, with the same joints
    PartNetMobilityLoader loader;
    loader.strict = true;
    PartNetMobilityObject got;
    ASSERT_NO_THROW(got = loader.Parse((dir / "object").string()));
    EXPECT_EQ(got.category, category);
    std::map<int, const PartNetLink*> by_rigid;  // rigid link id -> exported link
    for (const PartNetLink& l : got.links) {
      std::set<int> rigid;
      for (const PartNetPart& p : l.parts) rigid.insert(t.rigid_of_part.at(p.id));
      ASSERT_EQ(rigid.size(), 1u) << "link_" << l.id << " mixes rigid bodies";
      by_rigid[*rigid.begin()] = &l;
    }
    std::set<int> rigid_links;
    for (const auto& [part, r] : t.rigid_of_part) rigid_links.insert(r);
    EXPECT_EQ(by_rigid.size(), rigid_links.size());
    for (const GeneratedLink& l : o.links) {
      if (t.rigid_of_link.at(l.id) != l.id) continue;  // a static link: merged into its parent
      ASSERT_TRUE(by_rigid.count(l.id));
      const PartNetLink& e = *by_rigid.at(l.id);
      std::set<int> want_parts, got_parts;
      for (const GeneratedLink& m : o.links)
        if (t.rigid_of_link.at(m.id) == l.id)
          for (const GeneratedPart& p : m.parts) want_parts.insert(p.id);
      for (const PartNetPart& p : e.parts) got_parts.insert(p.id);
      EXPECT_EQ(got_parts, want_parts);
      EXPECT_EQ(e.joint, l.joint) << "link_" << e.id;
      if (e.partnet_name == l.partnet_name) {  // a link named as the generator names it
        ++named;
        EXPECT_EQ(e.semantic_label, l.name);  // "drawer", "rotation_door": what tasks look for
      }
      if (l.parent < 0) {
        EXPECT_EQ(e.parent, -1);
        continue;
      }
      ASSERT_GE(e.parent, 0);
      EXPECT_EQ(e.parent, by_rigid.at(t.rigid_of_link.at(l.parent))->id);
      if (l.joint != "hinge" && l.joint != "slider") continue;
      hinges += l.joint == "hinge";
      sliders += l.joint == "slider";
      screws += l.rotates;
      EXPECT_LT(std::acos(std::min(1.0, e.axis_direction.dot(l.axis_direction))), kPi / 180);
      EXPECT_LT((e.axis_origin - l.axis_origin).norm(), 1e-6);
      EXPECT_EQ(e.no_limit, l.no_limit);
      if (!l.no_limit) {  // the loader reads no numbers for a hinge without limit
        EXPECT_NEAR(e.limit_a, l.limit_a, 1e-6);
        EXPECT_NEAR(e.limit_b, l.limit_b, 1e-6);
      }
      EXPECT_EQ(e.rotates, l.rotates);
      EXPECT_NEAR(e.rotation_limit, l.rotation_limit, 1e-6);
    }
    // the part hierarchy and the meshes are the input's
    EXPECT_EQ(ReadText(dir / "object" / "result.json"), ReadText(dir / "task" / "result.json"));
  }
  // the movable-part vocabulary comes back for links the input names as the dataset does
  EXPECT_GT(named, 100);
  // the categories cover every kind of joint
  EXPECT_GT(hinges, 20);
  EXPECT_GT(sliders, 5);
  EXPECT_GT(screws, 0);
}

/// A three-level tree by hand: root -> {body group (two leaves), drawer group (front, handle),
/// door}; the drawer is a slider on the body, the door a hinge.
std::shared_ptr<AnnotationInput> HandTree(const fs::path& dir) {
  fs::create_directories(dir / "objs");
  const char* box =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
      "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\n"
      "f 4 1 5\nf 4 5 8\n";
  for (const char* n : {"a", "b", "c", "d", "e"})
    WriteText(dir / "objs" / (std::string(n) + ".obj"), box);
  WriteText(dir / "result.json",
            R"([{"text": "Cabinet", "name": "cabinet", "id": 0, "children": [
                 {"text": "Body", "name": "body", "id": 1, "children": [
                   {"text": "Top", "name": "top", "id": 2, "objs": ["a"]},
                   {"text": "Side", "name": "side", "id": 3, "objs": ["b"]}]},
                 {"text": "Drawer", "name": "drawer", "id": 4, "children": [
                   {"text": "Front", "name": "drawer_front", "id": 5, "objs": ["c"]},
                   {"text": "Handle", "name": "handle", "id": 6, "objs": ["d"]}]},
                 {"text": "Door", "name": "door", "id": 7, "objs": ["e"]}]}])");
  return std::make_shared<AnnotationInput>(ReadAnnotationInput(dir.string()));
}

AnnotationAnswer Answer(int index) {
  AnnotationAnswer a;
  a.index = index;
  return a;
}

/// A joint's answer: `parent` to `child` about `direction`, over [lower, upper].
AnnotationAnswer JointAnswer(int index, int parent, int child, double lower, double upper,
                             const Eigen::Vector3d& direction = Eigen::Vector3d::UnitY()) {
  AnnotationAnswer a = Answer(index);
  a.parent = parent;
  a.child = child;
  a.lower = lower;
  a.upper = upper;
  a.direction = direction;
  return a;
}

TEST(AnnotationTest, RefusedAnswersChangeNothingAndUndoReplays) {
  const fs::path dir = TempDir("hand");
  auto in = HandTree(dir / "in");
  AnnotationSession s(in);
  // the root moves; the body does not (one unit); the drawer's parts move? the answer "yes" here
  // makes its two parts separate units
  EXPECT_EQ(s.Question().phase, AnnotationPhase::kMotion);
  EXPECT_EQ(s.Question().node, 0);
  AnnotationAnswer a = Answer(0);
  a.moves = true;
  s.Answer(a);
  EXPECT_EQ(s.Question().node, 1);
  s.Answer(Answer(1));  // body: no
  EXPECT_EQ(s.Question().node, 4);
  a = Answer(2);
  a.moves = true;
  s.Answer(a);  // drawer: its front and handle move (a wrong answer, undone below)
  EXPECT_EQ(s.Question().phase, AnnotationPhase::kFixed);
  EXPECT_EQ(s.Links().size(), 4u);  // body, front, handle, door

  // a merge of front and handle contradicts "the drawer moves": refused, nothing changes
  AnnotationAnswer merge = Answer(3);
  merge.links = {5, 6};
  const std::string before = s.StateJson();
  try {
    s.Answer(merge);
    FAIL() << "the merge was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("Drawer"), std::string::npos) << e.what();
  }
  EXPECT_EQ(s.StateJson(), before);
  // an answer to another question is refused
  AnnotationAnswer stale = Answer(1);
  stale.none = true;
  EXPECT_THROW(s.Answer(stale), Error);
  EXPECT_EQ(s.StateJson(), before);

  // undo the drawer's answer: the same question comes back; answer it "no"
  ASSERT_TRUE(s.Undo());
  EXPECT_EQ(s.Question().node, 4);
  EXPECT_EQ(s.Question().index, 2);
  s.Answer(Answer(2));
  // three links: no merge is refused, so the fixed step asks once
  ASSERT_EQ(s.Question().phase, AnnotationPhase::kFixed);
  AnnotationAnswer none = Answer(3);
  none.none = true;
  s.Answer(none);
  ASSERT_EQ(s.Question().phase, AnnotationPhase::kHinge);
  // a hinge with the body as child of the door, then one closing a loop
  s.Answer(JointAnswer(4, 1, 7, 0, 90, Eigen::Vector3d(0, 2, 0)));
  EXPECT_EQ(s.Link(7).parent, 1);
  EXPECT_NEAR(s.Link(7).direction.norm(), 1.0, 1e-12);
  EXPECT_THROW(s.Answer(JointAnswer(5, 7, 1, 0, 1)),
               Error);  // the body hangs nowhere, but the door hangs on it
  EXPECT_THROW(s.Answer(JointAnswer(5, 4, 7, 0, 1)), Error);  // the door has a parent already
  EXPECT_THROW(s.Answer(JointAnswer(5, 1, 4, 1, 0)), Error);  // lower above upper
  EXPECT_THROW(s.Answer(JointAnswer(5, 1, 4, 0, 1, Eigen::Vector3d::Zero())), Error);  // no axis
  // "none" hinges; the drawer slides; one tree now: no "none" slider question, the root next
  AnnotationAnswer no_more = Answer(5);
  no_more.none = true;
  s.Answer(no_more);
  ASSERT_EQ(s.Question().phase, AnnotationPhase::kSlider);
  s.Answer(JointAnswer(6, 1, 4, 0, 0.3, Eigen::Vector3d(0, 0, 1)));
  ASSERT_EQ(s.Question().phase, AnnotationPhase::kRoot);
  EXPECT_EQ(s.Question().link, 1);
  AnnotationAnswer root = Answer(7);
  root.kind = "nailed";
  EXPECT_THROW(s.Answer(root), Error);
  root.kind = "fixed";
  s.Answer(root);
  EXPECT_TRUE(s.Done());
  EXPECT_EQ(s.Answers().size(), 8u);

  // the JSON forms round-trip
  for (const AnnotationAnswer& x : s.Answers()) {
    const AnnotationAnswer y = AnnotationAnswerFromJson(AnnotationAnswerToJson(x));
    EXPECT_EQ(AnnotationAnswerToJson(y), AnnotationAnswerToJson(x));
  }
  EXPECT_THROW(AnnotationAnswerFromJson("{\"moves\": true}"), Error);             // no index
  EXPECT_THROW(AnnotationAnswerFromJson("{\"index\": 0, \"moves\": 1}"), Error);  // not a bool
  EXPECT_THROW(AnnotationAnswerFromJson("{\"index\": 0, \"origin\": [1, 2]}"), Error);

  // reviews: of joints only; export
  EXPECT_THROW(s.Review({1, true, ""}), Error);  // the body has no joint
  s.Review({7, true, ""});
  s.Review({4, false, "the drawer slides the wrong way"});
  s.Review({7, false, "changed my mind"});
  ASSERT_EQ(s.Reviews().size(), 2u);
  EXPECT_FALSE(s.Reviews()[0].accept);
  ExportAnnotation(s, (dir / "object").string());
  PartNetMobilityLoader loader;
  loader.strict = true;
  const PartNetMobilityObject o = loader.Parse((dir / "object").string());
  ASSERT_EQ(o.links.size(), 3u);
  EXPECT_EQ(o.links[0].joint, "heavy");
  EXPECT_EQ(o.links[1].joint, "slider");  // pre-order: the drawer (node 4) before the door (7)
  EXPECT_EQ(o.links[2].joint, "hinge");
  // the reviews go with the export, named by the exported links
  const std::string meta = ReadText(dir / "object" / "meta.json");
  EXPECT_NE(
      meta.find(R"({"accept":false,"comment":"the drawer slides the wrong way","link":"link_1"})"),
      std::string::npos)
      << meta;
  EXPECT_NE(meta.find(R"({"accept":false,"comment":"changed my mind","link":"link_2"})"),
            std::string::npos)
      << meta;
  // a second export replaces the first; a folder partsim did not write is not replaced
  EXPECT_NO_THROW(ExportAnnotation(s, (dir / "object").string()));
  fs::create_directories(dir / "mine");
  WriteText(dir / "mine" / "notes.txt", "keep");
  EXPECT_THROW(ExportAnnotation(s, (dir / "mine").string()), Error);
  EXPECT_EQ(ReadText(dir / "mine" / "notes.txt"), "keep");
}

TEST(AnnotationTest, TheStoreSavesEveryAnswerAndResumes) {
  const fs::path dir = TempDir("store");
  auto in = HandTree(dir / "in");
  {
    AnnotationStore store(in, (dir / "session").string());
    AnnotationAnswer a = Answer(0);
    a.moves = true;
    store.Answer(a);
    store.Answer(Answer(1));
    EXPECT_THROW(store.Answer(Answer(5)), Error);  // refused: the file keeps two answers
  }
  {
    AnnotationStore store(in, (dir / "session").string());
    EXPECT_EQ(store.Session().Question().index, 2);
    EXPECT_EQ(store.Session().Question().node, 4);
    ASSERT_TRUE(store.Undo());
  }
  AnnotationStore store(in, (dir / "session").string());
  EXPECT_EQ(store.Session().Question().index, 1);

  // a session of another input is refused and its file kept
  const std::string saved = ReadText(dir / "session" / "session.json");
  WriteText(dir / "in" / "objs" / "e.obj", ReadText(dir / "in" / "objs" / "e.obj") + "v 2 2 2\n");
  auto changed = std::make_shared<AnnotationInput>(ReadAnnotationInput((dir / "in").string()));
  try {
    AnnotationStore other(changed, (dir / "session").string());
    FAIL() << "a session of another input was opened";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("another input"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ReadText(dir / "session" / "session.json"), saved);
  // a damaged file is refused and kept
  WriteText(dir / "session" / "session.json", "{\"format\": ");
  EXPECT_THROW(AnnotationStore(in, (dir / "session").string()), Error);
  EXPECT_EQ(ReadText(dir / "session" / "session.json"), "{\"format\": ");
}

TEST(AnnotationTest, HostileInputsGetAnErrorNamingWhatIsWrong) {
  const fs::path dir = TempDir("hostile");
  auto expect_error = [](const fs::path& folder, const std::string& words) {
    try {
      ReadAnnotationInput(folder.string(), true);
      ADD_FAILURE() << folder << " was read";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  // nested 100,000 deep
  fs::create_directories(dir / "deep");
  std::string deep;
  for (int i = 0; i < 100000; ++i) deep += "{\"id\": " + std::to_string(i) + ", \"children\": [";
  for (int i = 0; i < 100000; ++i) deep += "]}";
  WriteText(dir / "deep" / "result.json", "[" + deep + "]");
  expect_error(dir / "deep", "nested deeper than");
  // 10^5 parts
  fs::create_directories(dir / "wide");
  std::string wide = "[{\"id\": 0, \"name\": \"x\", \"children\": [";
  for (int i = 1; i <= 100000; ++i)
    wide +=
        (i > 1 ? "," : "") + std::string("{\"id\": ") + std::to_string(i) + ", \"objs\": [\"a\"]}";
  WriteText(dir / "wide" / "result.json", wide + "]}]");
  expect_error(dir / "wide", "more than 10000 part nodes");
  // a missing mesh
  fs::create_directories(dir / "missing");
  WriteText(
      dir / "missing" / "result.json",
      R"([{"id": 0, "name": "box", "children": [{"id": 1, "name": "lid", "objs": ["gone"]}]}])");
  expect_error(dir / "missing", "part \"lid\" (id 1): mesh 'gone.obj' is in neither");
  // a non-manifold mesh: three triangles on one edge
  fs::create_directories(dir / "fin" / "objs");
  WriteText(dir / "fin" / "objs" / "a.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
  WriteText(dir / "fin" / "result.json", R"([{"id": 3, "name": "fin", "objs": ["a"]}])");
  expect_error(dir / "fin", "not manifold");
  // without strict it is read, with the warning (real PartNet meshes are often not manifold)
  const AnnotationInput fin = ReadAnnotationInput((dir / "fin").string());
  ASSERT_EQ(fin.warnings.size(), 1u);
  EXPECT_NE(fin.warnings[0].find("part \"fin\" (id 3)"), std::string::npos) << fin.warnings[0];
  // repeated ids, a leaf without meshes, a mesh name with a path
  fs::create_directories(dir / "ids");
  WriteText(dir / "ids" / "result.json",
            R"([{"id": 0, "children": [{"id": 1, "objs": ["a"]}, {"id": 1, "objs": ["b"]}]}])");
  expect_error(dir / "ids", "node id 1: the id appears twice");
  fs::create_directories(dir / "bare");
  WriteText(dir / "bare" / "result.json", R"([{"id": 0, "name": "thing"}])");
  expect_error(dir / "bare", "leaf without meshes");
  fs::create_directories(dir / "path");
  WriteText(dir / "path" / "result.json", R"([{"id": 0, "objs": ["../../etc/passwd"]}])");
  expect_error(dir / "path", "not a mesh name");
  expect_error(dir / "nowhere", "is not a folder");
}

TEST(AnnotationTest, TheUnannotatedFormHoldsTheTaskAndNotTheAnswer) {
  const fs::path dir = TempDir("unannotated");
  GeneratorOptions opt;
  opt.categories = {"StorageFurniture", "Bottle"};
  opt.out_dir = (dir / "tasks").string();
  opt.unannotated = true;
  EXPECT_EQ(GenerateDataset(opt), 2);
  int folders = 0;
  for (const auto& e : fs::directory_iterator(dir / "tasks")) {
    ++folders;
    EXPECT_TRUE(fs::exists(e.path() / "result.json"));
    EXPECT_TRUE(fs::exists(e.path() / "meta.json"));
    EXPECT_FALSE(fs::exists(e.path() / "mobility.urdf"));
    EXPECT_FALSE(fs::exists(e.path() / "mobility_v2.json"));
    EXPECT_FALSE(fs::exists(e.path() / "semantics.txt"));
    EXPECT_NO_THROW(ReadAnnotationInput(e.path().string()));
  }
  EXPECT_EQ(folders, 2);
  // the annotated form of the same run, into the same folder, replaces them
  opt.unannotated = false;
  opt.overwrite = true;
  EXPECT_EQ(GenerateDataset(opt), 2);
  for (const auto& e : fs::directory_iterator(dir / "tasks"))
    EXPECT_TRUE(fs::exists(e.path() / "mobility.urdf"));
}

TEST(AnnotationTest, ARealPartNetHierarchyReads) {
  // the dataset's bottle: PartNet's tree (bottle > normal_bottle > body, neck, lid) over
  // textured_objs/ meshes as the dataset ships them
  const std::string folder =
      std::string(PARTSIM_SOURCE_DIR) + "/../shared/realdata/partnet-mobility-3763";
  if (!fs::exists(folder)) GTEST_SKIP() << "no " << folder;
  auto in = std::make_shared<AnnotationInput>(ReadAnnotationInput(folder));
  EXPECT_EQ(in->category, "Bottle");
  EXPECT_FALSE(in->warnings.empty());  // its body's mesh has edges of three triangles
  ASSERT_EQ(in->meshes.size(), 3u);
  // bottle has one child: its question is normal_bottle's; yes; then the fixed groups
  AnnotationSession s(in);
  EXPECT_EQ(s.Question().node, 1);
  AnnotationAnswer a = Answer(0);
  a.moves = true;
  s.Answer(a);
  ASSERT_EQ(s.Question().phase, AnnotationPhase::kFixed);
  AnnotationAnswer merge = Answer(1);
  merge.links = {5, 6, 7};  // everything under normal_bottle: contradicts "moves"
  EXPECT_THROW(s.Answer(merge), Error);
  merge.links = {5, 6};  // body and neck
  s.Answer(merge);
  // two links left under a moving node: no merge is possible, so no "none" question
  EXPECT_EQ(s.Question().phase, AnnotationPhase::kHinge);
}

}  // namespace
}  // namespace partsim
