// The perception datasets: same bytes whatever the jobs and shards (shards at the same time
// too), resume, the split, the COCO files read back by partsim's own COCO reader, bad options.
#include "partsim/vision/dataset.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <sstream>

#include "partsim/assets/generator.h"
#include "partsim/core/error.h"
#include "partsim/render/image_io.h"
#include "partsim/render/image_read.h"
#include "partsim/vision/coco_dataset.h"
#include "partsim/vision/evaluate.h"
#include "vision/npz.h"

namespace partsim::vision {
namespace {

namespace fs = std::filesystem;

// Removes this process's folders when it ends.
struct RemoveTempFolders {
  ~RemoveTempFolders() {
    const std::string prefix = "partsim_dataset_test_" + std::to_string(::getpid()) + "_";
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fs::temp_directory_path(), ec))
      if (e.path().filename().string().rfind(prefix, 0) == 0) fs::remove_all(e.path(), ec);
  }
} remove_temp_folders;

// A fresh folder of this process (ctest runs the tests of this file in parallel processes).
std::string Temp(const std::string& name) {
  const std::string dir = (fs::temp_directory_path() /
                           ("partsim_dataset_test_" + std::to_string(::getpid()) + "_" + name))
                              .string();
  fs::remove_all(dir);
  return dir;
}

// A small generated tree: two cabinets (doors and drawers), a refrigerator and a faucet.
std::string MakeTree() {
  static const std::string root = [] {
    const std::string dir = Temp("tree");
    int i = 0;
    for (const char* category :
         {"StorageFurniture", "StorageFurniture", "Refrigerator", "Faucet"}) {
      const GeneratedObject o = GenerateObject(category, i++, 3);
      WriteObject(o, dir + "/" + o.anno_id);
    }
    return dir;
  }();
  return root;
}

DatasetOptions SmallOptions(const std::string& out, DatasetKind kind) {
  DatasetOptions o;
  o.dataset_root = MakeTree();
  o.out = out;
  o.kind = kind;
  o.views = 2;
  o.size = 64;
  o.seed = 5;
  o.progress = false;
  return o;
}

// Every file under `dir` (relative path -> bytes).
std::map<std::string, std::string> Files(const std::string& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::ifstream f(e.path(), std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    out[fs::relative(e.path(), dir).generic_string()] = s.str();
  }
  return out;
}

TEST(DatasetTest, DetectionDatasetIsTheSameWhateverTheJobsAndShards) {
  const std::string one = Temp("one"), two = Temp("two"), sharded = Temp("sharded");
  DatasetOptions o = SmallOptions(one, DatasetKind::kDetection);
  const DatasetSummary s1 = GenerateDataset(o);
  EXPECT_EQ(s1.objects, 4);
  EXPECT_EQ(s1.rendered, 4);
  EXPECT_EQ(s1.failed, 0) << (s1.errors.empty() ? "" : s1.errors.front());
  EXPECT_EQ(s1.views, 8);
  EXPECT_EQ(s1.train_images + s1.test_images, 8);
  EXPECT_GT(s1.annotations, 0);
  // where the time went: each object loaded once, each view rendered, converted and written
  ASSERT_EQ(s1.phases.size(), 4u);
  const char* names[] = {"load", "render", "convert", "write"};
  const long counts[] = {4, 8, 8, 8};
  for (int p = 0; p < 4; ++p) {
    EXPECT_EQ(s1.phases[p].name, names[p]);
    EXPECT_EQ(s1.phases[p].count, counts[p]) << names[p];
    EXPECT_GT(s1.phases[p].wall_seconds, 0) << names[p];
    EXPECT_GT(s1.phases[p].cpu_seconds, 0) << names[p];
    // one thread's CPU time within a phase is at most its wall time (clock ticks aside)
    EXPECT_LE(s1.phases[p].cpu_seconds, s1.phases[p].wall_seconds + 0.01) << names[p];
  }
  EXPECT_LE(s1.phases[1].wall_seconds + s1.phases[2].wall_seconds, s1.seconds);
  o.out = two;
  o.jobs = 2;
  GenerateDataset(o);
  EXPECT_EQ(Files(one), Files(two));
  o.out = sharded;
  o.jobs = 1;
  o.shard_count = 2;
  o.shard_index = 1;
  const DatasetSummary half = GenerateDataset(o);
  EXPECT_EQ(half.rendered, 2);
  o.shard_index = 0;
  GenerateDataset(o);
  EXPECT_EQ(Files(one), Files(sharded));
  // read back by the COCO reader, which checks ids, sizes and RLE
  const CocoDataset train = LoadCocoDataset(one + "/instances_train.json");
  const CocoDataset test = LoadCocoDataset(one + "/instances_test.json");
  EXPECT_EQ(train.images.size() + test.images.size(), 8u);
  EXPECT_EQ(train.categories.size(), test.categories.size());
  bool door = false;
  for (const CocoCategory& c : train.categories) {
    EXPECT_NE(c.name.find('/'), std::string::npos) << c.name;
    door = door || c.name == "StorageFurniture/drawer";
  }
  EXPECT_TRUE(door);
  for (const CocoAnnotation& a : train.annotations) {
    EXPECT_EQ(a.area, static_cast<double>(RleArea(a.segmentation)));
    EXPECT_GE(a.area, 64.0 * 64.0 / 4096.0);
  }
  // the ground truth scores 100 against itself
  std::vector<CocoDetection> perfect;
  for (const CocoAnnotation& a : train.annotations)
    perfect.push_back({a.image_id, a.category_id, a.segmentation, 1.0});
  EXPECT_NEAR(EvaluateDetection(train, perfect).map, 1.0, 1e-12);
}

