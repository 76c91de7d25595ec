// `partsim tasks demo|evaluate`: the drawer and door tasks with the heuristic solvers, on
// generated cabinets.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "core/atomic_file.h"
#include "core/file_read.h"
#include "core/json_parse.h"
#include "partsim/assets/generator.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/core/error.h"
#include "partsim/tasks/tasks.h"

namespace partsim::tools {
namespace {

constexpr char kTasksUsage[] = R"(usage:
  partsim tasks demo [--task drawer|door] [--object N] [--seed S] [--out DIR] [--every K]
                     [--video FILE | --no-video] [--frames] [--size WxH]
  partsim tasks evaluate [--task drawer|door] [--count N] [--seed S] [--jobs J]
                         [--no-cameras] [--csv FILE] [--shard i/N]
                         [--dataset ROOT [--ids A,B,...] [--targets all|one]]
  partsim tasks evaluate --merge CSV... [--csv FILE]

demo       generates a cabinet (StorageFurniture object N of 0..344, default the first with a
           drawer or door), runs the heuristic solver with the flying gripper and reports
           success. A camera with a three-quarter view records the episode, on a floor with
           shadows, every K control steps (default 2: 25 frames per second of simulated time)
           into an H.264 video, DIR/demo.mp4 (default out/demo) or FILE, at WxH pixels (default
           640x480). --frames also writes the frames as DIR/frame_NNNNN.png.
evaluate   runs the heuristic solver on the first N cabinets (default 20) that have a drawer
           (door), one target each drawn by the seed, and prints the success rate beside the
           SAPIEN paper's (95.3% drawer, 81.8% door). --no-cameras perceives the handle from the
           meshes instead of the segmented point clouds. --csv writes one row per episode.
           With --dataset, the objects are the PartNet-Mobility folders under ROOT (real or
           generated, sorted by name; --ids keeps the named folders): the first N (all with
           --ids) that have a target, i.e. a link labelled 'drawer' ('rotation_door') in
           semantics.txt with a handle; --targets all runs every target of each object.
           The time taken goes to stderr. --shard i/N runs only the episodes whose index in
           the whole run's order % N is i (each with the seed it has in the whole run); its CSV
           starts with a '# partsim tasks evaluate shard: {...}' line naming the run and the
           episodes, then has the whole run's header and those episodes' rows. --merge reads
           the shards' CSVs and prints what the whole run prints; --csv then writes the
           whole run's CSV (rows in its order). Shards of different runs, overlapping or
           missing ones are refused, naming the files.

demo and evaluate:
  --task drawer|door   which task (default drawer)
  --seed S             episode seed (default 0)
demo:
  --object N           the generated StorageFurniture object, 0 to 344 (default: the first
                       with a drawer or door)
  --out DIR            output folder (default out/demo)
  --every K            one frame every K control steps (default 2)
  --video FILE         the video's file (default DIR/demo.mp4)
  --no-video           record no video
  --frames             also write the frames as DIR/frame_NNNNN.png
  --size WxH           picture size in pixels (default 640x480)
evaluate:
  --count N            number of objects (default 20; with --ids, every named one)
  --jobs J             episodes in parallel (default 1)
  --no-cameras         perceive the handle from the meshes, not segmented point clouds
  --csv FILE           one row per episode: object, target, success, progress, seconds, stage,
                       message (written whole or not at all)
  --shard i/N          run only the episodes whose index % N is i
  --merge CSV...       the CSVs of the shards of one run, merged (takes only --csv besides)
  --dataset ROOT       the PartNet-Mobility folders under ROOT (at any depth, through symbolic
                       links to folders) instead of generated cabinets
  --ids A,B,...        with --dataset: only the folders of these names, in this order
  --targets all|one    with --dataset: every target of each object, or one drawn by the seed
                       (default one)
)";

struct TasksArgs {
  std::string command;
  TaskType type = TaskType::kPullDrawer;
  int object = -1;
  int count = 20;
  unsigned long long seed = 0;
  int jobs = 1;
  int every = 2;
  std::string video;  // "" = <out>/demo.mp4
  bool no_video = false;
  bool frames = false;
  int width = 640;
  int height = 480;
  bool cameras = true;
  std::string out = "out/demo";
  std::string csv;
  std::string dataset;
  std::vector<std::string> ids;
  bool all_targets = false;
  bool count_given = false;
  int shard_index = 0;
  int shard_count = 1;
  bool sharded = false;
  std::vector<std::string> merge;  // --merge: the shards' CSVs
};

// The first line of a shard's CSV, before the whole run's header.
constexpr char kShardLine[] = "# partsim tasks evaluate shard: ";
constexpr char kCsvHeader[] = "object,target,success,progress,seconds,stage,message";

// The command line of --merge: the shards' CSVs and --csv.
TasksArgs ParseMerge(const std::vector<std::string>& args) {
  TasksArgs a;
  a.command = "evaluate";
  ArgParser p("partsim tasks evaluate --merge", "partsim tasks --help");
  p.Option("--merge", [&](const FlagValue& v) { a.merge.push_back(v.NonEmpty("a CSV file")); });
  p.Positional([&](const FlagValue& v) { a.merge.push_back(v.Text()); });
  p.Option("--csv", [&](const FlagValue& v) { a.csv = v.NonEmpty("a file name"); });
  p.Parse(std::vector<std::string>(args.begin() + 1, args.end()));
  return a;
}

TasksArgs Parse(const std::vector<std::string>& args) {
  TasksArgs a;
  ArgParser p("partsim tasks");
  if (args.empty()) p.Fail("expected demo or evaluate");
  a.command = args[0];
  if (a.command != "demo" && a.command != "evaluate")
    p.Fail("unknown command '" + a.command + "'" + DidYouMean(a.command, {"demo", "evaluate"}) +
           " (expected demo or evaluate)");
  if (a.command == "evaluate" && std::any_of(args.begin(), args.end(), [](const std::string& s) {
        return s == "--merge" || s.rfind("--merge=", 0) == 0;
      }))
    return ParseMerge(args);
  p.Option("--task", [&](const FlagValue& v) {
    a.type = ParseTaskType(v.Choice({"drawer", "door"}));
  });
  p.Option("--object", [&](const FlagValue& v) {
    const int objects = PaperModelCount("StorageFurniture");
    a.object = static_cast<int>(v.Integer(0, std::numeric_limits<int>::max()));
    if (a.object >= objects)
      v.Fail("--object " + std::to_string(a.object) +
             " is out of range: the generated dataset has " + std::to_string(objects) +
             " StorageFurniture objects (0 to " + std::to_string(objects - 1) + ")");
  });
  p.Option("--count", [&](const FlagValue& v) {
    a.count = static_cast<int>(v.Integer(1, std::numeric_limits<int>::max()));
    a.count_given = true;
  });
  p.Option("--dataset", [&](const FlagValue& v) { a.dataset = v.Text(); });
  p.Option("--ids", [&](const FlagValue& v) {
    for (const std::string& id : v.Names()) a.ids.push_back(id);
  });
  p.Option("--targets", [&](const FlagValue& v) {
    a.all_targets = v.Choice({"all", "one"}) == "all";
  });
  p.Option("--seed", [&](const FlagValue& v) { a.seed = v.Unsigned(); });
  p.Option("--jobs", [&](const FlagValue& v) {
    a.jobs = static_cast<int>(v.Integer(1, std::numeric_limits<int>::max()));
  });
  p.Option("--every", [&](const FlagValue& v) {
    a.every = static_cast<int>(v.Integer(1, std::numeric_limits<int>::max()));
  });
  p.Option("--video", [&](const FlagValue& v) { a.video = v.NonEmpty("a file name"); });
  p.Switch("--no-video", [&] { a.no_video = true; });
  p.Switch("--frames", [&] { a.frames = true; });
  p.Option("--size", [&](const FlagValue& v) { std::tie(a.width, a.height) = v.Size(16, 4096); });
  p.Option("--out", [&](const FlagValue& v) { a.out = v.Text(); });
  p.Option("--csv", [&](const FlagValue& v) { a.csv = v.Text(); });
  p.Switch("--no-cameras", [&] { a.cameras = false; });
  p.Option("--shard", [&](const FlagValue& v) {
    std::tie(a.shard_index, a.shard_count) = v.Shard();
    a.sharded = true;
  });
  p.Parse(std::vector<std::string>(args.begin() + 1, args.end()));
  if (a.dataset.empty() && (!a.ids.empty() || a.all_targets))
    p.Fail("--ids and --targets need --dataset");
  if (a.command != "demo" && (!a.video.empty() || a.no_video || a.frames))
    p.Fail("--video, --no-video and --frames go with demo");
  if (!a.video.empty() && a.no_video) p.Fail("--video and --no-video exclude each other");
  if (!a.dataset.empty() && a.command != "evaluate") p.Fail("--dataset goes with evaluate");
  if (a.sharded && a.command != "evaluate") p.Fail("--shard goes with evaluate");
  return a;
}

// One episode of evaluate: a generated object by index, or a dataset folder; a target index in
// the object's FindTaskTargets list (-1: drawn by the episode's seed).
struct Episode {
  std::string object;  // the CSV's object column: generator index or folder name
  int index = -1;
  std::string folder;
  int target = -1;
};

// The episodes of --dataset: folders under ROOT holding mobility.urdf, by name.
std::vector<Episode> DatasetEpisodes(const TasksArgs& a) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(a.dataset, ec))
    throw std::runtime_error("--dataset '" + a.dataset + "' is not a folder");
  // object folders at any depth, through symbolic links (a subset of the dataset)
  std::vector<fs::path> folders;
  try {
    for (const std::string& f : FindPartNetMobilityFolders(a.dataset)) folders.emplace_back(f);
  } catch (const Error& e) {
    throw std::runtime_error(std::string("--dataset: ") + e.what());
  }
  if (!a.ids.empty()) {
    std::vector<fs::path> keep;
    for (const std::string& id : a.ids) {
      auto it = std::find_if(folders.begin(), folders.end(),
                             [&](const fs::path& f) { return f.filename() == id; });
      if (it == folders.end())
        throw std::runtime_error("--ids: no PartNet-Mobility folder '" + id + "' under '" +
                                 a.dataset + "'");
      keep.push_back(*it);
    }
    folders = keep;
  }
  const size_t wanted = !a.ids.empty() && !a.count_given ? folders.size() : a.count;
  std::vector<Episode> out;
  size_t objects = 0;
  PartNetMobilityLoader loader;
  for (const fs::path& f : folders) {
    if (objects >= wanted) break;
    std::vector<int> targets;
    try {
      targets = FindTaskTargets(loader.Parse(f.string()), a.type);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "  %s: skipped: %s\n", f.filename().c_str(), e.what());
      continue;
    }
    if (targets.empty()) {
      if (!a.ids.empty())
        std::fprintf(stderr, "  %s: skipped: no %s with a handle\n", f.filename().c_str(),
                     TaskTargetLabel(a.type));
      continue;
    }
    ++objects;
    const int n = a.all_targets ? static_cast<int>(targets.size()) : 1;
    for (int t = 0; t < n; ++t) {
      Episode e;
      e.object = f.filename().string();
      e.folder = f.string();
      e.target = a.all_targets ? t : -1;
      out.push_back(e);
    }
  }
  if (out.empty())
    throw std::runtime_error("no object under '" + a.dataset + "' has a " + TaskTypeName(a.type) +
                             " (a link labelled '" + TaskTargetLabel(a.type) + "' with a handle)");
  return out;
}

