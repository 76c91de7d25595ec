// Motion-attribute metrics on hand-computed samples, and the files' checks.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "error_of.h"
#include "partsim/core/constants.h"
#include "partsim/core/error.h"
#include "partsim/vision/evaluate.h"

namespace partsim::vision {
namespace {

using ::testing::HasSubstr;

using partsim::testing::ErrorOf;

// m of a hinge: pivot p, axis d, state x_door
MotionSample Hinge(const std::string& id, std::array<double, 3> p, std::array<double, 3> d,
                   double x, double tr = 1, double tt = 0) {
  MotionSample s;
  s.sample_id = id;
  s.m = {tr, tt, p[0], p[1], p[2], d[0], d[1], d[2], 0, 0, 0, x, 0};
  return s;
}

// m of a slider: axis d, state x_drawer
MotionSample Slider(const std::string& id, std::array<double, 3> d, double x, double tr = 0,
                    double tt = 1) {
  MotionSample s;
  s.sample_id = id;
  s.m = {tr, tt, 0, 0, 0, 0, 0, 0, d[0], d[1], d[2], 0, x};
  return s;
}

TEST(VisionMotionTest, PerfectPredictionsHaveNoError) {
  MotionGroundTruth gt;
  gt.slider_range = 0.5;
  gt.samples = {Hinge("a", {0.1, 0.2, 0.3}, {0, 0, 1}, 0.25), Slider("b", {1, 0, 0}, 0.5)};
  const MotionEvaluation e = EvaluateMotion(gt, gt.samples);
  EXPECT_EQ(e.hinges, 1);
  EXPECT_EQ(e.sliders, 1);
  EXPECT_EQ(e.hinge_accuracy, 1);
  EXPECT_EQ(e.slider_accuracy, 1);
  EXPECT_EQ(e.hinge_origin_error, 0);
  EXPECT_EQ(e.hinge_axis_error, 0);
  EXPECT_EQ(e.slider_axis_error, 0);
  EXPECT_EQ(e.door_error, 0);
  EXPECT_EQ(e.drawer_error, 0);
}

TEST(VisionMotionTest, HandComputedErrors) {
  MotionGroundTruth gt;
  gt.slider_range = 0.4;
  gt.samples = {Hinge("h1", {1, 1, 0}, {0, 0, 2}, 0.25), Hinge("h2", {0, 0, 0}, {1, 0, 0}, 0.5),
                Slider("s1", {1, 0, 0}, 0.5), Slider("s2", {0, 1, 0}, 0.1)};
  const std::vector<MotionSample> predicted = {
      // pivot 5 m from the true axis (the vertical line through (1, 1): offset (3, 4)), anywhere
      // along it; axis at 45 degrees; state off by 0.05 of a turn = 18 degrees; typed a slider
      Hinge("h1", {4, 5, 7}, {0, 1, 1}, 0.3, 0.2, 0.8),
      // pivot on the axis; axis reversed (0 degrees, sign-free); state exact; T_r = T_t: hinge
      Hinge("h2", {-3, 0, 0}, {-5, 0, 0}, 0.5, 0.5, 0.5),
      // axis at 135 degrees -> 45 sign-free; state off by 0.25 * 0.4 m = 0.1 m
      Slider("s1", {-1, 1, 0}, 0.25),
      // zero axis: 90 degrees; typed a hinge; state exact
      Slider("s2", {0, 0, 0}, 0.1, 0.9, 0.1)};
  const MotionEvaluation e = EvaluateMotion(gt, predicted);
  EXPECT_EQ(e.hinges, 2);
  EXPECT_EQ(e.sliders, 2);
  EXPECT_DOUBLE_EQ(e.hinge_accuracy, 0.5);
  EXPECT_DOUBLE_EQ(e.slider_accuracy, 0.5);
  EXPECT_NEAR(e.hinge_origin_error, (5 + 0) / 2.0, 1e-12);
  EXPECT_NEAR(e.hinge_axis_error, (45 + 0) / 2.0, 1e-12);
  EXPECT_NEAR(e.slider_axis_error, (45 + 90) / 2.0, 1e-12);
  EXPECT_NEAR(e.door_error, (18 + 0) / 2.0, 1e-12);
  EXPECT_NEAR(e.drawer_error, (0.1 + 0) / 2.0, 1e-12);
  EXPECT_EQ(e.slider_range, 0.4);
}

TEST(VisionMotionTest, SmallAxisAnglesKeepTheirPrecision) {
  // 1e-7 rad between the axes: acos of the cosine would give 0 or 2.1e-8 rad
  MotionGroundTruth gt;
  gt.samples = {Hinge("a", {0, 0, 0}, {0, 0, 1}, 0)};
  const MotionEvaluation e =
      EvaluateMotion(gt, {Hinge("a", {0, 0, 0}, {std::sin(1e-7), 0, std::cos(1e-7)}, 0)});
  EXPECT_NEAR(e.hinge_axis_error, 1e-7 * 180 / kPi, 1e-18);
}

TEST(VisionMotionTest, TypesWithoutSamplesAreNaN) {
  MotionGroundTruth gt;
  gt.samples = {Hinge("a", {0, 0, 0}, {0, 0, 1}, 0)};
  const MotionEvaluation e = EvaluateMotion(gt, gt.samples);
  EXPECT_EQ(e.sliders, 0);
  EXPECT_TRUE(std::isnan(e.slider_accuracy));
  EXPECT_TRUE(std::isnan(e.drawer_error));
  EXPECT_THAT(MotionTableMarkdown(e), HasSubstr("| 100.0% | n/a | 0 | 0 | n/a | 0 | n/a |"));
  EXPECT_THAT(MotionTableCsv(e), HasSubstr("\n100,n/a,0,0,n/a,0,n/a,1,0\n"));
  EXPECT_THAT(MotionMetricsJson(e), HasSubstr("\"slider_accuracy\": null"));
}

TEST(VisionMotionTest, PredictionsMustMatchTheSamples) {
  MotionGroundTruth gt;
  gt.samples = {Hinge("a", {0, 0, 0}, {0, 0, 1}, 0), Slider("b", {1, 0, 0}, 0)};
  EXPECT_THAT(ErrorOf([&] { EvaluateMotion(gt, {gt.samples[0]}); }),
              HasSubstr("no prediction for sample_id b"));
  auto extra = gt.samples;
  extra.push_back(Slider("c", {1, 0, 0}, 0));
  EXPECT_THAT(ErrorOf([&] { EvaluateMotion(gt, extra); }),
              HasSubstr("the prediction for sample_id c has no ground-truth sample"));
  auto twice = gt.samples;
  twice.push_back(gt.samples[0]);
  EXPECT_THAT(ErrorOf([&] { EvaluateMotion(gt, twice); }),
              HasSubstr("two predictions for sample_id a"));
  gt.slider_range = 0;
  EXPECT_THAT(ErrorOf([&] { EvaluateMotion(gt, gt.samples); }), HasSubstr("slider_range"));
}

TEST(VisionMotionTest, ReadsTheFilesAndNamesTheSampleAtFault) {
  const MotionGroundTruth gt = ParseMotionGroundTruth(
      R"({"slider_range": 0.6, "samples": [
           {"sample_id": 4, "m": [1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0.1, 0]},
           {"sample_id": "cabinet_3/view_2", "m": [0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0.2]}]})",
      "gt");
  EXPECT_EQ(gt.slider_range, 0.6);
  ASSERT_EQ(gt.samples.size(), 2u);
  EXPECT_EQ(gt.samples[0].sample_id, "4");
  EXPECT_EQ(gt.samples[1].sample_id, "cabinet_3/view_2");
  EXPECT_EQ(gt.samples[1].m[kMotionDrawerState], 0.2);
  const auto predictions = ParseMotionPredictions(
      R"({"samples": [{"sample_id": "cabinet_3/view_2", "m": [0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0,
          0.3]}, {"sample_id": 4, "m": [1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0.1, 0]}]})",
      "predictions");
  EXPECT_NEAR(EvaluateMotion(gt, predictions).drawer_error, 0.1 * 0.6, 1e-15);

  auto gt_error = [](const std::string& text) {
    return ErrorOf([&] { ParseMotionGroundTruth(text, "motion ground truth 'gt.json'"); });
  };
  const std::string hinge = R"("m": [1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0])";
  EXPECT_THAT(gt_error(R"({"samples": []})"),
              HasSubstr("motion ground truth 'gt.json': missing key 'slider_range'"));
  EXPECT_THAT(gt_error(R"({"slider_range": -1, "samples": []})"),
              HasSubstr("'slider_range' must be > 0"));
  EXPECT_THAT(gt_error(R"({"slider_range": 1, "samples": [{"sample_id": 1, "m": [1, 0]}]})"),
              HasSubstr("samples[0] (sample_id 1): 'm' must be a list of 13 numbers"));
  EXPECT_THAT(gt_error(R"({"slider_range": 1, "samples": [{"sample_id": 1, )" + hinge +
                       R"(}, {"sample_id": 1, )" + hinge + "}]}"),
              HasSubstr("samples[1] (sample_id 1): the sample_id appears twice"));
  EXPECT_THAT(gt_error(R"({"slider_range": 1, "samples": [{"sample_id": 1,
                 "m": [0.7, 0.3, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0]}]})"),
              HasSubstr("the type (T_r, T_t) must be (1, 0) for a hinge or (0, 1) for a slider, "
                        "got (0.7, 0.3)"));
  EXPECT_THAT(gt_error(R"({"slider_range": 1, "samples": [{"sample_id": 1,
                 "m": [1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0]}]})"),
              HasSubstr("the hinge axis m[5..7] is zero"));
  EXPECT_THAT(gt_error(R"({"slider_range": 1, "samples": [{"sample_id": [1], )" + hinge + "}]}"),
              HasSubstr("'sample_id' (a string or an integer) must be an integer"));
  EXPECT_THAT(gt_error(R"({"slider_range": 1, "samples": [{"sample_id": 2,
                 "m": [1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, "x", 0]}]})"),
              HasSubstr("samples[0] (sample_id 2): m[11] must be a finite number"));
  EXPECT_THAT(ErrorOf([] { ParseMotionPredictions("[]", "motion predictions 'p.json'"); }),
              HasSubstr("motion predictions 'p.json': expected an object"));
}

