// The generator's category table (the paper's dataset statistics), object generation and the
// multi-threaded dataset writer.
#include "partsim/assets/generator.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <mutex>
#include <thread>

#include "assets/generator/categories.h"
#include "core/file_read.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

using namespace internal::gen;  // NOLINT

struct CategoryInfo {
  const char* name;
  int models;  ///< #M of the paper's Table (dataset statistics)
  int parts;   ///< #P
  CategoryBuilder build;
};

// In the order of the paper's table; the paper's "Cabinet" is StorageFurniture, "Chair" in the
// second row FoldingChair, "Fridge" Refrigerator, "Monitor" Display, "Pot" KitchenPot, "Washer"
// WashingMachine.
const CategoryInfo kCategories[] = {
    {"Bottle", 57, 114, BuildBottle},
    {"Box", 28, 94, BuildBox},
    {"Bucket", 36, 74, BuildBucket},
    {"StorageFurniture", 345, 1174, BuildStorageFurniture},
    {"Camera", 37, 341, BuildCamera},
    {"Cart", 61, 232, BuildCart},
    {"Chair", 80, 1235, BuildChair},
    {"Clock", 31, 106, BuildClock},
    {"CoffeeMachine", 55, 374, BuildCoffeeMachine},
    {"Dishwasher", 48, 112, BuildDishwasher},
    {"Dispenser", 57, 162, BuildDispenser},
    {"Door", 36, 103, BuildDoor},
    {"Eyeglasses", 65, 195, BuildEyeglasses},
    {"Fan", 81, 172, BuildFan},
    {"Faucet", 84, 228, BuildFaucet},
    {"FoldingChair", 26, 58, BuildFoldingChair},
    {"Refrigerator", 44, 118, BuildRefrigerator},
    {"Globe", 61, 130, BuildGlobe},
    {"Kettle", 29, 66, BuildKettle},
    {"Keyboard", 37, 3593, BuildKeyboard},
    {"Knife", 44, 149, BuildKnife},
    {"Lamp", 45, 165, BuildLamp},
    {"Laptop", 56, 112, BuildLaptop},
    {"Lighter", 28, 86, BuildLighter},
    {"Microwave", 16, 85, BuildMicrowave},
    {"Display", 37, 93, BuildDisplay},
    {"Mouse", 14, 61, BuildMouse},
    {"Oven", 30, 214, BuildOven},
    {"Pen", 48, 97, BuildPen},
    {"Phone", 17, 271, BuildPhone},
    {"Pliers", 25, 59, BuildPliers},
    {"KitchenPot", 25, 53, BuildKitchenPot},
    {"Printer", 29, 376, BuildPrinter},
    {"Remote", 49, 1490, BuildRemote},
    {"Safe", 30, 202, BuildSafe},
    {"Scissors", 47, 94, BuildScissors},
    {"Stapler", 23, 69, BuildStapler},
    {"Suitcase", 24, 101, BuildSuitcase},
    {"Switch", 70, 195, BuildSwitch},
    {"Table", 101, 420, BuildTable},
    {"Toaster", 25, 116, BuildToaster},
    {"Toilet", 69, 229, BuildToilet},
    {"TrashCan", 70, 208, BuildTrashCan},
    {"USB", 51, 103, BuildUSB},
    {"WashingMachine", 17, 144, BuildWashingMachine},
    {"Window", 58, 195, BuildWindow},
};

const CategoryInfo& Find(const std::string& category) {
  for (const CategoryInfo& c : kCategories) {
    if (category == c.name) return c;
  }
  std::string known;
  for (const CategoryInfo& c : kCategories)
    known += std::string(known.empty() ? "" : ", ") + c.name;
  throw Error("generator: unknown category '" + category + "' (known: " + known + ")");
}

int CategoryIndex(const std::string& category) {
  const CategoryInfo& c = Find(category);
  return static_cast<int>(&c - kCategories);
}

/// Seed of one object from the dataset seed, its category and index (so that subsets and
/// thread counts do not change an object).
std::uint64_t ObjectSeed(std::uint64_t seed, const std::string& category, int index) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a of the name
  for (char ch : category) h = (h ^ static_cast<unsigned char>(ch)) * 1099511628211ULL;
  std::uint64_t x = h ^ (seed * 0x9e3779b97f4a7c15ULL) ^
                    (static_cast<std::uint64_t>(index) * 0xc2b2ae3d27d4eb4fULL);
  x = (x ^ (x >> 31)) * 0x7fb5d329728ea185ULL;
  return x ^ (x >> 29);
}

