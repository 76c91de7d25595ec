// `partsim vision ...`: the perception benchmark's tools. Each subcommand is one function over
// the arguments after its name, listed in kSubcommands with its part of the help; a new one
// adds a function and a row there.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "partsim/core/check.h"
#include "partsim/vision/dataset.h"
#include "partsim/vision/evaluate.h"
#include "partsim/vision/show.h"

namespace partsim::tools {
namespace {

constexpr char kCommand[] = "partsim vision";

constexpr char kDetectionDatasetUsage[] =
    R"(  partsim vision detection-dataset --dataset ROOT --out DIR [--views 20] [--size 512]
                 [--seed S] [--split 0.75] [--jobs J] [--shard i/N] [--backend B]
                 [--no-point-clouds] [--merge-only] [--quiet]
      Movable-part detection data from the PartNet-Mobility folders under ROOT: per object,
      --views pictures (RGB PNG, depth as 16-bit mm PNG and float NPY, a 16-bit PNG of part
      instances, the partial point cloud as NPZ, cameras in views.json) and the COCO files
      DIR/instances_train.json and instances_test.json (RLE masks; categories
      "<object category>/<part label>"), split by object within each category. Same seed,
      same bytes, whatever --jobs and --shard; objects already done are skipped
      (docs/vision.md).
        --dataset ROOT       the objects: folders holding mobility.urdf, at any depth, through
                             symbolic links to folders (a folder of links picks a subset)
        --out DIR            output folder
        --views N            pictures per object (motion: samples per target part; default 20)
        --size PX            picture width and height in pixels (default 512)
        --seed S             seed of the joint states, the cameras and the split (default 0)
        --split F            fraction of each category's objects in the train split (0.75)
        --jobs J             worker threads, each rendering whole objects (default 1)
        --shard i/N          render only the objects whose index % N is i (several processes
                             or machines into one DIR); the split files cover every object done
        --backend B          rasterizer (default) or pathtracer
        --no-point-clouds    detection: write no point cloud NPZ files
        --merge-only         render nothing: write the split files from the objects done
        --quiet              no progress lines on stderr
)";

constexpr char kMotionDatasetUsage[] =
    R"(  partsim vision motion-dataset --dataset ROOT --out DIR [--parts door,drawer]
                 [the options above]
      Motion-attribute data: per target part of the objects under ROOT, --views samples (RGB,
      depth, the part's mask) and DIR/motion_train.json and motion_test.json with the label
      vector m in the camera frame, as evaluate-motion reads. The targets are the parts whose
      label contains a word of --parts (default door,drawer: the paper's set; e.g. lid, or
      knob,button) and that move on a hinge or a slider (one that also turns, a screw cap,
      counts as a slider).
)";

constexpr char kEvaluateDetectionUsage[] =
    R"(  partsim vision evaluate-detection --gt FILE --results FILE [--out DIR]
      AP at mask IoU 0.5 per part category and their mean (mAP), COCO's protocol: --gt is a
      COCO instances JSON (images, categories named "<object category>/<part>", annotations
      with RLE masks, iscrowd), --results a COCO results list (image_id, category_id,
      segmentation as RLE, score). Prints the paper's table (object category x part, AP in
      percent); with --out, writes DIR/table.md, DIR/table.csv and DIR/metrics.json.
)";

constexpr char kEvaluateMotionUsage[] =
    R"(  partsim vision evaluate-motion --gt FILE --predictions FILE [--out DIR]
      The paper's Table 2 (H acc, S acc, H_o, H_a, S_a, door and drawer errors): --gt is
      {"slider_range": R, "samples": [{"sample_id", "m": [13 numbers]}]}, --predictions
      {"samples": [...]} with one entry per sample; m = (T_r, T_t, pivot (3), hinge axis (3),
      slider axis (3), x_door, x_drawer) in the camera frame (docs/vision.md). Prints the
      table; with --out, writes DIR/table.md, DIR/table.csv and DIR/metrics.json.
)";

constexpr char kShowUsage[] =
    R"(  partsim vision show DIR --out FILE.png [--index 0] [--split train|test]
                 [--kind detection|motion]
      One picture of the dataset in DIR with its annotations drawn, what to check first:
      detection, COCO image K of instances_SPLIT.json (file order), every part's mask in its
      own colour, outlined, with its label; motion, sample K of motion_SPLIT.json, the target
      part's mask and label, the axis (a hinge's line through the pivot, drawn as a dot; a
      slider's arrow from the mask's centroid) and a caption with the type and state. --kind
      defaults to the kind whose split files DIR holds.
)";