// Shards of one dataset may run at the same time into one folder (a scheduler's array job):
// each writes dataset.json and the split files through a file of its own, so none trips over
// another's. After a merge-only run the folder is the same bytes as one run's.
TEST(DatasetTest, ShardsRunAtTheSameTimeIntoOneFolder) {
  const std::string one = Temp("together_one"), together = Temp("together");
  DatasetOptions o = SmallOptions(one, DatasetKind::kDetection);
  GenerateDataset(o);
  for (int attempt = 0; attempt < 3; ++attempt) {
    fs::remove_all(together);
    std::vector<std::future<DatasetSummary>> shards;
    for (int i = 0; i < 4; ++i) {
      DatasetOptions s = o;
      s.out = together;
      s.shard_count = 4;
      s.shard_index = i;
      shards.push_back(std::async(std::launch::async, [s] { return GenerateDataset(s); }));
    }
    int rendered = 0;
    for (auto& f : shards) {
      const DatasetSummary s = f.get();  // rethrows what a shard threw
      EXPECT_EQ(s.failed, 0) << (s.errors.empty() ? "" : s.errors.front());
      rendered += s.rendered;
    }
    EXPECT_EQ(rendered, 4);
    DatasetOptions merge = o;
    merge.out = together;
    merge.merge_only = true;
    GenerateDataset(merge);
    EXPECT_EQ(Files(one), Files(together)) << "attempt " << attempt;
  }
}

TEST(DatasetTest, SplitIsByObjectWithinEachCategory) {
  const std::string out = Temp("split");
  DatasetOptions o = SmallOptions(out, DatasetKind::kDetection);
  o.views = 1;
  GenerateDataset(o);
  std::ifstream f(out + "/dataset.json");
  std::stringstream text;
  text << f.rdbuf();
  // two cabinets: round(0.75 * 2) = 2, at most 1 of 2 train; one refrigerator, one faucet:
  // round(0.75) = 1 train
  const std::string s = text.str();
  EXPECT_EQ(s.find("\"test\""), s.rfind("\"test\"")) << s;
  EXPECT_NE(s.find("\"test\""), std::string::npos) << s;
  o.split = 0.5;
  o.out = Temp("split_half");
  const DatasetSummary half = GenerateDataset(o);
  // 0.5 of two cabinets: one in each split; round(0.5) = 1 (half away from zero) for the others
  EXPECT_EQ(half.test_objects, 1);
  EXPECT_EQ(half.train_objects, 3);
}

