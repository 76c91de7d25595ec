// Procedural articulated objects in the 46 categories of the PartNet-Mobility dataset (SAPIEN,
// Xiang et al. 2020), written as PartNet-Mobility folders with the real dataset's structure
// (docs/partnet_mobility_format.md).
//
// Objects are built in the raw mesh frame F of the files: y up, metres, the object's front facing
// +z, its bounding box at rest centred on the origin (mobility.urdf turns F z-up at the joint from
// "base" to the body, so that the front faces world -x). Every part piece is a closed,
// outward-facing, convex triangle mesh at least half a millimetre thick, so that it is both the
// visual and the exact collision shape of the piece. Every joint is at rest at q = 0, which lies
// inside its limits, and moving parts keep a few millimetres of clearance from the rest of the
// object over their whole range.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace partsim {

/// A closed convex triangle mesh of one part piece, in the file frame at rest (metres), with the
/// material it is made of.
struct GeneratedPiece {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;  ///< counter-clockwise seen from outside
  std::string material;                       ///< material name in the .mtl, e.g. "wood"
  Eigen::Vector3d color = Eigen::Vector3d::Constant(0.8);  ///< diffuse colour (Kd), 0..1
  double density = 1000.0;                                 ///< kg/m^3
  /// Name of its OBJ file in textured_objs/ (without ".obj"); "": original-K, K counting the
  /// object's pieces in link, part, piece order.
  std::string file;
};

/// One annotated part of a link ("handle", "door", "drawer_front", ...), made of convex pieces:
/// a leaf of result.json's part hierarchy.
struct GeneratedPart {
  int id = 0;        ///< node id in result.json, unique in the object; visuals "<name>-<id>"
  std::string name;  ///< PartNet part name
  std::vector<GeneratedPiece> pieces;
};

/// One link_N of the object and the joint that attaches it to its parent. A link has two names,
/// as in the real dataset: its semantics.txt label (the movable-part vocabulary of tasks and
/// benchmarks) and its mobility_v2.json name (the PartNet vocabulary of parts).
struct GeneratedLink {
  int id = 0;         ///< N of link_N
  int parent = -1;    ///< id of the parent link, -1 for base (the body only)
  std::string joint;  ///< mobility_v2.json motion: hinge | slider | heavy | static | free
  /// semantics.txt label, e.g. "drawer", "rotation_door", "rotation_lid", "furniture_body"
  std::string name;
  /// mobility_v2.json "name", the PartNet name, e.g. "drawer", "cabinet_door", "lid", "body"
  std::string partnet_name;
  std::vector<GeneratedPart> parts;
  Eigen::Vector3d axis_origin = Eigen::Vector3d::Zero();      ///< frame F (m)
  Eigen::Vector3d axis_direction = Eigen::Vector3d::UnitY();  ///< frame F, unit
  double limit_a = 0.0;            ///< lower limit: degrees (hinge) or metres (slider)
  double limit_b = 0.0;            ///< upper limit: degrees (hinge) or metres (slider)
  bool no_limit = false;           ///< continuous hinge
  bool rotates = false;            ///< slider that also turns about its axis
  bool no_rotation_limit = false;  ///< ... without limit
  double rotation_limit = 0.0;     ///< ... over [0, rotation_limit] degrees
  double friction = 0.0;           ///< dry friction, N (slider) or N m (hinge)
  double damping = 0.0;            ///< viscous damping, N s/m or N m s/rad
  double rotation_friction = 0.0;  ///< rotating sliders: dry friction of the turn, N m
  double rotation_damping = 0.0;   ///< rotating sliders: damping of the turn, N m s/rad
};

/// One generated object, in memory.
struct GeneratedObject {
  std::string category;  ///< meta.json model_cat, e.g. "StorageFurniture"
  /// meta.json model_id: 32 hexadecimal digits, like the dataset's ShapeNet model ids; depends on
  /// (category, index, seed)
  std::string model_id;
  /// meta.json anno_id and folder name: a number, unique across categories, that depends on
  /// (category, index) only: 1CCIIII with CC the category's place in the paper's table and IIII
  /// the index (the dataset's own ids are below 200000)
  std::string anno_id;
  int index = 0;                     ///< index within its category
  std::uint64_t seed = 0;            ///< dataset seed it was generated with
  std::vector<GeneratedLink> links;  ///< by id
};

