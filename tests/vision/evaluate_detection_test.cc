// Detection AP on hand-computed cases: each expected value is derived in the comments from the
// precision-recall points, as COCO's protocol samples them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "partsim/core/error.h"
#include "partsim/vision/evaluate.h"

namespace partsim::vision {
namespace {

using ::testing::HasSubstr;

constexpr int kSize = 20;  // images are kSize x kSize pixels

// foreground in columns [x0, x1) and rows [y0, y1) of a kSize x kSize image
Rle Box(int x0, int x1, int y0 = 0, int y1 = kSize) {
  Mask m(kSize, kSize);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) m(x, y) = 1;
  return EncodeMask(m);
}

// column k, all rows: 20 disjoint masks per image
Rle Column(int k) { return Box(k, k + 1); }

// a ground truth of `images` images (ids 1..images) and the named categories (ids 1..n), and
// detections against it
struct Case {
  CocoDataset gt;
  std::vector<CocoDetection> dts;

  explicit Case(int images, const std::vector<std::string>& categories = {"Cabinet/drawer"}) {
    for (int i = 1; i <= images; ++i) gt.images.push_back({i, kSize, kSize, ""});
    for (std::size_t c = 0; c < categories.size(); ++c)
      gt.categories.push_back({static_cast<std::int64_t>(c + 1), categories[c], ""});
  }
  void Truth(std::int64_t image, const Rle& mask, bool crowd = false, std::int64_t category = 1) {
    CocoAnnotation a;
    a.id = static_cast<std::int64_t>(gt.annotations.size() + 1);
    a.image_id = image;
    a.category_id = category;
    a.segmentation = mask;
    a.iscrowd = crowd;
    gt.annotations.push_back(a);
  }
  void Detect(std::int64_t image, const Rle& mask, double score, std::int64_t category = 1) {
    dts.push_back({image, category, mask, score});
  }
  DetectionEvaluation Evaluate(const DetectionOptions& options = {}) const {
    return EvaluateDetection(gt, dts, options);
  }
  double Ap(const DetectionOptions& options = {}) const {
    return Evaluate(options).categories.at(0).ap;
  }
};

// Two ground truths (columns 0 and 1 of image 1) and three detections: a true positive for
// each and a false positive (column 5), with the scores given in that order.
double TwoHitsOneMiss(double score_a, double score_b, double score_miss) {
  Case c(1);
  c.Truth(1, Column(0));
  c.Truth(1, Column(1));
  c.Detect(1, Column(0), score_a);
  c.Detect(1, Column(1), score_b);
  c.Detect(1, Column(5), score_miss);
  return c.Ap();
}

TEST(VisionDetectionTest, PerfectPredictionsGive100) {
  Case c(3, {"Cabinet/drawer", "Cabinet/rotation_door"});
  for (int image = 1; image <= 3; ++image) {
    for (int k = 0; k < image; ++k) {
      c.Truth(image, Column(k), false, 1);
      c.Detect(image, Column(k), 0.1 * k + 0.05, 1);
    }
    c.Truth(image, Box(10, 15), false, 2);
    c.Detect(image, Box(10, 15), 0.9, 2);
  }
  const DetectionEvaluation e = c.Evaluate();
  ASSERT_EQ(e.categories.size(), 2u);
  EXPECT_EQ(e.categories[0].ap, 1.0);
  EXPECT_EQ(e.categories[1].ap, 1.0);
  EXPECT_EQ(e.map, 1.0);
  EXPECT_EQ(e.present, 2);
  EXPECT_EQ(e.categories[0].ground_truths, 6);
  EXPECT_EQ(e.categories[0].true_positives, 6);
  EXPECT_EQ(e.categories[0].false_positives, 0);
}

TEST(VisionDetectionTest, NoPredictionsGive0) {
  Case c(2);
  c.Truth(1, Column(0));
  c.Truth(2, Column(3));
  const DetectionEvaluation e = c.Evaluate();
  EXPECT_EQ(e.categories[0].ap, 0.0);
  EXPECT_TRUE(e.categories[0].present);
  EXPECT_EQ(e.map, 0.0);
  // only misses: also 0
  c.Detect(1, Column(7), 0.9);
  c.Detect(2, Box(0, 20, 0, 1), 0.8);  // a row: IoU 1 / 39 with column 3
  EXPECT_EQ(c.Ap(), 0.0);
}

TEST(VisionDetectionTest, DuplicatesAreFalsePositives) {
  // the same two hits with a duplicate of the first between them (score 0.8): in score order
  // TP, FP, TP; recall 0.5, 0.5, 1; precision 1, 1/2, 2/3, made non-increasing from the right
  // 1, 2/3, 2/3. Recall thresholds 0 .. 0.5 (51 of them) reach the first point (precision 1),
  // 0.51 .. 1 (50) the third (2/3): AP = (51 + 50 * 2/3) / 101 = 253 / 303
  Case c(1);
  c.Truth(1, Column(0));
  c.Truth(1, Column(1));
  c.Detect(1, Column(0), 0.9);
  c.Detect(1, Column(0), 0.8);
  c.Detect(1, Column(1), 0.7);
  const DetectionEvaluation e = c.Evaluate();
  EXPECT_NEAR(e.categories[0].ap, 253.0 / 303.0, 1e-15);
  EXPECT_EQ(e.categories[0].true_positives, 2);
  EXPECT_EQ(e.categories[0].false_positives, 1);
  // without the duplicate: TP, TP
  Case clean(1);
  clean.Truth(1, Column(0));
  clean.Truth(1, Column(1));
  clean.Detect(1, Column(0), 0.9);
  clean.Detect(1, Column(1), 0.7);
  EXPECT_EQ(clean.Ap(), 1.0);
}

TEST(VisionDetectionTest, ScoresOrderThePrecisionRecallCurve) {
  // the same three detections, ordered by their scores:
  // - TP, TP, FP: precision 1 up to recall 1 -> AP 1
  EXPECT_EQ(TwoHitsOneMiss(0.9, 0.8, 0.7), 1.0);
  // - TP, FP, TP: the duplicate case's points -> AP (51 + 50 * 2/3) / 101 = 253 / 303
  EXPECT_NEAR(TwoHitsOneMiss(0.9, 0.7, 0.8), 253.0 / 303.0, 1e-15);
  // - FP, TP, TP: recall 0, 0.5, 1; precision 0, 1/2, 2/3 -> non-increasing from the right
  //   2/3, 2/3, 2/3; every threshold reaches a point of precision 2/3 -> AP 2/3
  EXPECT_NEAR(TwoHitsOneMiss(0.7, 0.6, 0.9), 2.0 / 3.0, 1e-15);
}

TEST(VisionDetectionTest, HundredAndOnePointInterpolation) {
  // three ground truths; in score order TP, FP, TP, FP, FP, the third never found:
  // recall    1/3, 1/3, 2/3, 2/3, 2/3
  // precision 1,   1/2, 2/3, 1/2, 2/5  -> from the right: 1, 2/3, 2/3, 1/2, 2/5
  // thresholds 0 .. 0.33 (34 points) reach the first point: 1; 0.34 .. 0.66 (33) the third:
  // 2/3; 0.67 .. 1 (34) nothing: 0. AP = (34 + 33 * 2/3) / 101 = 56 / 101
  Case c(1);
  for (int k = 0; k < 3; ++k) c.Truth(1, Column(k));
  c.Detect(1, Column(0), 0.9);
  c.Detect(1, Column(9), 0.8);
  c.Detect(1, Column(1), 0.7);
  c.Detect(1, Column(10), 0.6);
  c.Detect(1, Column(11), 0.5);
  EXPECT_NEAR(c.Ap(), 56.0 / 101.0, 1e-15);
}

TEST(VisionDetectionTest, RecallThresholdsAreNumpysLinspace) {
  // COCO's thresholds are np.linspace(0, 1, 101): r * 0.01 in floating point, and 35 * 0.01 is
  // 0.35000000000000003, above 7 / 20 = 0.35. With 20 ground truths, 7 hits, a miss, then an
  // 8th hit: recall 0.05 .. 0.35, 0.35, 0.4; precision 1 (x7), 7/8, 8/9 -> from the right 1
  // (x7), 8/9, 8/9. Thresholds 0 .. 0.34 (35 points) reach a hit of precision 1; 0.35 is not
  // reached at recall 0.35, so it and 0.36 .. 0.4 (6 points) take 8/9; 0.41 .. 1 nothing.
  // AP = (35 + 6 * 8/9) / 101 (with an exact 0.35 it would be (36 + 5 * 8/9) / 101).
  Case c(1);
  for (int k = 0; k < 20; ++k) c.Truth(1, Column(k));
  for (int k = 0; k < 7; ++k) c.Detect(1, Column(k), 0.9 - 0.01 * k);
  c.Detect(1, Box(0, 20, 0, 1), 0.5);  // a row: IoU 1/39 with each column
  c.Detect(1, Column(7), 0.4);
  EXPECT_NEAR(c.Ap(), (35 + 6 * 8.0 / 9.0) / 101, 1e-15);
}

TEST(VisionDetectionTest, EachDetectionTakesTheBestUnmatchedTruth) {
  // A: columns 0-9, B: columns 2-11 (10 columns each, in this order in the file); IoUs in
  // columns:
  // D1 (0.9): columns 2-10: IoU 8/11 with A, 9/10 with B -> takes B, the better.
  // D2 (0.8): columns 0-4: IoU 5/10 = 0.5 with A (the threshold counts), 3/12 with B.
  // Both hit: AP 1. Taking the first truth above 0.5 instead would give D1 A and leave D2
  // nothing: AP (51 + 0) / 101.
  Case c(1);
  c.Truth(1, Box(0, 10));
  c.Truth(1, Box(2, 12));
  c.Detect(1, Box(2, 11), 0.9);
  c.Detect(1, Box(0, 5), 0.8);
  const DetectionEvaluation e = c.Evaluate();
  EXPECT_EQ(e.categories[0].ap, 1.0);
  EXPECT_EQ(e.categories[0].true_positives, 2);
  // just below the threshold: columns 0-4 without the last row, 95/200
  Case below(1);
  below.Truth(1, Box(0, 10));
  below.Detect(1, Box(0, 5, 0, 19), 0.8);
  Rle almost = Box(0, 5, 0, 19);
  EXPECT_LT(RleIou(almost, Box(0, 10)), 0.5);
  EXPECT_EQ(below.Ap(), 0.0);
}

TEST(VisionDetectionTest, EqualScoresKeepTheResultsOrderAndImagesGoById) {
  // one truth; a miss and a hit of equal score: the file's order decides
  Case miss_first(1);
  miss_first.Truth(1, Column(0));
  miss_first.Detect(1, Column(5), 0.5);
  miss_first.Detect(1, Column(0), 0.5);
  // FP, TP: recall 0, 1; precision 0, 1/2 -> 1/2, 1/2: AP 1/2
  EXPECT_EQ(miss_first.Ap(), 0.5);
  Case hit_first(1);
  hit_first.Truth(1, Column(0));
  hit_first.Detect(1, Column(0), 0.5);
  hit_first.Detect(1, Column(5), 0.5);
  EXPECT_EQ(hit_first.Ap(), 1.0);
  // across images, equal scores go by image id, whatever the file's order: the hit in image 1
  // comes before the miss in image 2
  Case images(2);
  images.Truth(1, Column(0));
  images.Detect(2, Column(5), 0.5);
  images.Detect(1, Column(0), 0.5);
  EXPECT_EQ(images.Ap(), 1.0);
}

TEST(VisionDetectionTest, CrowdRegionsCountNeitherWay) {
  // one truth (column 0) and a crowd region (columns 10-19). A detection inside the crowd
  // region (IoU with it: intersection / detection area = 1) ranks first: without the crowd
  // flag it would be a miss first (FP, TP: AP 1/2); with it, it is ignored: AP 1
  Case c(1);
  c.Truth(1, Column(0));
  c.Truth(1, Box(10, 20), true);
  c.Detect(1, Box(12, 14), 0.95);
  c.Detect(1, Box(15, 20), 0.93);  // a crowd region takes several detections
  c.Detect(1, Column(0), 0.9);
  const DetectionEvaluation e = c.Evaluate();
  EXPECT_EQ(e.categories[0].ap, 1.0);
  EXPECT_EQ(e.categories[0].ground_truths, 1);
  EXPECT_EQ(e.categories[0].crowd, 1);
  EXPECT_EQ(e.categories[0].ignored, 2);
  EXPECT_EQ(e.categories[0].true_positives, 1);
  EXPECT_EQ(e.categories[0].false_positives, 0);
  Case plain(1);
  plain.Truth(1, Column(0));
  plain.Truth(1, Box(10, 20));
  plain.Detect(1, Box(12, 14), 0.95);
  plain.Detect(1, Column(0), 0.9);
  // FP, TP out of two truths: recall 0, 0.5; precision 0, 1/2 -> 1/2 up to recall 0.5
  EXPECT_NEAR(plain.Ap(), 51 * 0.5 / 101, 1e-15);
  // a detection that matches an ordinary truth takes it, not the crowd region around it
  Case inside(1);
  inside.Truth(1, Box(10, 20), true);
  inside.Truth(1, Box(10, 12));
  inside.Detect(1, Box(10, 12), 0.9);
  EXPECT_EQ(inside.Evaluate().categories[0].true_positives, 1);
  EXPECT_EQ(inside.Ap(), 1.0);
}

TEST(VisionDetectionTest, CategoriesWithoutTruthAreAbsentFromTheMean) {
  Case c(1, {"Cabinet/drawer", "Cabinet/rotation_door", "Table/wheel"});
  c.Truth(1, Column(0), false, 1);
  c.Detect(1, Column(0), 0.9, 1);
  c.Truth(1, Column(3), false, 2);  // missed: AP 0
  c.Detect(1, Column(4), 0.9, 3);   // detections of a category without truth
  c.Truth(1, Column(5), true, 3);   // only a crowd region
  const DetectionEvaluation e = c.Evaluate();
  EXPECT_TRUE(std::isnan(e.categories[2].ap));
  EXPECT_FALSE(e.categories[2].present);
  EXPECT_EQ(e.categories[2].detections, 1);
  EXPECT_EQ(e.present, 2);
  EXPECT_EQ(e.map, 0.5);
  // nothing present at all: NaN
  Case none(1);
  EXPECT_TRUE(std::isnan(none.Evaluate().map));
}

TEST(VisionDetectionTest, AtMostMaxDetectionsPerImageAndCategory) {
  // TP (0.9), FP (0.8), TP (0.7) in image 1; keeping 2 drops the second hit: recall 0.5, 0.5;
  // precision 1, 1/2 -> AP 51 / 101. Image 2's detections are cut on their own.
  Case c(2);
  c.Truth(1, Column(0));
  c.Truth(1, Column(1));
  c.Detect(1, Column(0), 0.9);
  c.Detect(1, Column(5), 0.8);
  c.Detect(1, Column(1), 0.7);
  DetectionOptions two;
  two.max_detections = 2;
  EXPECT_NEAR(c.Ap(two), 51.0 / 101.0, 1e-15);
  EXPECT_NEAR(c.Ap(), 253.0 / 303.0, 1e-15);
  c.Truth(2, Column(0));
  c.Detect(2, Column(0), 0.1);
  // 3 truths: TP, FP, TP(image 2, 0.1) -> recall 1/3, 1/3, 2/3; precision 1, 1/2, 2/3
  // -> 1, 2/3, 2/3: thresholds 0 .. 0.33 (34) 1, 0.34 .. 0.66 (33) 2/3: AP 56 / 101
  EXPECT_NEAR(c.Ap(two), 56.0 / 101.0, 1e-15);
  EXPECT_THAT(
      [&] {
        try {
          DetectionOptions bad;
          bad.max_detections = 0;
          c.Evaluate(bad);
        } catch (const Error& e) {
          return std::string(e.what());
        }
        return std::string();
      }(),
      HasSubstr("max_detections must be at least 1"));
}

TEST(VisionDetectionTest, TablesInThePapersLayout) {
  Case c(1, {"Cabinet/rotation_door", "Cabinet/drawer", "Table/drawer", "Table/wheel", "Fan"});
  c.Truth(1, Column(0), false, 1);
  c.Detect(1, Column(0), 0.9, 1);   // AP 1
  c.Truth(1, Column(1), false, 2);  // AP 0
  c.Truth(1, Column(2), false, 3);
  c.Truth(1, Column(3), false, 3);
  c.Detect(1, Column(2), 0.9, 3);  // one of two: AP 51 / 101
  c.Truth(1, Column(4), false, 5);
  c.Detect(1, Column(4), 0.9, 5);  // AP 1; Table/wheel absent
  const DetectionEvaluation e = c.Evaluate();
  // mean of 1, 0, 51/101, 1
  EXPECT_NEAR(e.map, (2 + 51.0 / 101) / 4, 1e-15);
  EXPECT_EQ(e.categories[4].object_category, "");
  EXPECT_EQ(e.categories[4].part, "Fan");
  EXPECT_EQ(DetectionTableCsv(e),
            "object_category,rotation_door,drawer,wheel,Fan,mAP\n"
            "Cabinet,100,0,,,50\n"
            "Table,,50.495,n/a,,50.495\n"
            "(none),,,,100,100\n"
            "All,,,,,62.6238\n");
  const std::string md = DetectionTableMarkdown(e);
  EXPECT_THAT(md, HasSubstr("| object category | rotation_door | drawer | wheel | Fan | mAP |\n"
                            "|---|---:|---:|---:|---:|---:|\n"
                            "| Cabinet | 100.0 | 0.0 | | | 50.0 |\n"
                            "| Table | | 50.5 | n/a | | 50.5 |\n"
                            "| (none) | | | | 100.0 | 100.0 |\n"
                            "| **All** | | | | | **62.6** |\n"));
  EXPECT_THAT(md, HasSubstr("n/a: no ground truth, not in the mean: Table/wheel."));
  const std::string json = DetectionMetricsJson(e);
  EXPECT_THAT(json, HasSubstr("\"absent\": [\n    \"Table/wheel\"\n  ]"));
  EXPECT_THAT(json, HasSubstr("\"ap\": null"));
}

}  // namespace
}  // namespace partsim::vision
