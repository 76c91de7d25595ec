// COCO files: what is read from a ground truth and a results list, the errors that name the
// entry at fault, and writing then reading back.
#include "partsim/vision/coco_dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "error_of.h"
#include "partsim/core/error.h"

namespace partsim::vision {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

using partsim::testing::ErrorOf;

// two 4x3 images (width 4, height 3), two categories, three annotations: a 2-pixel mask as
// counts, the same as compressed text ("52" is 5, 2, then 5 -> "525"), and a crowd region
const char kGroundTruth[] = R"({
  "images": [{"id": 7, "width": 4, "height": 3, "file_name": "a.png"},
             {"id": 3, "width": 4, "height": 3}],
  "categories": [{"id": 1, "name": "Cabinet/drawer", "supercategory": "Cabinet"},
                 {"id": 2, "name": "Cabinet/rotation_door"}],
  "annotations": [
    {"id": 10, "image_id": 7, "category_id": 1, "iscrowd": 0,
     "segmentation": {"size": [3, 4], "counts": [5, 2, 5]}},
    {"id": 11, "image_id": 3, "category_id": 2, "area": 2.5, "bbox": [1, 2, 3, 4],
     "segmentation": {"size": [3, 4], "counts": "525"}},
    {"id": 12, "image_id": 3, "category_id": 2, "iscrowd": true,
     "segmentation": {"size": [3, 4], "counts": [0, 12]}}]
})";

// kGroundTruth with `from` replaced by `to` (once)
std::string Edited(const std::string& from, const std::string& to) {
  std::string text = kGroundTruth;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(VisionCocoDatasetTest, ReadsImagesCategoriesAndAnnotations) {
  const CocoDataset d = ParseCocoDataset(kGroundTruth, "gt");
  ASSERT_EQ(d.images.size(), 2u);
  EXPECT_EQ(d.images[0].id, 7);
  EXPECT_EQ(d.images[0].width, 4);
  EXPECT_EQ(d.images[0].height, 3);
  EXPECT_EQ(d.images[0].file_name, "a.png");
  EXPECT_EQ(d.images[1].file_name, "");
  ASSERT_EQ(d.categories.size(), 2u);
  EXPECT_EQ(d.categories[1].name, "Cabinet/rotation_door");
  EXPECT_EQ(d.categories[0].supercategory, "Cabinet");
  ASSERT_EQ(d.annotations.size(), 3u);
  const CocoAnnotation& a = d.annotations[0];
  EXPECT_EQ(a.image_id, 7);
  EXPECT_EQ(a.category_id, 1);
  EXPECT_FALSE(a.iscrowd);
  EXPECT_THAT(a.segmentation.counts, ElementsAre(5, 2, 5));
  // area and box computed when absent: pixels 5 and 6 in column-major order are (1, 2), (2, 0)
  EXPECT_EQ(a.area, 2);
  EXPECT_THAT(a.bbox, ElementsAre(1, 0, 2, 3));
  // the compressed text reads as the same counts; the file's area and box are kept
  EXPECT_EQ(d.annotations[1].segmentation.counts, a.segmentation.counts);
  EXPECT_EQ(d.annotations[1].area, 2.5);
  EXPECT_THAT(d.annotations[1].bbox, ElementsAre(1, 2, 3, 4));
  EXPECT_TRUE(d.annotations[2].iscrowd);
}

TEST(VisionCocoDatasetTest, WritesWhatItReads) {
  const CocoDataset d = ParseCocoDataset(kGroundTruth, "gt");
  const CocoDataset again = ParseCocoDataset(CocoDatasetToJson(d), "written");
  ASSERT_EQ(again.annotations.size(), d.annotations.size());
  for (std::size_t i = 0; i < d.annotations.size(); ++i) {
    EXPECT_EQ(again.annotations[i].id, d.annotations[i].id);
    EXPECT_EQ(again.annotations[i].segmentation.counts, d.annotations[i].segmentation.counts);
    EXPECT_EQ(again.annotations[i].iscrowd, d.annotations[i].iscrowd);
    EXPECT_EQ(again.annotations[i].area, d.annotations[i].area);
    EXPECT_EQ(again.annotations[i].bbox, d.annotations[i].bbox);
  }
  EXPECT_EQ(again.images[0].file_name, "a.png");
  EXPECT_EQ(again.categories[1].name, "Cabinet/rotation_door");
  // results too
  std::vector<CocoDetection> results = {{7, 1, d.annotations[0].segmentation, 0.25},
                                        {3, 2, d.annotations[2].segmentation, 1e-9}};
  const auto read = ParseCocoResults(CocoResultsToJson(results), d, "written results");
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[1].score, 1e-9);
  EXPECT_EQ(read[1].segmentation.counts, results[1].segmentation.counts);
}