/// Options of GenerateDataset.
struct GeneratorOptions {
  std::vector<std::string> categories;  ///< empty: all 46
  int per_category = 1;                 ///< objects per category; <= 0: the paper's #M
  std::uint64_t seed = 0;
  std::string out_dir;       ///< objects go to <out_dir>/<anno_id>/, the dataset's flat layout
  bool by_category = false;  ///< <out_dir>/<category>/<anno_id>/ instead
  int jobs = 1;              ///< worker threads, >= 1
  /// A non-empty out_dir is refused (old and new objects would mix) unless this is set; then the
  /// object folders partsim generated there before (meta.json names the generator) and the
  /// leftovers of interrupted runs (*.partial) are removed first, and nothing else is touched.
  bool overwrite = false;
  /// This run writes only the objects whose index in the whole run's work list (categories in
  /// order, then index) % shard_count == shard_index; 0 <= shard_index < shard_count.
  int shard_index = 0;
  int shard_count = 1;
  /// out_dir is shared with other runs (shards of one dataset, at once or one after another): a
  /// non-empty out_dir is not refused and nothing there is removed first; an object of this run
  /// whose folder is already whole there (same seed and index in its meta.json) is skipped, or
  /// rewritten with overwrite; a folder of that name holding anything else is refused.
  bool shared_out_dir = false;
  /// WriteUnannotatedObject instead of WriteObject: annotation tasks with a known answer.
  bool unannotated = false;
};

/// Suffix of the folder an object is written into before it is renamed into place: an object
/// folder is there whole or not at all, and a *.partial folder is the leftover of a run that
/// was stopped (`assets check` fails it).
constexpr const char* kPartialSuffix = ".partial";

/// Progress of GenerateDataset: objects written so far, of `total`.
using GeneratorProgress = std::function<void(int done, int total, const GeneratedObject& last)>;

/// The 46 category names, in the order of the paper's table.
std::vector<std::string> GeneratorCategories();

/// The paper's number of models (#M) of a category (2,346 in all); throws partsim::Error naming
/// an unknown category.
int PaperModelCount(const std::string& category);

/// The paper's number of parts (#P) of a category (14,068 in all). The paper's counts are the
/// links of the models, body included (Laptop: 112 parts for 56 models); throws like
/// PaperModelCount.
int PaperPartCount(const std::string& category);

/// Generates object `index` of `category`. The result depends only on (category, index, seed).
/// Throws partsim::Error naming an unknown category or a negative index.
GeneratedObject GenerateObject(const std::string& category, int index, std::uint64_t seed);

/// Writes `object` into folder `dir` (created with its parents), as the dataset holds an object:
/// mobility.urdf, mobility_v2.json, semantics.txt, meta.json, bounding_box.json, result.json,
/// result_after_merging.json, textured_objs/original-K.obj and .mtl (one piece per file). Same
/// object, same bytes. The files go to `dir`.partial first, which is renamed to `dir` once all
/// are written (replacing a `dir` partsim generated before; a non-empty `dir` holding anything
/// else is refused); a process killed meanwhile leaves no torn `dir`. Throws partsim::Error
/// naming the file it cannot write.
void WriteObject(const GeneratedObject& object, const std::string& dir);

/// Writes `object` into `dir` as an annotation task (docs/annotation.md): what WriteObject writes
/// less mobility.urdf, mobility_v2.json and semantics.txt, so the part hierarchy (result.json)
/// and the meshes are there and the answer is not.
void WriteUnannotatedObject(const GeneratedObject& object, const std::string& dir);

/// Whether `folder` holds an object WriteObject wrote (its meta.json names partsim's generator).
bool IsGeneratedObjectFolder(const std::string& folder);
/// Whether `folder` is a staging folder WriteObject left behind (its name ends in kPartialSuffix).
bool IsPartialObjectFolder(const std::string& folder);

/// Generates and writes the objects of `options` (of its shard) on `options.jobs` threads; calls
/// `progress` (serialised) after each object written, `total` being the objects to write. Returns
/// the number of objects written; `skipped`, when given, receives the number of objects that were
/// already whole in a shared out_dir and were left as they are.
int GenerateDataset(const GeneratorOptions& options,
                    const GeneratorProgress& progress = GeneratorProgress(),
                    int* skipped = nullptr);

}  // namespace partsim
