// The metrics of the SAPIEN paper's perception experiments: movable-part detection (AP at mask
// IoU 0.5 per part category and their mean, COCO's protocol) and motion-attribute estimation
// (the columns of the paper's Table 2), with their tables as Markdown, CSV and JSON.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "partsim/vision/coco_dataset.h"

namespace partsim::vision {

// ---------------------------------------------------------------------------------------------
// movable-part detection

/// How detections are matched and counted.
struct DetectionOptions {
  double iou_threshold = 0.5;  ///< a detection matches a ground truth at mask IoU >= this
  int max_detections = 100;    ///< per image and category, the highest scores kept
};

/// The result for one category of the ground truth.
struct CategoryAp {
  std::int64_t category_id = 0;
  std::string name;             ///< "Cabinet/rotation_door"
  std::string object_category;  ///< the name before its first '/' ("Cabinet"), "" without one
  std::string part;             ///< the name after its first '/' ("rotation_door"), else the name
  bool present = false;         ///< whether it has ground truth (not iscrowd); else absent
  double ap = 0;                ///< average precision in [0, 1]; NaN when absent
  int ground_truths = 0;        ///< annotations, iscrowd ones not counted
  int crowd = 0;                ///< iscrowd annotations
  int detections = 0;           ///< results, before the max_detections cut
  int true_positives = 0;       ///< kept detections matched to a ground truth
  int false_positives = 0;      ///< kept detections matched to nothing
  int ignored = 0;              ///< kept detections matched to an iscrowd region only
};

/// AP per category and their mean.
struct DetectionEvaluation {
  DetectionOptions options;
  std::vector<CategoryAp> categories;  ///< in the ground truth's order
  double map = 0;                      ///< mean AP over the present categories; NaN if none
  int present = 0;                     ///< categories in the mean
};

/// Average precision of `detections` against `ground_truth` per category, COCO's protocol
/// (pycocotools' COCOeval for masks at one IoU threshold, all areas):
/// - per image and category, the detections sorted by score, highest first (stable: equal
///   scores keep the results' order), the first `max_detections` kept;
/// - each in turn matched to the unmatched ground truth of highest mask IoU >= the threshold
///   (on equal IoU the later annotation in the file), iscrowd regions last and only when no
///   other matches; a crowd region may take several detections, which count as neither true
///   nor false positives (IoU with a crowd region: intersection over the detection's area);
/// - per category, the kept detections of all images sorted by score (stable, images by id),
///   precision made non-increasing from the right, sampled at recall 0, 0.01, ..., 1 (the first
///   point at or beyond each; 0 past the last), AP the mean of the 101 samples;
/// - a category without ground truth (iscrowd aside) is absent: AP NaN, not in the mean.
/// Precision is tp / (tp + fp) exactly (COCOeval adds 2.2e-16 to the denominator, so its values
/// can differ in the sixteenth digit). Throws Error for options out of range.
DetectionEvaluation EvaluateDetection(const CocoDataset& ground_truth,
                                      const std::vector<CocoDetection>& detections,
                                      const DetectionOptions& options = {});

/// EvaluateDetection of a ground-truth file and a results file (LoadCocoDataset,
/// LoadCocoResults).
DetectionEvaluation EvaluateDetectionFiles(const std::string& ground_truth_path,
                                           const std::string& results_path,
                                           const DetectionOptions& options = {});

/// The paper's table as Markdown: a row per object category, a column per part label (both in
/// the ground truth's order of categories), AP in percent with one decimal, the row's mean in a
/// last column and a last row "All" with the mAP; "n/a" where a category is absent, empty where
/// the object category has no such part; then a line with the protocol and the absent
/// categories.
std::string DetectionTableMarkdown(const DetectionEvaluation& evaluation);

/// The same table as CSV: header "object_category,<parts...>,mAP", AP in percent with six
/// significant digits, "n/a" where absent, empty where there is no such part, a last row "All".
std::string DetectionTableCsv(const DetectionEvaluation& evaluation);

/// Everything as JSON, numbers in full: {"iou_threshold", "max_detections",
/// "recall_points": 101, "map" (fraction, null if none present), "present", "categories":
/// [{"id", "name", "object_category", "part", "present", "ap" (fraction or null),
/// "ground_truths", "crowd", "detections", "true_positives", "false_positives", "ignored"}],
/// "absent": [names]}.
std::string DetectionMetricsJson(const DetectionEvaluation& evaluation);

// ---------------------------------------------------------------------------------------------
// motion attributes

/// Entries of the motion label vector m = (T_r, T_t, p^r, d^r, d^t, x_door, x_drawer), in the
/// camera frame: the type one-hot (T_r = 1 for a hinge, i.e. a revolute door; T_t = 1 for a
/// slider, i.e. a prismatic drawer; a prediction's larger entry is its type), the hinge's pivot
/// (a point on its axis, m) and axis direction, the slider's axis direction, the hinge state
/// (joint position / 2 pi) and the slider state (joint position / the ground truth's
/// slider_range). The entries of the other type are unused.
enum MotionEntry : int {
  kMotionHinge = 0,         ///< T_r
  kMotionSlider = 1,        ///< T_t
  kMotionPivot = 2,         ///< p^r: 2, 3, 4 (m)
  kMotionHingeAxis = 5,     ///< d^r: 5, 6, 7 (any length but 0)
  kMotionSliderAxis = 8,    ///< d^t: 8, 9, 10 (any length but 0)
  kMotionDoorState = 11,    ///< x_door = angle / (2 pi)
  kMotionDrawerState = 12,  ///< x_drawer = displacement / slider_range
  kMotionVectorSize = 13,
};

/// One sample's label vector, keyed by the sample's id.
struct MotionSample {
  std::string sample_id;  ///< a JSON string as it is, an integer as its decimal text
  std::array<double, kMotionVectorSize> m{};
};

/// The ground truth of a motion-attribute set.
struct MotionGroundTruth {
  double slider_range = 1;  ///< m: the slider-state normalisation, > 0
  std::vector<MotionSample> samples;
};

/// Reads a motion ground truth: {"slider_range": R (m, > 0), "samples": [{"sample_id": integer
/// or string, "m": [13 numbers]}, ...]}. Sample ids are unique; m is finite, its type one-hot
/// (T_r, T_t = 1, 0 or 0, 1) and the axis of its type non-zero. Throws Error naming `source` and
/// the sample at fault.
MotionGroundTruth ParseMotionGroundTruth(const std::string& json_text, const std::string& source);

/// ParseMotionGroundTruth of the file at `path`.
MotionGroundTruth LoadMotionGroundTruth(const std::string& path);

/// Reads motion predictions: {"samples": [{"sample_id", "m": [13 finite numbers]}, ...]}, ids
/// unique (other keys, e.g. a "slider_range", are ignored: the ground truth's is used). Throws
/// Error naming `source` and the sample at fault.
std::vector<MotionSample> ParseMotionPredictions(const std::string& json_text,
                                                 const std::string& source);

/// ParseMotionPredictions of the file at `path`.
std::vector<MotionSample> LoadMotionPredictions(const std::string& path);

/// The paper's Table 2. Each mean is over the samples of the ground-truth type (hinges or
/// sliders), whatever type was predicted; NaN when there are none.
struct MotionEvaluation {
  double slider_range = 1;        ///< m, from the ground truth
  int hinges = 0;                 ///< hinge samples
  int sliders = 0;                ///< slider samples
  double hinge_accuracy = 0;      ///< H acc: hinges predicted as hinges, fraction
  double slider_accuracy = 0;     ///< S acc: sliders predicted as sliders, fraction
  double hinge_origin_error = 0;  ///< H_o err: predicted pivot to the true axis line, m
  double hinge_axis_error = 0;    ///< H_a err: angle between the axes, sign-free, degrees
  double slider_axis_error = 0;   ///< S_a err: the same for sliders, degrees
  double door_error = 0;          ///< |x_door error| * 360, degrees
  double drawer_error = 0;        ///< |x_drawer error| * slider_range, m
};

/// The metrics of `predictions` against `ground_truth`: every ground-truth sample needs one
/// prediction, and every prediction a ground-truth sample (else Error naming the sample id). The
/// predicted type is the larger of T_r and T_t (T_r on a tie). Axis angles are sign-free, in
/// [0, 90] degrees (min(theta, 180 - theta)); a zero predicted axis counts as 90.
MotionEvaluation EvaluateMotion(const MotionGroundTruth& ground_truth,
                                const std::vector<MotionSample>& predictions);

/// EvaluateMotion of a ground-truth file and a predictions file.
MotionEvaluation EvaluateMotionFiles(const std::string& ground_truth_path,
                                     const std::string& predictions_path);

/// Table 2 as Markdown: H acc and S acc in percent with one decimal, the errors with three
/// significant digits, "n/a" where there is no sample of the type; a line with the counts
/// below.
std::string MotionTableMarkdown(const MotionEvaluation& evaluation);

/// The same row as CSV with a header (h_acc, s_acc in percent; h_o_err_m, h_a_err_deg,
/// s_a_err_deg, door_err_deg, drawer_err_m; hinges, sliders), six significant digits, "n/a"
/// where there is no sample.
std::string MotionTableCsv(const MotionEvaluation& evaluation);

/// Everything as JSON, numbers in full (fractions for the accuracies, null where there is no
/// sample): {"slider_range", "hinges", "sliders", "hinge_accuracy", "slider_accuracy",
/// "hinge_origin_error_m", "hinge_axis_error_deg", "slider_axis_error_deg", "door_error_deg",
/// "drawer_error_m"}.
std::string MotionMetricsJson(const MotionEvaluation& evaluation);

}  // namespace partsim::vision