/// A 32-digit hexadecimal model id from the object's seed, like the dataset's ShapeNet ids.
std::string ModelId(std::uint64_t object_seed) {
  std::uint64_t a = object_seed * 0xd1b54a32d192ed03ULL + 0x8bb84b93962eacc9ULL;
  a = (a ^ (a >> 32)) * 0x9e3779b97f4a7c15ULL;
  std::uint64_t b = (a ^ (a >> 29)) * 0xbf58476d1ce4e5b9ULL;
  char buf[33];
  std::snprintf(buf, sizeof(buf), "%016llx%016llx", static_cast<unsigned long long>(a ^ (a >> 31)),
                static_cast<unsigned long long>(b ^ (b >> 31)));
  return buf;
}

/// Moves the object so that its bounding box at rest is centred on the origin of frame F, as the
/// dataset's objects are (the shift rounded to 0.1 mm, like the generator's other positions).
void CentreOnBoundingBox(GeneratedObject* o) {
  V3 lo = V3::Constant(1e30), hi = V3::Constant(-1e30);
  for (const GeneratedLink& l : o->links)
    for (const GeneratedPart& part : l.parts)
      for (const GeneratedPiece& piece : part.pieces)
        for (const V3& v : piece.vertices) {
          lo = lo.cwiseMin(v);
          hi = hi.cwiseMax(v);
        }
  if (lo.x() > hi.x()) return;
  const V3 c = Q(V3(0.5 * (lo + hi)));
  for (GeneratedLink& l : o->links) {
    l.axis_origin -= c;
    for (GeneratedPart& part : l.parts)
      for (GeneratedPiece& piece : part.pieces)
        for (V3& v : piece.vertices) v -= c;
  }
}

/// Numbers the parts as the leaves of result.json's hierarchy, in pre-order: the object is
/// node 0; a link with several parts is a node whose children are its parts, a link with one
/// part contributes that part alone.
void NumberPartNodes(GeneratedObject* o) {
  int next = 1;
  for (GeneratedLink& l : o->links) {
    if (l.parts.size() > 1) ++next;  // the link's node
    for (GeneratedPart& part : l.parts) part.id = next++;
  }
}

}  // namespace

std::vector<std::string> GeneratorCategories() {
  std::vector<std::string> out;
  for (const CategoryInfo& c : kCategories) out.push_back(c.name);
  return out;
}

int PaperModelCount(const std::string& category) { return Find(category).models; }
int PaperPartCount(const std::string& category) { return Find(category).parts; }

namespace {

// meta.json's anno_id and the folder name: 1CCIIII with CC the category's place in the table and
// IIII the index
std::string AnnoId(const std::string& category, int index) {
  return std::to_string(1000000 + CategoryIndex(category) * 10000 + index);
}

}  // namespace

GeneratedObject GenerateObject(const std::string& category, int index, std::uint64_t seed) {
  const CategoryInfo& info = Find(category);
  if (index < 0 || index >= 10000) {
    throw Error("GenerateObject: index " + std::to_string(index) + " out of range [0, 9999]");
  }
  GeneratedObject out;
  out.category = info.name;
  out.index = index;
  out.seed = seed;
  const std::uint64_t object_seed = ObjectSeed(seed, category, index);
  out.anno_id = AnnoId(category, index);
  out.model_id = ModelId(object_seed);
  Rng rng(object_seed);
  ObjectBuilder b(&out);
  info.build(b, rng);
  b.Finalize();
  ApplyLabels(&out);
  CentreOnBoundingBox(&out);
  NumberPartNodes(&out);
  return out;
}

