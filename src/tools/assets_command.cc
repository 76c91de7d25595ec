// `partsim assets generate`: writes procedural articulated objects of the PartNet-Mobility
// categories as dataset folders, with progress on stderr.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

#include "../core/progress.h"
#include "commands.h"
#include "partsim/assets/convex_decomposition.h"
#include "partsim/assets/generator.h"
#include "partsim/assets/quality.h"

namespace partsim::tools {
namespace {

constexpr char kAssetsUsage[] = R"(usage:
  partsim assets generate --out DIR [--categories all|Cat1,Cat2] [--per-category N|paper]
                          [--seed S] [--jobs J] [--by-category] [--overwrite]
  partsim assets categories
  partsim assets check DIR [--jobs J] [--no-visibility] [--backend B] [--report FILE]
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
categories   lists the 46 categories with the paper's model and part counts.
check        runs the quality checks on every object folder under DIR and prints the models and
             movable parts per category beside the paper's (`check --help` for more).
decompose    splits a non-convex mesh into convex OBJ pieces with a URDF <collision> snippet and
             reports coverage and excess (`decompose --help` for more).
)";

struct AssetsUsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

long long ParseInt(const std::string& flag, const std::string& v, long long lo) {
  long long n = 0;
  if (!ParseInteger(v, lo, &n))
    throw AssetsUsageError("partsim assets: " + flag +
                           " expects an integer >= " + std::to_string(lo) + ", got '" + v + "'");
  return n;
}

std::string Clock(double s) {
  char buf[32];
  int t = static_cast<int>(s + 0.5);
  std::snprintf(buf, sizeof(buf), "%d:%02d", t / 60, t % 60);
  return buf;
}

int Generate(const std::vector<std::string>& args) {
  GeneratorOptions opt;
  bool have_out = false;
  for (size_t i = 0; i < args.size(); ++i) {
    std::string flag = args[i], value;
    bool inline_value = false;
    if (size_t eq = flag.find('='); eq != std::string::npos && flag.rfind("--", 0) == 0) {
      value = flag.substr(eq + 1);
      flag = flag.substr(0, eq);
      inline_value = true;
    }
    auto next = [&]() {
      if (inline_value) return value;
      if (i + 1 >= args.size())
        throw AssetsUsageError("partsim assets: " + flag + " needs a value");
      return args[++i];
    };
    if (flag == "--out") {
      opt.out_dir = next();
      have_out = true;
    } else if (flag == "--categories") {
      std::string list = next();
      opt.categories.clear();
      if (list != "all") {
        std::stringstream in(list);
        std::string c;
        while (std::getline(in, c, ',')) {
          if (c.empty())
            throw AssetsUsageError("partsim assets: empty name in --categories '" + list + "'");
          opt.categories.push_back(c);
        }
      }
    } else if (flag == "--per-category") {
      std::string v = next();
      opt.per_category = v == "paper" ? 0 : static_cast<int>(ParseInt(flag, v, 1));
    } else if (flag == "--seed") {
      std::string v = next();
      char* end = nullptr;
      errno = 0;
      unsigned long long s = std::strtoull(v.c_str(), &end, 10);
      if (v.empty() || v[0] == '-' || *end != '\0' || errno == ERANGE) {
        throw AssetsUsageError("partsim assets: --seed expects an unsigned integer, got '" + v +
                               "'");
      }
      opt.seed = s;
    } else if (flag == "--jobs") {
      opt.jobs = static_cast<int>(ParseInt(flag, next(), 1));
    } else if (flag == "--by-category" && !inline_value) {
      opt.by_category = true;
    } else if (flag == "--overwrite" && !inline_value) {
      opt.overwrite = true;
    } else {
      throw AssetsUsageError("partsim assets generate: unknown argument '" + args[i] + "'");
    }
  }
  if (!have_out) throw AssetsUsageError("partsim assets generate: --out DIR is required");
  // unknown categories are a bad command line, refused before anything is written
  const std::vector<std::string> known = GeneratorCategories();
  for (const std::string& c : opt.categories) {
    if (std::find(known.begin(), known.end(), c) == known.end())
      throw AssetsUsageError("partsim assets generate: unknown category '" + c +
                             "' in --categories" + DidYouMean(c, known) +
                             " (partsim assets categories lists them)");
  }

  auto start = std::chrono::steady_clock::now();
  internal::ProgressLine progress(stderr);
  int written = GenerateDataset(opt, [&](int done, int total, const GeneratedObject& o) {
    double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double eta = done > 0 ? t / done * (total - done) : 0.0;
    progress.Update(done, total,
                    "[" + std::to_string(done) + "/" + std::to_string(total) + "] " + o.category +
                        " " + o.anno_id + "  elapsed " + Clock(t) + "  eta " + Clock(eta));
  });
  progress.Break();
  double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(stderr, "wrote %d objects to %s in %.1f s\n", written, opt.out_dir.c_str(), t);
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
  try {
    if (args.empty())
      throw AssetsUsageError(std::string("partsim assets: missing sub-command\n") + kAssetsUsage);
    for (const std::string& a : args) {
      if (a == "--help" || a == "-h") {
        std::printf("%s", kAssetsUsage);
        return 0;
      }
    }
    std::string sub = args[0];
    args.erase(args.begin());
    if (sub == "generate") return Generate(args);
    if (sub == "categories" && args.empty()) return ListCategories();
    throw AssetsUsageError("partsim assets: unknown sub-command '" + sub + "'" +
                           DidYouMean(sub, {"generate", "categories", "check", "decompose"}) +
                           " (expected generate, categories, check or decompose)");
  } catch (const AssetsUsageError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "partsim assets: %s\n", e.what());
    return 1;
  }
}

}  // namespace partsim::tools