TEST(DatasetTest, ResumeSkipsDoneObjectsAndRedoesTornOnes) {
  const std::string out = Temp("resume");
  DatasetOptions o = SmallOptions(out, DatasetKind::kDetection);
  o.views = 1;
  GenerateDataset(o);
  const auto before = Files(out);
  // one object torn: its DONE marker gone and a stale partial folder beside it
  std::string torn;
  for (const auto& e : fs::directory_iterator(out + "/objects")) torn = e.path().string();
  fs::remove(torn + "/DONE");
  fs::create_directories(torn + ".partial/rgb");
  const DatasetSummary again = GenerateDataset(o);
  EXPECT_EQ(again.skipped, 3);
  EXPECT_EQ(again.rendered, 1);
  EXPECT_FALSE(fs::exists(torn + ".partial"));
  EXPECT_EQ(Files(out), before);
  // other options into the same folder are refused, naming what differs
  o.views = 3;
  try {
    GenerateDataset(o);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("other options"), std::string::npos) << e.what();
  }
}

TEST(DatasetTest, MotionDatasetHasDoorsAndDrawersWithUnitAxes) {
  const std::string out = Temp("motion");
  DatasetOptions o = SmallOptions(out, DatasetKind::kMotion);
  o.views = 1;
  const DatasetSummary s = GenerateDataset(o);
  EXPECT_EQ(s.objects, 3);  // the faucet has neither
  EXPECT_GT(s.slider_range, 0);
  // a sample drawn again when its part is not seen renders more views than it writes
  ASSERT_EQ(s.phases.size(), 4u);
  EXPECT_EQ(s.phases[0].count, 3);
  EXPECT_EQ(s.phases[1].count, s.views);
  EXPECT_LE(s.phases[3].count, s.views);
  EXPECT_GT(s.phases[3].count, 0);
  const MotionGroundTruth train = LoadMotionGroundTruth(out + "/motion_train.json");
  EXPECT_EQ(train.slider_range, s.slider_range);
  int hinges = 0, sliders = 0;
  for (const MotionSample& m : train.samples) {
    const bool hinge = m.m[kMotionHinge] == 1;
    hinges += hinge;
    sliders += !hinge;
    const int axis = hinge ? kMotionHingeAxis : kMotionSliderAxis;
    EXPECT_NEAR(std::hypot(m.m[axis], m.m[axis + 1], m.m[axis + 2]), 1.0, 1e-9);
    const double state = hinge ? m.m[kMotionDoorState] : m.m[kMotionDrawerState];
    EXPECT_GE(state, -1e-9);
    EXPECT_LE(state, 1.0 + 1e-9);
  }
  EXPECT_GT(hinges, 0);
  EXPECT_GT(sliders, 0);
  // the ground truth scores perfectly against itself
  const MotionEvaluation e = EvaluateMotion(train, train.samples);
  EXPECT_EQ(e.hinge_accuracy, 1.0);
  EXPECT_NEAR(e.hinge_axis_error, 0.0, 1e-6);
  EXPECT_NEAR(e.hinge_origin_error, 0.0, 1e-9);
}