int RunDemo(const TasksArgs& a) {
  TaskOptions o;
  o.type = a.type;
  o.object_index = a.object >= 0 ? a.object : FindTaskObjects(a.type, 1).front();
  const bool record = a.frames || !a.no_video;
  if (record) {
    o.video_width = a.width;
    o.video_height = a.height;
  }
  const std::string video = a.no_video ? ""
                            : !a.video.empty()
                                ? a.video
                                : (std::filesystem::path(a.out) / "demo.mp4").string();
  ArticulationTask task(o);  // checks the object before anything is written
  std::filesystem::create_directories(a.out);
  if (!video.empty() && std::filesystem::path(video).has_parent_path())
    std::filesystem::create_directories(std::filesystem::path(video).parent_path());
  // the frames of an earlier demo in the same folder go first: none is left beside this run's
  ClearOwnedOutputs(a.out, {{"frame_", ".png"}});
  task.Reset(a.seed);
  std::printf("partsim tasks demo: %s task on StorageFurniture object %d, target %s\n",
              TaskTypeName(a.type), o.object_index, task.GetTargetLink().GetName().c_str());
  SolverOptions so;
  if (a.frames) so.frames_dir = a.out;
  so.video_path = video;
  so.frame_every = a.every;
  auto t0 = std::chrono::steady_clock::now();
  SolverResult r = SolveTask(task, so);
  double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("  %s: opened %.0f%% of the range in %.1f s simulated (%.1f s wall)\n",
              r.success ? "SUCCESS" : "FAILURE", 100.0 * r.progress, r.seconds, wall);
  if (!r.success) std::printf("  stage %s: %s\n", r.stage.c_str(), r.message.c_str());
  if (a.frames) {
    int frames = 0;
    for (const auto& e : std::filesystem::directory_iterator(a.out))
      frames +=
          e.path().filename().string().rfind("frame_", 0) == 0 && e.path().extension() == ".png";
    std::printf("  frames: %d PNG in %s\n", frames, a.out.c_str());
  }
  if (!video.empty())
    std::printf("  video: %s (%dx%d, %.0f fps)\n", video.c_str(), a.width & ~1, a.height & ~1,
                o.control_rate / a.every);
  return r.success ? 0 : 1;
}