namespace {

// Refuses a non-empty output folder unless overwrite; then removes what partsim generated
// there (object folders, leftovers of stopped runs), flat or by category, and nothing else.
void PrepareOutDir(const GeneratorOptions& options) {
  namespace fs = std::filesystem;
  const fs::path out(options.out_dir);
  std::error_code ec;
  if (!fs::exists(out, ec)) return;
  if (!fs::is_directory(out, ec))
    throw Error("GenerateDataset: '" + options.out_dir + "' exists and is not a folder");
  // other runs' objects are not this run's to refuse or remove
  if (options.shared_out_dir || fs::is_empty(out, ec)) return;
  if (!options.overwrite)
    throw Error("GenerateDataset: '" + options.out_dir +
                "' is not empty, and old and new objects would mix: choose an empty folder, or "
                "overwrite (--overwrite) to replace the objects partsim generated there");
  std::vector<fs::path> owned;
  for (auto it = fs::recursive_directory_iterator(out, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (!it->is_directory()) continue;
    if (IsPartialObjectFolder(it->path().string()) ||
        IsGeneratedObjectFolder(it->path().string())) {
      owned.push_back(it->path());
      it.disable_recursion_pending();
    } else if (it.depth() >= 1) {
      it.disable_recursion_pending();  // objects lie at <out>/<id> or <out>/<category>/<id>
    }
  }
  for (const fs::path& p : owned) {
    fs::remove_all(p, ec);
    if (ec) throw Error("GenerateDataset: cannot remove '" + p.string() + "': " + ec.message());
  }
}

// Whether the folder of object `index` of `category` is already whole in a shared output folder
// (a folder appears whole or not at all, see WriteObject), written with this seed; throws naming
// a folder of that name that partsim generated with another seed or index.
bool AlreadyWritten(const GeneratorOptions& options, const std::string& category, int index) {
  namespace fs = std::filesystem;
  fs::path dir(options.out_dir);
  if (options.by_category) dir /= category;
  dir /= AnnoId(category, index);
  std::error_code ec;
  if (!fs::is_directory(dir, ec) || !IsGeneratedObjectFolder(dir.string())) return false;
  // the other form (annotated against unannotated) is written again
  if (fs::exists(dir / "mobility.urdf", ec) == options.unannotated) return false;
  const std::string meta = internal::ReadWholeFile((dir / "meta.json").string(), "meta.json");
  const std::string mine =
      "\"seed\": " + std::to_string(options.seed) + ", \"index\": " + std::to_string(index) + "}";
  if (meta.find(mine) != std::string::npos) return true;
  throw Error("GenerateDataset: '" + dir.string() +
              "' holds an object generated with another seed or index than this run's (its "
              "meta.json has no '" +
              mine +
              "'): choose another folder, or overwrite it "
              "(--overwrite)");
}

}  // namespace

int GenerateDataset(const GeneratorOptions& options, const GeneratorProgress& progress,
                    int* skipped) {
  if (!(options.shard_count >= 1 && options.shard_index >= 0 &&
        options.shard_index < options.shard_count))
    throw Error("GenerateDataset: shard " + std::to_string(options.shard_index) + "/" +
                std::to_string(options.shard_count) + " is not one: it needs 0 <= i < N");
  // the work list, in category then index order; this shard's share of it
  std::vector<std::string> cats =
      options.categories.empty() ? GeneratorCategories() : options.categories;
  std::vector<std::pair<std::string, int>> work;
  int position = 0;
  for (const std::string& c : cats) {
    int n = options.per_category > 0 ? options.per_category : PaperModelCount(c);
    for (int i = 0; i < n; ++i, ++position)
      if (position % options.shard_count == options.shard_index) work.emplace_back(Find(c).name, i);
  }
  if (options.out_dir.empty()) throw Error("GenerateDataset: out_dir is empty");
  PrepareOutDir(options);
  // in a shared folder, what this shard wrote before (or another process at once) stays
  int already = 0;
  if (options.shared_out_dir && !options.overwrite) {
    std::vector<std::pair<std::string, int>> to_write;
    for (const auto& w : work) {
      if (AlreadyWritten(options, w.first, w.second))
        ++already;
      else
        to_write.push_back(w);
    }
    work = std::move(to_write);
  }
  if (skipped) *skipped = already;
  const int total = static_cast<int>(work.size());
  std::atomic<int> next{0};
  std::mutex mutex;
  int done = 0;
  std::exception_ptr failure;
  auto worker = [&]() {
    while (true) {
      int i = next.fetch_add(1);
      if (i >= total) return;
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (failure) return;
      }
      try {
        GeneratedObject o = GenerateObject(work[i].first, work[i].second, options.seed);
        std::filesystem::path dir(options.out_dir);
        if (options.by_category) dir /= o.category;
        if (options.unannotated)
          WriteUnannotatedObject(o, (dir / o.anno_id).string());
        else
          WriteObject(o, (dir / o.anno_id).string());
        std::lock_guard<std::mutex> lock(mutex);
        ++done;
        if (progress) progress(done, total, o);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!failure) failure = std::current_exception();
        return;
      }
    }
  };
  int jobs = std::max(1, std::min(options.jobs, std::max(1, total)));
  std::vector<std::thread> threads;
  for (int j = 1; j < jobs; ++j) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
  return done;
}

}  // namespace partsim
