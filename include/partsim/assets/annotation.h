// The mobility annotation procedure of the SAPIEN paper (its Appendix A; docs/annotation.md):
// from a PartNet part hierarchy (result.json and part meshes) to a PartNet-Mobility object, by
// questions that are exhaustive (every movable part is asked about) and never redundant (no
// question whose answer follows from earlier answers), and whose answers always make a forest of
// links with each part in exactly one link. `partsim annotate` shows the questions in a browser;
// everything here works without it.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "partsim/physics/description.h"

namespace partsim {

/// Most nodes of a part tree read (leaves and groups): real PartNet objects have a few hundred.
constexpr int kMaxAnnotationNodes = 10000;

/// A node of the part hierarchy (result.json): a group of parts, or a leaf with meshes.
struct PartTreeNode {
  int id = -1;                    ///< result.json "id", unique in the object
  std::string name;               ///< PartNet name ("drawer_front")
  std::string text;               ///< display text ("Drawer Front")
  int parent = -1;                ///< index in AnnotationInput::nodes, -1 for a root
  std::vector<int> children;      ///< indices in AnnotationInput::nodes
  std::vector<std::string> objs;  ///< leaves: the mesh names of result.json ("original-3")
  int mesh = -1;                  ///< leaves: index in AnnotationInput::meshes
};

/// The meshes of one leaf: its files, each merged into one mesh, in the file frame.
struct AnnotationMesh {
  int node = -1;                   ///< index of the leaf in AnnotationInput::nodes
  std::vector<std::string> files;  ///< paths of the OBJ files, one per name in objs
  std::vector<std::shared_ptr<const MeshData>> meshes;  ///< one per file
  std::vector<Eigen::Vector3d> colors;                  ///< diffuse colour of each file
};

/// What `partsim annotate` works on: a PartNet-style folder.
struct AnnotationInput {
  std::string folder;
  std::string category;             ///< meta.json model_cat ("" when there is no meta.json)
  std::string model_id;             ///< meta.json model_id ("")
  std::string anno_id;              ///< meta.json anno_id ("")
  std::vector<PartTreeNode> nodes;  ///< pre-order of the hierarchy
  std::vector<int> roots;           ///< indices of the roots (result.json is a list of them)
  std::vector<AnnotationMesh> meshes;
  std::string result_json;  ///< result.json as read
  std::string digest;       ///< of result.json and the mesh files' sizes: a session's input
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();  ///< of every mesh (m)
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();
  /// What was read but is doubtful: meshes that are not manifold (real PartNet meshes often are
  /// not; they still display and export), one line each naming the part and file.
  std::vector<std::string> warnings;

  /// Index of the node with result.json id `id`; throws partsim::Error when there is none.
  int Index(int id) const;
  /// Indices of the leaves at and below node `index`, in pre-order.
  std::vector<int> Leaves(int index) const;
};

/// Reads `folder`: result.json (a list of root nodes; at most kMaxAnnotationNodes nodes, nested
/// at most 64 deep), meta.json when present, and every leaf's meshes (objs/NAME.obj, else
/// textured_objs/NAME.obj). Throws partsim::Error naming the file and the node at fault: a
/// missing or malformed result.json, a node without id, a repeated id, a leaf without meshes, a
/// missing or unreadable mesh file. A mesh that is not manifold (an edge of three or more
/// triangles) is a warning, or with `strict` an error.
AnnotationInput ReadAnnotationInput(const std::string& folder, bool strict = false);

/// The steps of the procedure, in order.
enum class AnnotationPhase { kMotion, kFixed, kHinge, kSlider, kRoot, kDone };
/// "motion", "fixed", "hinge", "slider", "root", "done".
const char* AnnotationPhaseName(AnnotationPhase phase);

/// The question to answer next.
struct AnnotationQuestion {
  int index = 0;  ///< number of answers before it
  AnnotationPhase phase = AnnotationPhase::kMotion;
  std::string text;
  int node = -1;  ///< kMotion: the node asked about (result.json id)
  int link = -1;  ///< kRoot: the link asked about
};

/// An answer; which fields count depends on the question's phase (docs/annotation.md).
struct AnnotationAnswer {
  int index = -1;               ///< the question's index
  bool none = false;            ///< kFixed, kHinge, kSlider: nothing (more) of this kind
  bool moves = false;           ///< kMotion
  std::vector<int> links;       ///< kFixed: links fixed together (two or more)
  int parent = -1, child = -1;  ///< kHinge, kSlider: link ids
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();      ///< a point of the axis, file frame (m)
  Eigen::Vector3d direction = Eigen::Vector3d::UnitY();  ///< the axis (normalised on answer)
  double lower = 0, upper = 0;  ///< degrees (hinge) or metres (slider), lower <= upper
  bool no_limit = false;        ///< kHinge: turns without limit
  bool rotates = false;         ///< kSlider: also turns about its axis (a screw)
  double rotation_limit = 0;    ///< ... over [0, rotation_limit] degrees
  bool no_rotation_limit = false;
  std::string kind;  ///< kRoot: "fixed", "free" or "outlier"
  double time = 0;   ///< when it was given (s since the epoch); 0: not recorded
};

/// A link as the answers so far make it: parts fixed together, and how it hangs on its parent.
struct AnnotationLink {
  int id = -1;              ///< result.json id of its first unit
  std::vector<int> units;   ///< node indices of the rigid units in it
  std::vector<int> leaves;  ///< node indices of its parts
  int parent = -1;          ///< parent link id, -1 while it has none
  std::string joint;        ///< "hinge", "slider", "" (none yet, or a root)
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitY();
  double lower = 0, upper = 0;
  bool no_limit = false, rotates = false, no_rotation_limit = false;
  double rotation_limit = 0;
  std::string root;  ///< roots: "fixed", "free", "outlier" once answered
};

/// A review of one joint (the paper's quality control).
struct AnnotationReview {
  int link = -1;  ///< the link whose joint it is
  bool accept = false;
  std::string comment;
};

/// The state of an annotation: its answers, and what follows from them. Answers are checked
/// whatever gives them; one refused leaves the session as it was.
class AnnotationSession {
 public:
  explicit AnnotationSession(std::shared_ptr<const AnnotationInput> input);