// What decides a run's episodes and their outcomes, as flags: shards of one run share it.
std::string RunFlags(const TasksArgs& a) {
  std::string flags = std::string("--task ") +
                      (a.type == TaskType::kPullDrawer ? "drawer" : "door") + " --seed " +
                      std::to_string(a.seed) + (a.cameras ? "" : " --no-cameras");
  if (a.dataset.empty()) return flags + " --count " + std::to_string(a.count);
  flags += " --dataset " + a.dataset;
  if (!a.ids.empty()) {
    flags += " --ids ";
    for (size_t i = 0; i < a.ids.size(); ++i) flags += (i ? "," : "") + a.ids[i];
  }
  if (a.ids.empty() || a.count_given) flags += " --count " + std::to_string(a.count);
  return flags + (a.all_targets ? " --targets all" : "");
}

// The line evaluate prints: successes beside the paper's rate.
void PrintSuccessRate(TaskType type, bool cameras, int ok, size_t episodes) {
  const double paper = type == TaskType::kPullDrawer ? 95.3 : 81.8;
  std::printf(
      "%s task, heuristic solver (%s perception): %d / %zu succeeded = %.1f%% "
      "(SAPIEN paper: %.1f%%)\n",
      TaskTypeName(type), cameras ? "ground-truth segmented point clouds" : "meshes", ok, episodes,
      100.0 * ok / episodes, paper);
}

