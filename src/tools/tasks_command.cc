// `partsim tasks demo|evaluate`: the drawer and door tasks with the heuristic solvers, on
// generated cabinets.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
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
                         [--no-cameras] [--csv FILE]
                         [--dataset ROOT [--ids A,B,...] [--targets all|one]]

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
                       message
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
};

TasksArgs Parse(const std::vector<std::string>& args) {
  TasksArgs a;
  ArgParser p("partsim tasks");
  if (args.empty()) p.Fail("expected demo or evaluate");
  a.command = args[0];
  if (a.command != "demo" && a.command != "evaluate")
    p.Fail("unknown command '" + a.command + "'" + DidYouMean(a.command, {"demo", "evaluate"}) +
           " (expected demo or evaluate)");
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
  p.Parse(std::vector<std::string>(args.begin() + 1, args.end()));
  if (a.dataset.empty() && (!a.ids.empty() || a.all_targets))
    p.Fail("--ids and --targets need --dataset");
  if (a.command != "demo" && (!a.video.empty() || a.no_video || a.frames))
    p.Fail("--video, --no-video and --frames go with demo");
  if (!a.video.empty() && a.no_video) p.Fail("--video and --no-video exclude each other");
  if (!a.dataset.empty() && a.command != "evaluate") p.Fail("--dataset goes with evaluate");
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
  std::vector<SolverResult> results(objects.size());
  std::vector<std::string> targets(objects.size());
  std::atomic<size_t> next{0};
  std::mutex io;
  auto t0 = std::chrono::steady_clock::now();
  auto worker = [&]() {
    for (size_t i = next++; i < objects.size(); i = next++) {
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
  for (const SolverResult& r : results) ok += r.success;
  const double paper = a.type == TaskType::kPullDrawer ? 95.3 : 81.8;
  std::printf(
      "%s task, heuristic solver (%s perception): %d / %zu succeeded = %.1f%% "
      "(SAPIEN paper: %.1f%%), %.0f s wall\n",
      TaskTypeName(a.type), a.cameras ? "ground-truth segmented point clouds" : "meshes", ok,
      results.size(), 100.0 * ok / results.size(), paper, wall);
  if (!a.csv.empty()) {
    std::ofstream f(a.csv);
    if (!f) throw std::runtime_error("cannot write '" + a.csv + "'");
    f << "object,target,success,progress,seconds,stage,message\n";
    for (size_t i = 0; i < results.size(); ++i)
      f << objects[i].object << ',' << targets[i] << ',' << results[i].success << ','
        << results[i].progress << ',' << results[i].seconds << ',' << results[i].stage << ",\""
        << results[i].message << "\"\n";
  }
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
    return a.command == "demo" ? RunDemo(a) : RunEvaluate(a);
  });
}

}  // namespace partsim::tools