  const AnnotationInput& Input() const { return *input_; }
  const AnnotationQuestion& Question() const { return question_; }
  bool Done() const { return question_.phase == AnnotationPhase::kDone; }
  /// Applies `answer` to the current question; throws partsim::Error saying why it is refused
  /// (another question's index, a field missing or out of range, a link that does not exist, a
  /// merge that contradicts a "moves" answer, a joint that would close a loop).
  void Answer(AnnotationAnswer answer);
  /// Removes the last answer (replaying the others); false when there is none.
  bool Undo();
  const std::vector<AnnotationAnswer>& Answers() const { return answers_; }
  /// The links so far (in the motion step: one per unit decided).
  const std::vector<AnnotationLink>& Links() const { return links_; }
  /// The units decided so far (node indices), in pre-order.
  std::vector<int> Units() const;
  /// The link with id `id`; throws partsim::Error when there is none.
  const AnnotationLink& Link(int id) const;

  /// Records the review of link `link`'s joint (after Done; replaces an earlier one); throws
  /// partsim::Error for a link without a joint.
  void Review(const AnnotationReview& review);
  const std::vector<AnnotationReview>& Reviews() const { return reviews_; }

  /// The state as docs/annotation.md describes it (JSON text); `review_mode` adds the review.
  std::string StateJson(bool review_mode = false) const;

 private:
  void Apply(const AnnotationAnswer& answer);
  void Advance();
  /// The subtree of node `top` becomes one rigid unit, a link of its own.
  void AddUnit(int top);
  int LinkIndex(int id) const;
  bool AnyMergePossible() const;
  int Components() const;

  std::shared_ptr<const AnnotationInput> input_;
  AnnotationQuestion question_;
  std::vector<AnnotationAnswer> answers_;
  std::vector<AnnotationQuestion> asked_;  ///< the question each answer answered
  std::vector<AnnotationReview> reviews_;
  AnnotationPhase phase_ = AnnotationPhase::kMotion;  ///< the step after the motion step
  bool links_sorted_ = false;  ///< the motion step is over and links_ are in pre-order
  // the motion step
  std::vector<int> queue_;   ///< nodes still to look at (front = back of the vector)
  int asked_top_ = -1;       ///< the node whose subtree the motion question is about
  std::vector<int> units_;   ///< decided, in decision order
  std::vector<int> moving_;  ///< nodes answered "moves"
  std::vector<AnnotationLink> links_;
  std::vector<int> leaf_link_;  ///< by node index: index in links_ of the link holding a leaf
};

/// An answer from its JSON form (docs/annotation.md); throws partsim::Error naming a field of the
/// wrong type. Whether it fits the question is AnnotationSession::Answer's to say.
AnnotationAnswer AnnotationAnswerFromJson(const std::string& json);
/// The JSON form of an answer (what session.json stores).
std::string AnnotationAnswerToJson(const AnnotationAnswer& answer);

/// The session stored in `dir`/session.json: every answer and review, written atomically after
/// each one. Opening a folder holding a session of another input (its digest differs) throws
/// partsim::Error and leaves the file as it is; so does a session.json that cannot be read or
/// whose answers no longer apply.
class AnnotationStore {
 public:
  /// Reads `dir`/session.json when present (replaying it into a session of `input`), else starts
  /// an empty session; creates `dir`.
  AnnotationStore(std::shared_ptr<const AnnotationInput> input, const std::string& dir);
  AnnotationSession& Session() { return session_; }
  const AnnotationSession& Session() const { return session_; }
  const std::string& Dir() const { return dir_; }
  /// Answer, Undo and Review of the session, each saved before it returns; an answer refused
  /// changes neither the session nor the file.
  void Answer(AnnotationAnswer answer);
  bool Undo();
  void Review(const AnnotationReview& review);

 private:
  void Save() const;
  AnnotationSession session_;
  std::string dir_;
};

/// Writes a finished session as a PartNet-Mobility folder `dir` (mobility.urdf,
/// mobility_v2.json, semantics.txt, meta.json, bounding_box.json, result.json as the input's,
/// textured_objs/NAME.obj for each mesh name): links numbered link_0.. in pre-order of the
/// forest; fixed roots are "heavy", free roots "free"; outlier roots and what hangs below them
/// are left out (meta.json lists their parts); meta.json's "reviews" holds the session's reviews
/// of the joints exported. The folder appears whole or not at all. Throws
/// partsim::Error when the session is not done or every root is an outlier.
void ExportAnnotation(const AnnotationSession& session, const std::string& dir);

}  // namespace partsim