// A CSV field: quoted, with its quotes doubled (RFC 4180), so that a message may hold anything.
std::string CsvQuoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// Splits `text` at `separator` outside quoted fields ("" inside a field keeps it quoted).
std::vector<std::string> SplitOutsideQuotes(const std::string& text, char separator) {
  std::vector<std::string> pieces(1);
  bool quoted = false;
  for (char c : text) {
    if (c == '"') quoted = !quoted;
    if (c == separator && !quoted)
      pieces.emplace_back();
    else
      pieces.back() += c;
  }
  return pieces;
}

int RunEvaluate(const TasksArgs& a) {
  std::vector<Episode> objects;
  if (!a.dataset.empty()) {
    objects = DatasetEpisodes(a);
  } else {
    for (int i : FindTaskObjects(a.type, a.count)) {
      Episode e;
      e.object = std::to_string(i);
      e.index = i;
      objects.push_back(e);
    }
  }
  // this shard's episodes, by their index in the whole run (which picks their seeds)
  std::vector<size_t> mine;
  for (size_t i = static_cast<size_t>(a.shard_index); i < objects.size(); i += a.shard_count)
    mine.push_back(i);
  std::vector<SolverResult> results(objects.size());
  std::vector<std::string> targets(objects.size());
  std::atomic<size_t> next{0};
  std::mutex io;
  auto t0 = std::chrono::steady_clock::now();
  auto worker = [&]() {
    for (size_t k = next++; k < mine.size(); k = next++) {
      const size_t i = mine[k];
      try {
        TaskOptions o;
        o.type = a.type;
        o.object_index = std::max(0, objects[i].index);
        o.object_folder = objects[i].folder;
        o.target = objects[i].target;
        o.cameras = a.cameras;
        ArticulationTask task(o);
        task.Reset(a.seed + i);
        targets[i] = task.GetTargetLink().GetName();
        SolverOptions so;
        so.use_cameras = a.cameras;
        results[i] = SolveTask(task, so);
      } catch (const std::exception& e) {
        results[i].message = std::string("error: ") + e.what();
        results[i].stage = "error";
      }
      std::lock_guard<std::mutex> lock(io);
      std::fprintf(stderr, "  object %4s %-8s %s progress %5.1f%%  %s %s\n",
                   objects[i].object.c_str(), targets[i].c_str(),
                   results[i].success ? "ok  " : "FAIL", 100 * results[i].progress,
                   results[i].stage.c_str(), results[i].message.c_str());
    }
  };
  std::vector<std::thread> pool;
  for (int j = 0; j < a.jobs; ++j) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  int ok = 0;
  for (size_t i : mine) ok += results[i].success;
  if (a.sharded)
    std::fprintf(stderr, "shard %d/%d: %zu of the run's %zu episodes\n", a.shard_index,
                 a.shard_count, mine.size(), objects.size());
  if (mine.empty()) {
    std::printf("%s task: no episode in this shard\n", TaskTypeName(a.type));
  } else {
    PrintSuccessRate(a.type, a.cameras, ok, mine.size());
  }
  std::fprintf(stderr, "%zu episodes in %.0f s wall\n", mine.size(), wall);
  if (!a.csv.empty()) {
    std::ostringstream f;
    if (a.sharded) {
      const nlohmann::json shard = {
          {"run", RunFlags(a)},
          {"task", a.type == TaskType::kPullDrawer ? "drawer" : "door"},
          {"cameras", a.cameras},
          {"episodes", objects.size()},
          {"shard", std::to_string(a.shard_index) + "/" + std::to_string(a.shard_count)},
          {"rows", mine}};
      f << kShardLine << internal::DumpJson(shard) << "\n";
    }
    f << kCsvHeader << "\n";
    for (size_t i : mine)
      f << objects[i].object << ',' << targets[i] << ',' << results[i].success << ','
        << results[i].progress << ',' << results[i].seconds << ',' << results[i].stage << ','
        << CsvQuoted(results[i].message) << "\n";
    internal::WriteFileAtomically(a.csv, f.str());
  }
  return 0;
}

