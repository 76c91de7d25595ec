// `partsim assets check DIR`: quality checks of every object folder under DIR, with progress, a
// report of the failures and the statistics table.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "core/atomic_file.h"
#include "core/file_read.h"
#include "core/json_parse.h"
#include "core/progress.h"
#include "partsim/assets/generator.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/assets/quality.h"
#include "partsim/core/error.h"
#include "partsim/render/visibility.h"

namespace partsim {

namespace {

using tools::ArgParser;
using tools::FlagValue;
using tools::RunWithExitCode;

constexpr const char* kCheckUsage =
    "usage: partsim assets check DIR [--jobs J] [--no-visibility] [--backend "
    "rasterizer|pathtracer]\n"
    "                            [--report FILE] [--limit N] [--shard i/N] [--results FILE]\n"
    "       partsim assets check --merge FILE... [--report FILE] [--results FILE]\n"
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
    "  --shard i/N       check only the folders whose index in path order (after --limit) % N\n"
    "                    is i; the summary and table are then this shard's\n"
    "  --results FILE    also write every checked object's outcome, as JSON, to FILE (whole or\n"
    "                    not at all)\n"
    "  --merge FILE...   read the --results files of shards of one check of DIR and print,\n"
    "                    report and write the results exactly as one run over all of DIR would\n"
    "                    (with its exit code); overlapping shards, missing objects or results\n"
    "                    of different runs are refused, naming the files\n"
    "The time taken goes to stderr, so that stdout and --report are the same however the check\n"
    "is split.\n"
    "Exit code: 0 all passed, 1 some failed (or a file could not be read), 2 bad command line.\n";

// What `--results` holds: the run (DIR as given, the number of folders under it, the options
// that change the outcome) and the outcome of each checked folder by its index in path order.
struct CheckResults {
  std::string dir;
  size_t folders = 0;
  bool visibility = true;
  std::string backend;
  std::map<size_t, ObjectQualityReport> objects;  // by index in path order
};

// A generate run was stopped while writing this object: it fails without being loaded.
ObjectQualityReport PartialReport(const std::string& folder) {
  ObjectQualityReport r;
  r.folder = folder;
  r.checks.push_back({"load", false,
                      "left by a generate run that was stopped before the object was whole; "
                      "generate again with --overwrite"});
  return r;
}

constexpr const char* kResultsFormat = "partsim assets check results";

std::string ResultsJson(const CheckResults& results) {
  nlohmann::json objects = nlohmann::json::array();
  for (const auto& [index, r] : results.objects) {
    nlohmann::json checks = nlohmann::json::array();
    for (const QualityCheck& c : r.checks)
      checks.push_back({{"name", c.name}, {"passed", c.passed}, {"detail", c.detail}});
    objects.push_back({{"index", index},
                       {"folder", r.folder},
                       {"category", r.category},
                       {"model_id", r.model_id},
                       {"movable_parts", r.movable_parts},
                       {"checks", checks}});
  }
  const nlohmann::json j = {{"format", kResultsFormat},   {"dir", results.dir},
                            {"folders", results.folders}, {"visibility", results.visibility},
                            {"backend", results.backend}, {"objects", objects}};
  return j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

// Reads a --results file; throws partsim::Error naming the file and what is wrong with it.
CheckResults ReadResults(const std::string& path) {
  const std::string text = internal::ReadWholeFile(path, "results file");
  CheckResults out;
  try {
    const nlohmann::json j = internal::ParseJsonBounded(text);
    if (!j.is_object() || j.value("format", "") != kResultsFormat)
      throw Error("'" + path + "' is not a results file of partsim assets check (--results)");
    out.dir = j.at("dir").get<std::string>();
    out.folders = j.at("folders").get<size_t>();
    out.visibility = j.at("visibility").get<bool>();
    out.backend = j.at("backend").get<std::string>();
    for (const nlohmann::json& o : j.at("objects")) {
      ObjectQualityReport r;
      const size_t index = o.at("index").get<size_t>();
      r.folder = o.at("folder").get<std::string>();
      r.category = o.at("category").get<std::string>();
      r.model_id = o.at("model_id").get<std::string>();
      r.movable_parts = o.at("movable_parts").get<int>();
      for (const nlohmann::json& c : o.at("checks"))
        r.checks.push_back({c.at("name").get<std::string>(), c.at("passed").get<bool>(),
                            c.at("detail").get<std::string>()});
      if (index >= out.folders)
        throw Error("'" + path + "': object " + std::to_string(index) + " of " +
                    std::to_string(out.folders) + " folders");
      if (!out.objects.emplace(index, std::move(r)).second)
        throw Error("'" + path + "' holds object " + std::to_string(index) + " twice");
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error("'" + path + "' is not a results file of partsim assets check: " + e.what());
  }
  return out;
}

// The shards' results as one run's: the same run (DIR, folders, options), no object twice, none
// missing. Throws partsim::Error naming the files at fault.
CheckResults MergeResults(const std::vector<std::string>& paths) {
  CheckResults merged;
  std::map<size_t, std::string> owner;  // object index -> the file it came from
  for (size_t k = 0; k < paths.size(); ++k) {
    CheckResults shard = ReadResults(paths[k]);
    if (k == 0) {
      merged.dir = shard.dir;
      merged.folders = shard.folders;
      merged.visibility = shard.visibility;
      merged.backend = shard.backend;
    } else if (shard.dir != merged.dir || shard.folders != merged.folders ||
               shard.visibility != merged.visibility || shard.backend != merged.backend) {
      auto run = [](const CheckResults& r) {
        return "'" + r.dir + "' (" + std::to_string(r.folders) + " folders, " +
               (r.visibility ? "view check with " + r.backend : std::string("no view check")) + ")";
      };
      throw Error("'" + paths[0] + "' and '" + paths[k] +
                  "' are results of different checks: " + run(merged) + " and " + run(shard));
    }
    for (auto& [index, r] : shard.objects) {
      const auto [it, added] = owner.emplace(index, paths[k]);
      if (!added)
        throw Error("'" + it->second + "' and '" + paths[k] + "' both hold object " +
                    std::to_string(index) + " ('" + r.folder + "'): the shards overlap");
      merged.objects.emplace(index, std::move(r));
    }
  }
  if (merged.objects.size() != merged.folders) {
    std::string missing;
    int listed = 0;
    for (size_t i = 0; i < merged.folders && listed < 5; ++i)
      if (!merged.objects.count(i)) missing += (listed++ ? ", " : "") + std::to_string(i);
    throw Error("the results cover " + std::to_string(merged.objects.size()) + " of the " +
                std::to_string(merged.folders) + " folders under '" + merged.dir +
                "' (none has object " + missing +
                (merged.folders - merged.objects.size() > 5 ? ", ..." : "") +
                "): is a shard's file missing?");
  }
  return merged;
}

// The summary and table on stdout, the report and the results files; the exit code.
int Finish(const CheckResults& results, const std::string& report_path,
           const std::string& results_path) {
  // summary, per check and per category
  DatasetStatistics stats;
  int failed = 0;
  std::map<std::string, int> failed_by_check;
  for (const auto& [index, r] : results.objects) {
    if (!r.category.empty()) stats.Add(r.category, r.movable_parts);
    if (r.Passed()) continue;
    ++failed;
    for (const QualityCheck& c : r.checks)
      if (!c.passed) ++failed_by_check[c.name];
  }
  std::ostringstream out;
  out << "checked " << results.objects.size() << " objects: " << results.objects.size() - failed
      << " passed, " << failed << " failed\n";
  for (const auto& [check, n] : failed_by_check) out << "  failed '" << check << "': " << n << "\n";
  out << "\n" << stats.ToTable();
  std::cout << out.str();
  try {
    if (!report_path.empty()) {
      std::string report;
      for (const auto& [index, r] : results.objects) report += r.ToString();
      internal::WriteFileAtomically(report_path, report + "\n" + out.str());
    }
    if (!results_path.empty()) internal::WriteFileAtomically(results_path, ResultsJson(results));
  } catch (const Error& e) {
    std::cerr << "partsim assets check: " << e.what() << "\n";
    return 1;
  }
  return failed == 0 ? 0 : 1;
}

int RunMerge(const std::vector<std::string>& args) {
  std::vector<std::string> files;
  std::string report_path, results_path;
  const int parsed = RunWithExitCode("partsim assets check", kCheckUsage, [&] {
    ArgParser p("partsim assets check --merge", "partsim assets check --help");
    p.Option("--merge", [&](const FlagValue& v) { files.push_back(v.NonEmpty("a file name")); });
    p.Positional([&](const FlagValue& v) { files.push_back(v.Text()); });
    p.Option("--report", [&](const FlagValue& v) { report_path = v.NonEmpty("a file name"); });
    p.Option("--results", [&](const FlagValue& v) { results_path = v.NonEmpty("a file name"); });
    p.Parse(args);
    return 0;
  });
  if (parsed != 0) return parsed;
  CheckResults merged;
  try {
    merged = MergeResults(files);
  } catch (const Error& e) {
    std::cerr << "partsim assets check --merge: " << e.what() << "\n";
    return 1;
  }
  // the failures, in path order (a run prints them as they come)
  for (const auto& [index, r] : merged.objects)
    if (!r.Passed()) std::cerr << r.ToString();
  return Finish(merged, report_path, results_path);
}

}  // namespace

int RunQualityCommand(int argc, char** argv) {
  const std::vector<std::string> args(argv, argv + argc);
  if (ArgParser::AsksForHelp(args)) {
    std::cout << kCheckUsage;
    return 0;
  }
  // --merge reads results files instead of DIR, with a command line of its own
  if (std::any_of(args.begin(), args.end(), [](const std::string& a) {
        return a == "--merge" || a.rfind("--merge=", 0) == 0;
      }))
    return RunMerge(args);
  std::string dir, report_path, results_path;
  int jobs = 2;
  long long limit = -1;  // no limit
  int shard_index = 0, shard_count = 1;
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
    p.Option("--results", [&](const FlagValue& v) { results_path = v.NonEmpty("a file name"); });
    p.Option("--limit", [&](const FlagValue& v) {
      limit = v.Integer(0, std::numeric_limits<long long>::max());
    });
    p.Option("--shard",
             [&](const FlagValue& v) { std::tie(shard_index, shard_count) = v.Shard(); });
    p.Option("--merge", [](const FlagValue&) {});  // answered above; declared to be suggested
    p.Switch("--help", [] {});                     // answered above; declared to be suggested
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
  // this shard's folders, by their index in path order
  std::vector<size_t> mine;
  for (size_t i = static_cast<size_t>(shard_index); i < folders.size(); i += shard_count)
    mine.push_back(i);

  // the visibility check renders: the finder comes from the render layer
  if (options.check_visibility)
    options.hidden_parts = HiddenMovingLinksFinder(options.render_backend, options.image_size);
  // check on a few threads; each object has its own scene
  std::vector<ObjectQualityReport> reports(mine.size());
  std::atomic<size_t> next{0}, done{0};
  std::mutex print;  // guards stderr and progress
  internal::ProgressLine progress(stderr);
  auto start = std::chrono::steady_clock::now();
  auto worker = [&] {
    for (size_t i = next++; i < mine.size(); i = next++) {
      const std::string& folder = folders[mine[i]];
      reports[i] = IsPartialObjectFolder(folder) ? PartialReport(folder)
                                                 : CheckPartNetObject(folder, options);
      size_t n = ++done;
      std::lock_guard<std::mutex> lock(print);
      double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!reports[i].Passed()) {
        progress.Break();
        std::cerr << reports[i].ToString();
      }
      char line[128];
      std::snprintf(line, sizeof(line), "checked %zu/%zu objects, %.0f s elapsed, %.0f s left", n,
                    mine.size(), t, t / n * (mine.size() - n));
      progress.Update(static_cast<long>(n), static_cast<long>(mine.size()), line);
    }
  };
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  progress.Break();
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cerr << "checked " << mine.size() << " objects in " << seconds << " s\n";

  CheckResults results;
  results.dir = dir;
  results.folders = folders.size();
  results.visibility = options.check_visibility;
  results.backend = options.check_visibility ? options.render_backend : "";
  for (size_t i = 0; i < mine.size(); ++i) results.objects.emplace(mine[i], std::move(reports[i]));
  return Finish(results, report_path, results_path);
}

}  // namespace partsim
