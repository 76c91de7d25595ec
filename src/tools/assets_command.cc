// `partsim assets generate`: writes procedural articulated objects of the PartNet-Mobility
// categories as dataset folders, with progress on stderr.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "../core/progress.h"
#include "arg_parser.h"
#include "commands.h"
#include "partsim/assets/convex_decomposition.h"
#include "partsim/assets/generator.h"
#include "partsim/assets/quality.h"

namespace partsim::tools {
namespace {

constexpr char kAssetsUsage[] = R"(usage:
  partsim assets generate --out DIR [--categories all|Cat1,Cat2] [--per-category N|paper]
                          [--seed S] [--jobs J] [--by-category] [--overwrite] [--shard i/N]
                          [--unannotated]
  partsim assets categories
  partsim assets check DIR [--jobs J] [--no-visibility] [--backend B] [--report FILE]
                       [--limit N] [--shard i/N] [--results FILE]
  partsim assets check --merge FILE... [--report FILE] [--results FILE]
  partsim assets decompose MESH --out DIR [--concavity C] [--max-pieces N]

generate     writes DIR/<anno_id>/ folders in the PartNet-Mobility format, laid out as the
             dataset is (mobility.urdf, mobility_v2.json, semantics.txt, meta.json,
             bounding_box.json, result.json, result_after_merging.json, textured_objs/); the
             category is meta.json's model_cat. Same arguments and seed, same bytes.
  --out DIR               output folder (required)
  --categories LIST       comma-separated category names, or all (default all)
  --per-category N|paper  objects per category, or the paper's model count (default 1)
  --seed S                dataset seed, an unsigned integer (default 0)
  --jobs J                worker threads (default 1)
  --by-category           DIR/<Category>/<anno_id>/ instead
  --overwrite             DIR may hold objects of an earlier run: they are replaced (without
                          it a non-empty DIR is refused); other files there are left alone.
                          Each object is written to <anno_id>.partial and renamed when whole.
  --shard i/N             write only the objects whose index in the whole run's order
                          (categories, then index) % N is i. Several shards may write into one
                          DIR, at once or in turn: DIR may hold other objects, and this shard's
                          objects already whole there are skipped (rewritten with --overwrite,
                          which then replaces only this shard's objects). The N shards' trees
                          together are a single run's, byte for byte: generate writes nothing
                          but the object folders.
  --unannotated           write annotation tasks instead (docs/annotation.md): the meshes,
                          result.json, meta.json and bounding_box.json, without mobility.urdf,
                          mobility_v2.json and semantics.txt; `partsim annotate` turns one back
                          into a PartNet-Mobility object, and the same command without this
                          option writes the answer
categories   lists the 46 categories with the paper's model and part counts.
check        runs the quality checks on every object folder under DIR and prints the models and
             movable parts per category beside the paper's (`check --help` for more).
decompose    splits a non-convex mesh into convex OBJ pieces with a URDF <collision> snippet and
             reports coverage and excess (`decompose --help` for more).
)";

std::string Clock(double s) {
  char buf[32];
  int t = static_cast<int>(s + 0.5);
  std::snprintf(buf, sizeof(buf), "%d:%02d", t / 60, t % 60);
  return buf;
}

int Generate(const std::vector<std::string>& args) {
  GeneratorOptions opt;
  bool have_out = false;
  ArgParser p("partsim assets generate");
  p.Option("--out", [&](const FlagValue& v) {
    opt.out_dir = v.Text();
    have_out = true;
  });
  p.Option("--categories", [&](const FlagValue& v) {
    opt.categories.clear();
    if (v.Text() != "all") opt.categories = v.Names();
  });
  p.Option("--per-category", [&](const FlagValue& v) {
    opt.per_category =
        v.Text() == "paper" ? 0 : static_cast<int>(v.Integer(1, std::numeric_limits<int>::max()));
  });
  p.Option("--seed", [&](const FlagValue& v) { opt.seed = v.Unsigned(); });
  p.Option("--jobs", [&](const FlagValue& v) {
    opt.jobs = static_cast<int>(v.Integer(1, std::numeric_limits<int>::max()));
  });
  p.Switch("--by-category", [&] { opt.by_category = true; });
  p.Switch("--overwrite", [&] { opt.overwrite = true; });
  p.Switch("--unannotated", [&] { opt.unannotated = true; });
  p.Option("--shard", [&](const FlagValue& v) {
    std::tie(opt.shard_index, opt.shard_count) = v.Shard();
    opt.shared_out_dir = true;
  });
  p.Parse(args);
  if (!have_out) p.Fail("--out DIR is required");
  // unknown categories are a bad command line, refused before anything is written
  const std::vector<std::string> known = GeneratorCategories();
  for (const std::string& c : opt.categories) {
    if (std::find(known.begin(), known.end(), c) == known.end())
      p.Fail("unknown category '" + c + "' in --categories" + DidYouMean(c, known) +
             " (partsim assets categories lists them)");
  }

  auto start = std::chrono::steady_clock::now();
  internal::ProgressLine progress(stderr);
  int skipped = 0;
  int written = GenerateDataset(
      opt,
      [&](int done, int total, const GeneratedObject& o) {
        double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        double eta = done > 0 ? t / done * (total - done) : 0.0;
        progress.Update(done, total,
                        "[" + std::to_string(done) + "/" + std::to_string(total) + "] " +
                            o.category + " " + o.anno_id + "  elapsed " + Clock(t) + "  eta " +
                            Clock(eta));
      },
      &skipped);
  progress.Break();
  double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string shard = opt.shared_out_dir ? " (shard " + std::to_string(opt.shard_index) +
                                                     "/" + std::to_string(opt.shard_count) + ")"
                                               : "";
  std::fprintf(stderr, "wrote %d objects to %s%s in %.1f s", written, opt.out_dir.c_str(),
               shard.c_str(), t);
  if (opt.shared_out_dir)
    std::fprintf(stderr, "; skipped %d already there\n", skipped);
  else
    std::fprintf(stderr, "\n");
  return 0;
}

int ListCategories() {
  int m = 0, p = 0;
  std::printf("%-18s %6s %6s\n", "category", "#M", "#P");
  for (const std::string& c : GeneratorCategories()) {
    std::printf("%-18s %6d %6d\n", c.c_str(), PaperModelCount(c), PaperPartCount(c));
    m += PaperModelCount(c);
    p += PaperPartCount(c);
  }
  std::printf("%-18s %6d %6d\n", "all", m, p);
  return 0;
}

}  // namespace

int RunAssetsCommand(int argc, char** argv) {
  // check and decompose parse their own arguments (and --help)
  if (argc > 0 && std::string(argv[0]) == "check") return RunQualityCommand(argc - 1, argv + 1);
  if (argc > 0 && std::string(argv[0]) == "decompose") return RunDecomposeCommand(argc, argv);
  std::vector<std::string> args(argv, argv + argc);
  return RunWithExitCode("partsim assets", "", [&] {
    if (args.empty())
      throw UsageError(std::string("partsim assets: missing sub-command\n") + kAssetsUsage);
    if (ArgParser::AsksForHelp(args)) {
      std::printf("%s", kAssetsUsage);
      return 0;
    }
    std::string sub = args[0];
    args.erase(args.begin());
    if (sub == "generate") return Generate(args);
    if (sub == "categories" && args.empty()) return ListCategories();
    throw UsageError("partsim assets: unknown sub-command '" + sub + "'" +
                     DidYouMean(sub, {"generate", "categories", "check", "decompose"}) +
                     " (expected generate, categories, check or decompose)");
  });
}

}  // namespace partsim::tools