TEST(VisionMotionTest, TableOfThePaper) {
  MotionEvaluation e;
  e.slider_range = 0.5;
  e.hinges = 3;
  e.sliders = 2;
  e.hinge_accuracy = 0.955;
  e.slider_accuracy = 2.0 / 3.0;
  e.hinge_origin_error = 0.16812;
  e.hinge_axis_error = 18.94;
  e.slider_axis_error = 6.351;
  e.door_error = 14.42;
  e.drawer_error = 0.064512;
  EXPECT_EQ(MotionTableMarkdown(e),
            "| H acc. | S acc. | H_o err (m) | H_a err (°) | S_a err (°) | door err (°) | drawer "
            "err (m) |\n|---:|---:|---:|---:|---:|---:|---:|\n"
            "| 95.5% | 66.7% | 0.168 | 18.9 | 6.35 | 14.4 | 0.0645 |\n\n"
            "3 hinge and 2 slider samples; axis angles sign-free; drawer states scaled by the "
            "slider range 0.5 m.\n");
  EXPECT_EQ(MotionTableCsv(e),
            "h_acc,s_acc,h_o_err_m,h_a_err_deg,s_a_err_deg,door_err_deg,drawer_err_m,hinges,"
            "sliders\n95.5,66.6667,0.16812,18.94,6.351,14.42,0.064512,3,2\n");
}

}  // namespace
}  // namespace partsim::vision