constexpr char kBaselinesUsage[] =
    R"(  partsim vision train maskrcnn|insseg|motion-resnet|motion-pointnet --data DIR --out RUN
                 [--input I] [--epochs N] [--size S] [--batch-size B] [--lr LR] [--seed S]
                 [--backbone resnet50|resnet18] [--points N] [--instances K] [--init FILE]
                 [--device auto|cpu|cuda] [--no-eval] [--quiet]
  partsim vision predict RUN [--split test|train] [--data DIR] [--shard i/N]
  partsim vision table RUN... [--split test|train] [--out FILE]
      The paper's baselines (Python, PyTorch; partsim.perception): train one on a dataset's
      train split into RUN (checkpoints, continued when RUN exists; progress.csv, curves.png,
      model.pt), predict a split and score it (RUN/eval-SPLIT/), print Tables 1 and 2 beside
      the paper's numbers. `partsim vision train --help` lists every option.
)";

// the subcommands that are Python (partsim.perception), run by RunPythonModule
const char* const kPythonSubcommands[] = {"train", "predict", "table"};

// one subcommand: its name, its part of the help, and what runs it (the arguments after its
// name; returns the exit code, throws UsageError for a bad command line)
struct Subcommand {
  const char* name;
  const char* usage;
  int (*run)(const std::vector<std::string>& args);
};

int RunDetectionDataset(const std::vector<std::string>& args);
int RunMotionDataset(const std::vector<std::string>& args);
int RunEvaluateDetection(const std::vector<std::string>& args);
int RunEvaluateMotion(const std::vector<std::string>& args);
int RunShow(const std::vector<std::string>& args);

const Subcommand kSubcommands[] = {
    {"detection-dataset", kDetectionDatasetUsage, RunDetectionDataset},
    {"motion-dataset", kMotionDatasetUsage, RunMotionDataset},
    {"evaluate-detection", kEvaluateDetectionUsage, RunEvaluateDetection},
    {"evaluate-motion", kEvaluateMotionUsage, RunEvaluateMotion},
    {"show", kShowUsage, RunShow},
};

std::string Usage() {
  std::string s = "usage:\n";
  for (const Subcommand& c : kSubcommands) s += c.usage;
  s += kBaselinesUsage;
  return s + "Exit codes: 0 success, 1 a file missing or malformed, 2 a bad command line.\n";
}

std::vector<std::string> Names() {
  std::vector<std::string> names;
  for (const Subcommand& c : kSubcommands) names.push_back(c.name);
  for (const char* name : kPythonSubcommands) names.push_back(name);
  return names;
}

// the input files and output folder of an evaluate-* subcommand
struct EvaluateArgs {
  std::string gt, input, out;
};

// --gt FILE, `input_flag` FILE (both required) and --out DIR
EvaluateArgs ParseEvaluateArgs(const std::string& name, const std::string& input_flag,
                               const std::vector<std::string>& args) {
  EvaluateArgs a;
  ArgParser p(std::string(kCommand) + " " + name, "partsim vision --help");
  p.Option("--gt", [&](const FlagValue& v) { a.gt = v.NonEmpty("a file name"); });
  p.Option(input_flag, [&](const FlagValue& v) { a.input = v.NonEmpty("a file name"); });
  p.Option("--out", [&](const FlagValue& v) { a.out = v.NonEmpty("a folder name"); });
  p.Parse(args);
  if (a.gt.empty()) p.Fail("--gt FILE is required");
  if (a.input.empty()) p.Fail(input_flag + " FILE is required");
  return a;
}

// writes the tables and metrics into `dir` (created if missing) and says where
void WriteOutputs(const std::string& dir, const std::string& markdown, const std::string& csv,
                  const std::string& json) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create the folder '" + dir + "': " + ec.message());
  for (const auto& [name, text] :
       {std::pair<const char*, const std::string*>{"table.md", &markdown},
        {"table.csv", &csv},
        {"metrics.json", &json}}) {
    const fs::path path = fs::path(dir) / name;
    std::ofstream f(path, std::ios::binary);
    f << *text;
    f.close();
    if (!f) throw std::runtime_error("cannot write '" + path.string() + "'");
    std::printf("wrote %s\n", path.c_str());
  }
}