TEST(VisionCocoDatasetTest, ErrorsNameTheEntryAndTheKey) {
  auto error = [](const std::string& text) {
    return ErrorOf([&] { ParseCocoDataset(text, "COCO ground truth 'gt.json'"); });
  };
  EXPECT_THAT(error("{"), HasSubstr("COCO ground truth 'gt.json': not valid JSON"));
  EXPECT_THAT(error("[]"), HasSubstr("expected an object"));
  EXPECT_THAT(error(Edited("\"images\"", "\"imgs\"")), HasSubstr("missing key 'images'"));
  EXPECT_THAT(error(Edited("\"image_id\": 3, \"category_id\": 2, \"area\"",
                           "\"image_id\": 99, \"category_id\": 2, \"area\"")),
              HasSubstr("annotations[1] (id 11): image_id 99 is not in 'images'"));
  EXPECT_THAT(error(Edited("\"category_id\": 1", "\"category_id\": 5")),
              HasSubstr("annotations[0] (id 10): category_id 5 is not in 'categories'"));
  EXPECT_THAT(error(Edited("\"counts\": [5, 2, 5]", "\"counts\": [5, 2, 4]")),
              HasSubstr("annotations[0] (id 10): 'segmentation': the counts add up to 11 "
                        "pixels, the size [3, 4] has 12"));
  EXPECT_THAT(error(Edited("\"size\": [3, 4], \"counts\": [5, 2, 5]",
                           "\"size\": [4, 3], \"counts\": [5, 2, 5]")),
              HasSubstr("the mask's size [4, 3] differs from image 7's [height, width] = [3, 4]"));
  EXPECT_THAT(error(Edited("\"counts\": \"525\"", "\"counts\": \"52~\"")),
              HasSubstr("annotations[1] (id 11): 'segmentation': RLE counts: character 2"));
  EXPECT_THAT(error(Edited("{\"size\": [3, 4], \"counts\": [5, 2, 5]}", "[[0, 0, 1, 0, 1, 1]]")),
              HasSubstr("is a polygon list; only RLE masks are supported"));
  EXPECT_THAT(error(Edited("\"id\": 11", "\"id\": 10")),
              HasSubstr("annotations[1] (id 10): the annotation id 10 appears twice"));
  EXPECT_THAT(error(Edited("\"id\": 3,", "\"id\": 7,")), HasSubstr("image id 7 appears twice"));
  EXPECT_THAT(error(Edited("\"id\": 7,", "\"id\": \"7\",")),
              HasSubstr("images[0]: 'id' must be an integer, got \"7\""));
  EXPECT_THAT(error(Edited("\"iscrowd\": 0", "\"iscrowd\": 2")),
              HasSubstr("'iscrowd' must be 0 or 1"));
  EXPECT_THAT(error(Edited("\"width\": 4,", "\"width\": -4,")),
              HasSubstr("images[0] (id 7): 'width' must be from 0"));
  EXPECT_THAT(error(Edited("\"bbox\": [1, 2, 3, 4]", "\"bbox\": [1, 2, 3]")),
              HasSubstr("'bbox' must be [x, y, width, height]"));
  // file_name is optional
  EXPECT_EQ(error(Edited(", \"file_name\": \"a.png\"", "")), "");
}