// The datasets write their PNGs at zlib level 1, rows not filtered (PngCompression{1, 0}), to
// be faster: other bytes than libpng's default, the same pixels.
TEST(DatasetTest, FasterPngCompressionKeepsThePixels) {
  const int w = 37, h = 23;
  std::vector<std::uint8_t> rgb(3 * w * h);
  for (std::size_t i = 0; i < rgb.size(); ++i)
    rgb[i] = static_cast<std::uint8_t>((i * 7919u) % 251u + (i % 97u < 40u ? 0u : 4u));
  const std::string dir = Temp("png");
  fs::create_directories(dir);
  WritePng(dir + "/default.png", w, h, 3, rgb.data());
  WritePng(dir + "/fast.png", w, h, 3, rgb.data(), PngCompression{1, 0});
  int w1 = 0, h1 = 0, w2 = 0, h2 = 0;
  const std::vector<std::uint8_t> a = ReadPng(dir + "/default.png", 3, &w1, &h1);
  const std::vector<std::uint8_t> b = ReadPng(dir + "/fast.png", 3, &w2, &h2);
  EXPECT_EQ(w1, w);
  EXPECT_EQ(h2, h);
  EXPECT_EQ(a, rgb);
  EXPECT_EQ(b, rgb);
  EXPECT_NE(Files(dir)["default.png"], Files(dir)["fast.png"]);
  EXPECT_THROW(WritePng(dir + "/x.png", w, h, 3, rgb.data(), PngCompression{10, 2}), Error);
  EXPECT_THROW(WritePng(dir + "/x.png", w, h, 3, rgb.data(), PngCompression{1, 5}), Error);
  EXPECT_FALSE(fs::exists(dir + "/x.png"));
}

TEST(DatasetTest, BadOptionsAreRefusedByName) {
  DatasetOptions o = SmallOptions(Temp("bad"), DatasetKind::kDetection);
  auto refused = [&](DatasetOptions bad, const std::string& word) {
    try {
      GenerateDataset(bad);
      ADD_FAILURE() << "expected an error naming " << word;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    }
  };
  DatasetOptions b = o;
  b.views = 0;
  refused(b, "--views");
  b = o;
  b.shard_index = 2;
  b.shard_count = 2;
  refused(b, "--shard");
  b = o;
  b.backend = "vulkan";
  refused(b, "--backend");
  b = o;
  b.split = 1.5;
  refused(b, "--split");
  b = o;
  b.motion_parts = {};
  refused(b, "--parts");
  b = o;
  b.motion_parts = {"door", "left door"};
  refused(b, "--parts");
  b = o;
  b.dataset_root = Temp("empty");
  fs::create_directories(b.dataset_root);
  refused(b, "no PartNet-Mobility object");
}

// DatasetOptions::motion_parts (--parts) chooses the targets by a word of their label: with
// {"drawer"} every sample is a slider and the doors are left out.
TEST(DatasetTest, MotionPartsChooseTheTargetsByLabel) {
  const std::string out = Temp("motion_parts");
  DatasetOptions o = SmallOptions(out, DatasetKind::kMotion);
  o.views = 1;
  o.motion_parts = {"drawer"};
  const DatasetSummary s = GenerateDataset(o);
  EXPECT_GT(s.objects, 0);
  const MotionGroundTruth train = LoadMotionGroundTruth(out + "/motion_train.json");
  ASSERT_FALSE(train.samples.empty());
  for (const MotionSample& m : train.samples) {
    EXPECT_EQ(m.m[kMotionSlider], 1) << m.sample_id;
    EXPECT_EQ(m.m[kMotionHinge], 0) << m.sample_id;
  }
  // a word no label holds: nothing to render, said with the words
  o.out = Temp("motion_parts_none");
  o.motion_parts = {"no-such-part"};
  try {
    GenerateDataset(o);
    ADD_FAILURE() << "expected the dataset to be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'no-such-part'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace partsim::vision

namespace partsim::vision {
namespace {

TEST(NpzTest, Crc32IsZipsAndArchivesHoldTheirArrays) {
  const std::string check = "123456789";  // the CRC-32 check value of the standard
  EXPECT_EQ(internal::Crc32(reinterpret_cast<const std::uint8_t*>(check.data()), check.size()),
            0xCBF43926u);
  const std::vector<std::uint8_t> npy =
      internal::NpyBytes(internal::MakeNpyArray("a", std::vector<float>{1, 2, 3}, {3}));
  ASSERT_EQ(npy.size() % 16, 12u);  // 64-byte aligned header, then 3 float32
  EXPECT_EQ(std::string(npy.begin() + 1, npy.begin() + 6), "NUMPY");
  EXPECT_THROW(internal::MakeNpyArray("b", std::vector<float>{1, 2}, {3}), Error);
}

}  // namespace
}  // namespace partsim::vision