// the options of detection-dataset and motion-dataset
vision::DatasetOptions ParseDatasetArgs(const std::string& name, vision::DatasetKind kind,
                                        const std::vector<std::string>& args) {
  vision::DatasetOptions o;
  o.kind = kind;
  ArgParser p(std::string(kCommand) + " " + name, "partsim vision --help");
  p.Option("--dataset", [&](const FlagValue& v) { o.dataset_root = v.NonEmpty("a folder name"); });
  p.Option("--out", [&](const FlagValue& v) { o.out = v.NonEmpty("a folder name"); });
  p.Option("--views", [&](const FlagValue& v) { o.views = static_cast<int>(v.Integer(1, 10000)); });
  p.Option("--size", [&](const FlagValue& v) { o.size = static_cast<int>(v.Integer(16, 4096)); });
  p.Option("--seed", [&](const FlagValue& v) { o.seed = v.Unsigned(); });
  p.Option("--split", [&](const FlagValue& v) { o.split = v.Number(0, true, 1); });
  p.Option("--jobs", [&](const FlagValue& v) { o.jobs = static_cast<int>(v.Integer(1, 256)); });
  p.Option("--shard",
           [&](const FlagValue& v) { std::tie(o.shard_index, o.shard_count) = v.Shard(); });
  p.Option("--backend", [&](const FlagValue& v) {
    o.backend = v.Choice({"rasterizer", "pathtracer"});
  });
  p.Switch("--no-point-clouds", [&] { o.point_clouds = false; });
  if (kind == vision::DatasetKind::kMotion)
    p.Option("--parts", [&](const FlagValue& v) {
      o.motion_parts.clear();
      std::stringstream words(v.NonEmpty("label words separated by commas"));
      for (std::string w; std::getline(words, w, ',');) {
        if (w.empty() || w.find_first_of(" \t") != std::string::npos)
          p.Fail("--parts wants label words separated by commas (e.g. door,drawer), got '" +
                 v.Text() + "'");
        o.motion_parts.push_back(w);
      }
    });
  p.Switch("--merge-only", [&] { o.merge_only = true; });
  p.Switch("--quiet", [&] { o.progress = false; });
  p.Parse(args);
  if (o.dataset_root.empty()) p.Fail("--dataset ROOT is required");
  if (o.out.empty()) p.Fail("--out DIR is required");
  return o;
}

int RunDataset(const std::string& name, vision::DatasetKind kind,
               const std::vector<std::string>& args) {
  const vision::DatasetOptions o = ParseDatasetArgs(name, kind, args);
  const vision::DatasetSummary s = vision::GenerateDataset(o);
  const bool detection = kind == vision::DatasetKind::kDetection;
  std::printf("%d objects (%d rendered now, %d already done, %d failed), %ld pictures in %s s",
              s.objects, s.rendered, s.skipped, s.failed, s.views,
              FormatNumber(std::round(s.seconds * 10) / 10).c_str());
  if (s.views > 0 && s.seconds > 0)
    std::printf(" (%s per second)",
                FormatNumber(std::round(s.views / s.seconds * 10) / 10).c_str());
  // where the workers' time went, per picture (load: per object)
  std::string phases;
  for (const vision::DatasetPhase& p : s.phases) {
    if (p.count == 0) continue;
    const auto ms = [&](double seconds) {
      return FormatNumber(std::round(seconds / static_cast<double>(p.count) * 1e4) / 10);
    };
    phases += (phases.empty() ? "" : ", ") + p.name + " " + ms(p.wall_seconds) + " ms (CPU " +
              ms(p.cpu_seconds) + ")";
  }
  if (!phases.empty()) std::printf("\nper picture (load: per object): %s", phases.c_str());
  std::printf("\ntrain: %d objects, %ld %s; test: %d objects, %ld %s", s.train_objects,
              s.train_images, detection ? "images" : "samples", s.test_objects, s.test_images,
              detection ? "images" : "samples");
  if (detection)
    std::printf("; %ld part instances\n", s.annotations);
  else
    std::printf("; slider range %s m\n", FormatNumber(s.slider_range).c_str());
  std::printf("wrote %s/%s\n", o.out.c_str(),
              detection ? "instances_{train,test}.json" : "motion_{train,test}.json");
  for (const std::string& e : s.errors) std::fprintf(stderr, "failed: %s\n", e.c_str());
  return s.failed > 0 ? 1 : 0;
}