// --merge: the shards' CSVs as the whole run's.
int RunMergeEvaluate(const TasksArgs& a) {
  if (a.merge.empty()) throw UsageError("partsim tasks evaluate --merge: no CSV given");
  struct Shard {
    std::string path;
    nlohmann::json meta;
  };
  std::vector<Shard> shards;
  std::map<size_t, std::pair<std::string, std::string>> rows;  // episode -> (row, its file)
  size_t episodes = 0;
  for (const std::string& path : a.merge) {
    const std::string text = internal::ReadWholeFile(path, "CSV");
    const std::string what = "'" + path + "' is not the CSV of a partsim tasks evaluate --shard";
    std::vector<std::string> lines = SplitOutsideQuotes(text, '\n');
    if (!lines.empty() && lines.back().empty()) lines.pop_back();
    if (lines.size() < 2 || lines[0].rfind(kShardLine, 0) != 0)
      throw std::runtime_error(what + " run (its first line is not '" + kShardLine + "{...}')");
    if (lines[1] != kCsvHeader)
      throw std::runtime_error(what + " run (its second line is not '" + kCsvHeader + "')");
    Shard s{path, {}};
    std::vector<size_t> indices;
    try {
      s.meta = internal::ParseJsonBounded(lines[0].substr(std::strlen(kShardLine)));
      indices = s.meta.at("rows").get<std::vector<size_t>>();
      s.meta.at("task").get<std::string>();
      s.meta.at("cameras").get<bool>();
      s.meta.at("run").get<std::string>();
      episodes = s.meta.at("episodes").get<size_t>();
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(what + " run: its first line: " + e.what());
    }
    if (indices.size() != lines.size() - 2)
      throw std::runtime_error("'" + path + "' has " + std::to_string(lines.size() - 2) +
                               " rows, its first line names " + std::to_string(indices.size()) +
                               " episodes: was it cut short?");
    if (!shards.empty()) {
      const nlohmann::json& first = shards[0].meta;
      for (const char* key : {"run", "episodes"})
        if (s.meta.at(key) != first.at(key))
          throw std::runtime_error(
              "'" + shards[0].path + "' and '" + path +
              "' are shards of different runs: " + first.at("run").get<std::string>() + " (" +
              std::to_string(first.at("episodes").get<size_t>()) + " episodes) and " +
              s.meta.at("run").get<std::string>() + " (" + std::to_string(episodes) + " episodes)");
    }
    for (size_t k = 0; k < indices.size(); ++k) {
      if (indices[k] >= episodes)
        throw std::runtime_error("'" + path + "' names episode " + std::to_string(indices[k]) +
                                 " of a run of " + std::to_string(episodes));
      const auto [it, added] = rows.emplace(indices[k], std::make_pair(lines[k + 2], path));
      if (!added)
        throw std::runtime_error("'" + it->second.second + "' and '" + path +
                                 "' both hold episode " + std::to_string(indices[k]) +
                                 ": the shards overlap");
    }
    shards.push_back(std::move(s));
  }
  if (rows.size() != episodes) {
    std::string missing;
    int listed = 0;
    for (size_t i = 0; i < episodes && listed < 5; ++i)
      if (!rows.count(i)) missing += (listed++ ? ", " : "") + std::to_string(i);
    throw std::runtime_error("the CSVs hold " + std::to_string(rows.size()) + " of the run's " +
                             std::to_string(episodes) + " episodes (none has episode " + missing +
                             (episodes - rows.size() > 5 ? ", ..." : "") +
                             "): is a shard's CSV missing?");
  }
  // the success column of each row, in the whole run's order
  int ok = 0;
  std::string csv = std::string(kCsvHeader) + "\n";
  for (const auto& [index, row] : rows) {
    const std::vector<std::string> fields = SplitOutsideQuotes(row.first, ',');
    if (fields.size() != 7 || (fields[2] != "0" && fields[2] != "1"))
      throw std::runtime_error("'" + row.second + "': the row of episode " + std::to_string(index) +
                               " is not object,target,success(0/1),"
                               "progress,seconds,stage,message: '" +
                               row.first + "'");
    ok += fields[2] == "1";
    csv += row.first + "\n";
  }
  const nlohmann::json& meta = shards[0].meta;
  PrintSuccessRate(ParseTaskType(meta.at("task").get<std::string>()),
                   meta.at("cameras").get<bool>(), ok, episodes);
  if (!a.csv.empty()) internal::WriteFileAtomically(a.csv, csv);
  return 0;
}

}  // namespace

int RunTasksCommand(int argc, char** argv) {
  const std::vector<std::string> args(argv, argv + argc);
  if (ArgParser::AsksForHelp(args)) {
    std::printf("%s", kTasksUsage);
    return 0;
  }
  return RunWithExitCode("partsim tasks", kTasksUsage, [&] {
    TasksArgs a = Parse(args);
    if (!a.merge.empty()) return RunMergeEvaluate(a);
    return a.command == "demo" ? RunDemo(a) : RunEvaluate(a);
  });
}

}  // namespace partsim::tools
