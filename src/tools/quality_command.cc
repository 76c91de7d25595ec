// `partsim assets check DIR`: quality checks of every object folder under DIR, with progress, a
// report of the failures and the statistics table.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "core/progress.h"
#include "partsim/assets/generator.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/assets/quality.h"
#include "partsim/render/visibility.h"

namespace partsim {

namespace {

using tools::ArgParser;
using tools::FlagValue;
using tools::RunWithExitCode;

constexpr const char* kCheckUsage =
    "usage: partsim assets check DIR [--jobs J] [--no-visibility] [--backend "
    "rasterizer|pathtracer]\n"
    "                            [--report FILE] [--limit N]\n"
    "Checks every PartNet-Mobility folder under DIR: it loads and its files agree; at rest "
    "nothing\n"
    "moves; each movable part covers its range without jamming; each shows in some view. Prints\n"
    "the failures, a summary and the models/parts table beside the SAPIEN paper's. The object\n"
    "folders are found at any depth, through symbolic links to folders.\n"
    "  --jobs J          objects checked at once (default 2)\n"
    "  --no-visibility   skip the view check (renders nothing)\n"
    "  --backend B       the view check's renderer: rasterizer (default) or pathtracer\n"
    "  --report FILE     also write every object's checks, then the summary, to FILE\n"
    "  --limit N         check only the first N folders, in path order\n"
    "Exit code: 0 all passed, 1 some failed, 2 bad command line.\n";

// A generate run was stopped while writing this object: it fails without being loaded.
ObjectQualityReport PartialReport(const std::string& folder) {
  ObjectQualityReport r;
  r.folder = folder;
  r.checks.push_back({"load", false,
                      "left by a generate run that was stopped before the object was whole; "
                      "generate again with --overwrite"});
  return r;
}

}  // namespace

int RunQualityCommand(int argc, char** argv) {
  const std::vector<std::string> args(argv, argv + argc);
  if (ArgParser::AsksForHelp(args)) {
    std::cout << kCheckUsage;
    return 0;
  }
  std::string dir, report_path;
  int jobs = 2;
  long long limit = -1;  // no limit
  QualityOptions options;
  const int parsed = RunWithExitCode("partsim assets check", kCheckUsage, [&] {
    ArgParser p("partsim assets check");
    p.Positional([&](const FlagValue& v) {
      if (!dir.empty()) v.Fail("unexpected argument '" + v.Text() + "' (one DIR only)");
      dir = v.Text();
    });
    p.Option("--jobs", [&](const FlagValue& v) {
      jobs = static_cast<int>(v.Integer(1, std::numeric_limits<int>::max()));
    });
    p.Switch("--no-visibility", [&] { options.check_visibility = false; });
    p.Option("--backend", [&](const FlagValue& v) {
      options.render_backend = v.Choice({"rasterizer", "pathtracer"}, {"null"});
    });
    p.Option("--report", [&](const FlagValue& v) { report_path = v.NonEmpty("a file name"); });
    p.Option("--limit", [&](const FlagValue& v) {
      limit = v.Integer(0, std::numeric_limits<long long>::max());
    });
    p.Switch("--help", [] {});  // answered above; declared to be suggested
    p.Parse(args);
    if (dir.empty()) p.Fail("no DIR given");
    return 0;
  });
  if (parsed != 0) return parsed;
  if (!std::filesystem::is_directory(dir)) {
    std::cerr << "partsim assets check: '" << dir << "' is not a folder\n";
    return 1;
  }
  // every object folder, in path order: one that holds any file of the dataset's layout (a
  // folder with textured_objs/ alone fails to load, it is not skipped), and the leftovers of
  // generate runs that were stopped (*.partial, failed without loading)
  // (at any depth, through symbolic links: a folder of links picks a subset of the dataset)
  std::vector<std::string> folders;
  try {
    folders = FindDatasetFolders(dir, [](const std::string& folder) {
      namespace fs = std::filesystem;
      const fs::path f(folder);
      std::error_code ec;
      return fs::exists(f / "mobility_v2.json", ec) || fs::exists(f / "mobility.urdf", ec) ||
             fs::exists(f / "semantics.txt", ec) || fs::is_directory(f / "textured_objs", ec);
    });
  } catch (const Error& e) {
    std::cerr << "partsim assets check: " << e.what() << "\n";
    return 1;
  }
  if (limit >= 0 && static_cast<long long>(folders.size()) > limit)
    folders.resize(static_cast<size_t>(limit));
  if (folders.empty()) {
    std::cerr << "partsim assets check: no object folder (with mobility_v2.json) under '" << dir
              << "'\n";
    return 1;
  }

  // the visibility check renders: the finder comes from the render layer
  if (options.check_visibility)
    options.hidden_parts = HiddenMovingLinksFinder(options.render_backend, options.image_size);
  // check on a few threads; each object has its own scene
  std::vector<ObjectQualityReport> reports(folders.size());
  std::atomic<size_t> next{0}, done{0};
  std::mutex print;  // guards stderr and progress
  internal::ProgressLine progress(stderr);
  auto start = std::chrono::steady_clock::now();
  auto worker = [&] {
    for (size_t i = next++; i < folders.size(); i = next++) {
      reports[i] = IsPartialObjectFolder(folders[i]) ? PartialReport(folders[i])
                                                     : CheckPartNetObject(folders[i], options);
      size_t n = ++done;
      std::lock_guard<std::mutex> lock(print);
      double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!reports[i].Passed()) {
        progress.Break();
        std::cerr << reports[i].ToString();
      }
      char line[128];
      std::snprintf(line, sizeof(line), "checked %zu/%zu objects, %.0f s elapsed, %.0f s left", n,
                    folders.size(), t, t / n * (folders.size() - n));
      progress.Update(static_cast<long>(n), static_cast<long>(folders.size()), line);
    }
  };
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  progress.Break();
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // summary, per check and per category
  DatasetStatistics stats;
  int failed = 0;
  std::map<std::string, int> failed_by_check;
  for (const ObjectQualityReport& r : reports) {
    if (!r.category.empty()) stats.Add(r.category, r.movable_parts);
    if (r.Passed()) continue;
    ++failed;
    for (const QualityCheck& c : r.checks)
      if (!c.passed) ++failed_by_check[c.name];
  }
  std::ostringstream out;
  out << "checked " << reports.size() << " objects in " << seconds
      << " s: " << reports.size() - failed << " passed, " << failed << " failed\n";
  for (const auto& [check, n] : failed_by_check) out << "  failed '" << check << "': " << n << "\n";
  out << "\n" << stats.ToTable();
  std::cout << out.str();
  if (!report_path.empty()) {
    std::ofstream f(report_path);
    if (!f) {
      std::cerr << "partsim assets check: cannot write the report '" << report_path << "'\n";
      return 1;
    }
    for (const ObjectQualityReport& r : reports) f << r.ToString();
    f << "\n" << out.str();
  }
  return failed == 0 ? 0 : 1;
}

}  // namespace partsim