TEST(VisionCocoDatasetTest, ResultErrorsNameTheEntry) {
  const CocoDataset gt = ParseCocoDataset(kGroundTruth, "gt");
  auto error = [&](const std::string& text) {
    return ErrorOf([&] { ParseCocoResults(text, gt, "COCO results 'r.json'"); });
  };
  const std::string mask = R"("segmentation": {"size": [3, 4], "counts": "525"})";
  EXPECT_EQ(error("[]"), "");
  EXPECT_EQ(error(R"([{"image_id": 7, "category_id": 1, "score": 0.5, )" + mask + "}]"), "");
  EXPECT_THAT(error("{}"), HasSubstr("COCO results 'r.json': expected a list of results"));
  EXPECT_THAT(error(R"([{"image_id": 8, "category_id": 1, "score": 0.5, )" + mask + "}]"),
              HasSubstr("COCO results 'r.json': [0]: image_id 8 is not an image of the ground "
                        "truth"));
  EXPECT_THAT(error(R"([{"image_id": 7, "category_id": 4, "score": 0.5, )" + mask + "}]"),
              HasSubstr("[0]: category_id 4 is not a category of the ground truth"));
  EXPECT_THAT(error(R"([{"image_id": 7, "category_id": 1, )" + mask + "}]"),
              HasSubstr("[0]: missing key 'score'"));
  EXPECT_THAT(error(R"([{"image_id": 7, "category_id": 1, "score": "high", )" + mask + "}]"),
              HasSubstr("[0]: 'score' must be a finite number, got \"high\""));
  EXPECT_THAT(error(R"([{"image_id": 7, "category_id": 1, "score": 1,
                        "segmentation": {"size": [3, 5], "counts": [15]}}])"),
              HasSubstr("differs from image 7's"));
  EXPECT_THAT(error(R"([{"image_id": 7, "category_id": 1, "score": 1,
                        "segmentation": {"size": [3, 4]}}])"),
              HasSubstr("[0]: 'segmentation': missing key 'counts'"));
}

TEST(VisionCocoDatasetTest, LoadNamesTheFile) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("partsim_coco_dataset_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "gt.json").string();
  std::ofstream(path) << Edited("\"category_id\": 1", "\"category_id\": 5");
  EXPECT_THAT(ErrorOf([&] { LoadCocoDataset(path); }),
              HasSubstr("COCO ground truth '" + path + "': annotations[0] (id 10)"));
  EXPECT_THAT(ErrorOf([&] { LoadCocoDataset((dir / "missing.json").string()); }),
              HasSubstr("missing.json"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace partsim::vision

namespace partsim::vision {
namespace {

TEST(VisionCocoDatasetTest, HostileFilesAreRefusedByName) {
  auto error = [](const std::string& text) {
    return ErrorOf([&] { ParseCocoDataset(text, "gt"); });
  };
  // nesting deep enough to overflow a recursive parser's stack
  EXPECT_THAT(error(std::string(100000, '[') + std::string(100000, ']')),
              HasSubstr("nested deeper than"));
  // bytes that are not text at all, and garbage after a valid document
  EXPECT_THAT(error(std::string("\xff\xfe\x00\x9c garbage", 12)), HasSubstr("gt: not valid JSON"));
  EXPECT_THAT(error(std::string(kGroundTruth) + "\xc3\x28"), HasSubstr("gt: not valid JSON"));
  // numbers far out of range
  EXPECT_THAT(error(Edited("\"width\": 4,", "\"width\": 1e300,")),
              HasSubstr("images[0] (id 7): 'width'"));
  EXPECT_THAT(error(Edited("\"id\": 7,", "\"id\": 1e300,")),
              HasSubstr("images[0]: 'id' must be an integer"));
  EXPECT_THAT(error(Edited("\"counts\": [5, 2, 5]", "\"counts\": [5, 99999999999999999999, 5]")),
              HasSubstr("annotations[0] (id 10): 'segmentation'"));
  EXPECT_THAT(error(Edited("\"counts\": [5, 2, 5]", "\"counts\": [5, -2, 9]")),
              HasSubstr("annotations[0] (id 10): 'segmentation'"));
}

}  // namespace
}  // namespace partsim::vision