int RunDetectionDataset(const std::vector<std::string>& args) {
  return RunDataset("detection-dataset", vision::DatasetKind::kDetection, args);
}

int RunMotionDataset(const std::vector<std::string>& args) {
  return RunDataset("motion-dataset", vision::DatasetKind::kMotion, args);
}

int RunEvaluateDetection(const std::vector<std::string>& args) {
  const EvaluateArgs a = ParseEvaluateArgs("evaluate-detection", "--results", args);
  const vision::DetectionEvaluation e = vision::EvaluateDetectionFiles(a.gt, a.input);
  const std::string markdown = vision::DetectionTableMarkdown(e);
  std::printf("%s", markdown.c_str());
  if (!a.out.empty())
    WriteOutputs(a.out, markdown, vision::DetectionTableCsv(e), vision::DetectionMetricsJson(e));
  return 0;
}

int RunEvaluateMotion(const std::vector<std::string>& args) {
  const EvaluateArgs a = ParseEvaluateArgs("evaluate-motion", "--predictions", args);
  const vision::MotionEvaluation e = vision::EvaluateMotionFiles(a.gt, a.input);
  const std::string markdown = vision::MotionTableMarkdown(e);
  std::printf("%s", markdown.c_str());
  if (!a.out.empty())
    WriteOutputs(a.out, markdown, vision::MotionTableCsv(e), vision::MotionMetricsJson(e));
  return 0;
}

int RunShow(const std::vector<std::string>& args) {
  vision::ShowOptions o;
  std::string out;
  ArgParser p(std::string(kCommand) + " show", "partsim vision --help");
  p.Positional([&](const FlagValue& v) {
    if (!o.dir.empty())
      v.Fail("one dataset folder expected, got '" + o.dir + "' and '" + v.Text() + "'");
    o.dir = v.NonEmpty("a folder name");
  });
  p.Option("--index", [&](const FlagValue& v) { o.index = v.Integer(0, 1000000000000LL); });
  p.Option("--out", [&](const FlagValue& v) { out = v.NonEmpty("a file name"); });
  p.Option("--split", [&](const FlagValue& v) { o.split = v.Choice({"train", "test"}); });
  p.Option("--kind", [&](const FlagValue& v) {
    o.kind = v.Choice({"detection", "motion"}) == "detection" ? vision::DatasetKind::kDetection
                                                              : vision::DatasetKind::kMotion;
  });
  p.Parse(args);
  if (o.dir.empty()) p.Fail("the dataset folder DIR is required");
  if (out.empty()) p.Fail("--out FILE.png is required");
  const vision::ShownImage s = vision::WriteShowPng(o, out);
  std::printf("%s of %s/%s: %s, %zu %s\n", s.title.c_str(), o.dir.c_str(), s.split_file.c_str(),
              s.rgb_file.c_str(), s.instances.size(), s.instances.size() == 1 ? "part" : "parts");
  if (!s.caption.empty()) std::printf("%s\n", s.caption.c_str());
  std::printf("wrote %s\n", out.c_str());
  return 0;
}

}  // namespace

int RunVisionCommand(int argc, char** argv) {
  const std::vector<std::string> args(argv, argv + argc);
  for (const char* name : kPythonSubcommands)
    if (argc > 0 && args[0] == name)
      return RunPythonModule("partsim.perception", "partsim vision train|predict|table (PyTorch)",
                             argc, argv);
  if (ArgParser::AsksForHelp(args)) {
    std::printf("%s", Usage().c_str());
    return 0;
  }
  return RunWithExitCode(kCommand, "see partsim vision --help\n", [&] {
    if (args.empty())
      throw UsageError(std::string(kCommand) + ": expected a subcommand (" + [] {
        std::string list;
        for (const std::string& n : Names()) list += (list.empty() ? "" : ", ") + n;
        return list;
      }() + ")");
    for (const Subcommand& c : kSubcommands)
      if (args[0] == c.name) return c.run(std::vector<std::string>(args.begin() + 1, args.end()));
    throw UsageError(std::string(kCommand) + ": unknown subcommand '" + args[0] + "'" +
                     DidYouMean(args[0], Names()));
  });
}

}  // namespace partsim::tools
