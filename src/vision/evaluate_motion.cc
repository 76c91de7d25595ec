// Motion-attribute estimation: the metrics of the paper's Table 2.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <unordered_map>
#include <unordered_set>

#include "partsim/core/check.h"
#include "partsim/core/constants.h"
#include "partsim/vision/evaluate.h"
#include "vision/json_fields.h"

namespace partsim::vision {
namespace {

using internal::ArrayField;
using internal::AsInteger;
using internal::AsNumber;
using internal::Describe;
using internal::Field;
using internal::json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Eigen::Vector3d Vec(const std::array<double, kMotionVectorSize>& m, int first) {
  return {m[first], m[first + 1], m[first + 2]};
}

// the samples of a motion file: ids unique, m of 13 finite numbers
std::vector<MotionSample> ParseSamples(const json& doc, const std::string& source) {
  const json& samples = ArrayField(doc, "samples", source);
  std::vector<MotionSample> out;
  std::unordered_map<std::string, std::size_t> seen;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const std::string where = source + ": samples[" + std::to_string(i) + "]";
    MotionSample s;
    const json& id = Field(samples[i], "sample_id", where);
    s.sample_id = id.is_string() ? id.get<std::string>()
                                 : std::to_string(AsInteger(id, where + ": 'sample_id' (a string "
                                                                        "or an integer)"));
    const std::string at = where + " (sample_id " + s.sample_id + ")";
    if (!seen.emplace(s.sample_id, i).second)
      throw Error(at + ": the sample_id appears twice (first at samples[" +
                  std::to_string(seen[s.sample_id]) + "])");
    const json& m = Field(samples[i], "m", at);
    if (!m.is_array() || m.size() != kMotionVectorSize)
      throw Error(at + ": 'm' must be a list of " + std::to_string(kMotionVectorSize) +
                  " numbers (T_r, T_t, pivot (3), hinge axis (3), slider axis (3), x_door, "
                  "x_drawer), got " +
                  Describe(m));
    for (int k = 0; k < kMotionVectorSize; ++k)
      s.m[k] = AsNumber(m[k], at + ": m[" + std::to_string(k) + "]");
    out.push_back(std::move(s));
  }
  return out;
}

// the sign-free angle between two directions, degrees in [0, 90]; 90 when one is zero
double AxisAngleDegrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double cross = a.cross(b).norm(), dot = std::abs(a.dot(b));
  if (cross == 0 && dot == 0) return 90;
  // atan2 keeps its precision near 0, where acos of the cosine does not
  return std::atan2(cross, dot) * 180 / kPi;
}

std::string Cell(double value, const char* format, double scale = 1) {
  if (std::isnan(value)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, value * scale);
  return buf;
}

}  // namespace

MotionGroundTruth ParseMotionGroundTruth(const std::string& json_text, const std::string& source) {
  const json doc = internal::ParseDocument(json_text, source);
  MotionGroundTruth out;
  out.slider_range = AsNumber(Field(doc, "slider_range", source), source + ": 'slider_range'");
  if (!(out.slider_range > 0))
    throw Error(source + ": 'slider_range' must be > 0 (metres), got " +
                FormatNumber(out.slider_range));
  out.samples = ParseSamples(doc, source);
  for (std::size_t i = 0; i < out.samples.size(); ++i) {
    const MotionSample& s = out.samples[i];
    const std::string at =
        source + ": samples[" + std::to_string(i) + "] (sample_id " + s.sample_id + ")";
    const double tr = s.m[kMotionHinge], tt = s.m[kMotionSlider];
    if (!((tr == 1 && tt == 0) || (tr == 0 && tt == 1)))
      throw Error(at +
                  ": the type (T_r, T_t) must be (1, 0) for a hinge or (0, 1) for a "
                  "slider, got (" +
                  FormatNumber(tr) + ", " + FormatNumber(tt) + ")");
    const int axis = tr == 1 ? kMotionHingeAxis : kMotionSliderAxis;
    if (Vec(s.m, axis).norm() == 0)
      throw Error(at + ": the " + (tr == 1 ? "hinge" : "slider") + " axis m[" +
                  std::to_string(axis) + ".." + std::to_string(axis + 2) + "] is zero");
  }
  return out;
}

MotionGroundTruth LoadMotionGroundTruth(const std::string& path) {
  return ParseMotionGroundTruth(internal::ReadDocument(path, "motion ground truth"),
                                "motion ground truth '" + path + "'");
}

std::vector<MotionSample> ParseMotionPredictions(const std::string& json_text,
                                                 const std::string& source) {
  return ParseSamples(internal::ParseDocument(json_text, source), source);
}

std::vector<MotionSample> LoadMotionPredictions(const std::string& path) {
  return ParseMotionPredictions(internal::ReadDocument(path, "motion predictions"),
                                "motion predictions '" + path + "'");
}

MotionEvaluation EvaluateMotion(const MotionGroundTruth& ground_truth,
                                const std::vector<MotionSample>& predictions) {
  PARTSIM_THROW_UNLESS(std::isfinite(ground_truth.slider_range) && ground_truth.slider_range > 0,
                       "EvaluateMotion: slider_range must be finite and > 0, got " +
                           FormatNumber(ground_truth.slider_range));
  std::unordered_map<std::string, const MotionSample*> predicted;
  for (const MotionSample& p : predictions) {
    PARTSIM_THROW_UNLESS(predicted.emplace(p.sample_id, &p).second,
                         "EvaluateMotion: two predictions for sample_id " + p.sample_id);
  }
  std::unordered_set<std::string> known;
  for (const MotionSample& g : ground_truth.samples) known.insert(g.sample_id);
  for (const MotionSample& p : predictions)
    PARTSIM_THROW_UNLESS(known.count(p.sample_id), "EvaluateMotion: the prediction for sample_id " +
                                                       p.sample_id + " has no ground-truth sample");

  MotionEvaluation e;
  e.slider_range = ground_truth.slider_range;
  double hinge_right = 0, slider_right = 0, origin = 0, hinge_axis = 0, slider_axis = 0, door = 0,
         drawer = 0;
  for (const MotionSample& g : ground_truth.samples) {
    auto it = predicted.find(g.sample_id);
    PARTSIM_THROW_UNLESS(it != predicted.end(),
                         "EvaluateMotion: no prediction for sample_id " + g.sample_id);
    const auto& m = it->second->m;
    const bool hinge = g.m[kMotionHinge] == 1 && g.m[kMotionSlider] == 0;
    PARTSIM_THROW_UNLESS(hinge || (g.m[kMotionHinge] == 0 && g.m[kMotionSlider] == 1),
                         "EvaluateMotion: ground-truth sample_id " + g.sample_id +
                             ": the type (T_r, T_t) must be (1, 0) or (0, 1)");
    // the predicted type: the larger of T_r and T_t, T_r on a tie (argmax)
    const bool predicted_hinge = m[kMotionHinge] >= m[kMotionSlider];
    if (hinge) {
      ++e.hinges;
      hinge_right += predicted_hinge ? 1 : 0;
      // distance from the predicted pivot to the true axis line through the true pivot
      const Eigen::Vector3d d = Vec(g.m, kMotionHingeAxis).normalized();
      origin += (Vec(m, kMotionPivot) - Vec(g.m, kMotionPivot)).cross(d).norm();
      hinge_axis += AxisAngleDegrees(Vec(m, kMotionHingeAxis), d);
      door += std::abs(m[kMotionDoorState] - g.m[kMotionDoorState]) * 360;
    } else {
      ++e.sliders;
      slider_right += predicted_hinge ? 0 : 1;
      slider_axis += AxisAngleDegrees(Vec(m, kMotionSliderAxis), Vec(g.m, kMotionSliderAxis));
      drawer += std::abs(m[kMotionDrawerState] - g.m[kMotionDrawerState]) * e.slider_range;
    }
  }
  const double h = e.hinges ? e.hinges : kNaN, s = e.sliders ? e.sliders : kNaN;
  e.hinge_accuracy = hinge_right / h;
  e.slider_accuracy = slider_right / s;
  e.hinge_origin_error = origin / h;
  e.hinge_axis_error = hinge_axis / h;
  e.slider_axis_error = slider_axis / s;
  e.door_error = door / h;
  e.drawer_error = drawer / s;
  return e;
}

MotionEvaluation EvaluateMotionFiles(const std::string& ground_truth_path,
                                     const std::string& predictions_path) {
  return EvaluateMotion(LoadMotionGroundTruth(ground_truth_path),
                        LoadMotionPredictions(predictions_path));
}

std::string MotionTableMarkdown(const MotionEvaluation& e) {
  std::string s =
      "| H acc. | S acc. | H_o err (m) | H_a err (°) | S_a err (°) | door err (°) | drawer err "
      "(m) |\n|---:|---:|---:|---:|---:|---:|---:|\n";
  s += "| " + Cell(e.hinge_accuracy, "%.1f%%", 100) + " | " +
       Cell(e.slider_accuracy, "%.1f%%", 100) + " | " + Cell(e.hinge_origin_error, "%.3g") + " | " +
       Cell(e.hinge_axis_error, "%.3g") + " | " + Cell(e.slider_axis_error, "%.3g") + " | " +
       Cell(e.door_error, "%.3g") + " | " + Cell(e.drawer_error, "%.3g") + " |\n\n";
  s += std::to_string(e.hinges) + " hinge and " + std::to_string(e.sliders) +
       " slider samples; axis angles sign-free; drawer states scaled by the slider range " +
       FormatNumber(e.slider_range) + " m.\n";
  return s;
}

std::string MotionTableCsv(const MotionEvaluation& e) {
  return "h_acc,s_acc,h_o_err_m,h_a_err_deg,s_a_err_deg,door_err_deg,drawer_err_m,hinges,"
         "sliders\n" +
         Cell(e.hinge_accuracy, "%.6g", 100) + "," + Cell(e.slider_accuracy, "%.6g", 100) + "," +
         Cell(e.hinge_origin_error, "%.6g") + "," + Cell(e.hinge_axis_error, "%.6g") + "," +
         Cell(e.slider_axis_error, "%.6g") + "," + Cell(e.door_error, "%.6g") + "," +
         Cell(e.drawer_error, "%.6g") + "," + std::to_string(e.hinges) + "," +
         std::to_string(e.sliders) + "\n";
}

std::string MotionMetricsJson(const MotionEvaluation& e) {
  using nlohmann::ordered_json;
  auto number = [](double v) { return std::isnan(v) ? ordered_json(nullptr) : ordered_json(v); };
  const ordered_json doc = {{"slider_range", e.slider_range},
                            {"hinges", e.hinges},
                            {"sliders", e.sliders},
                            {"hinge_accuracy", number(e.hinge_accuracy)},
                            {"slider_accuracy", number(e.slider_accuracy)},
                            {"hinge_origin_error_m", number(e.hinge_origin_error)},
                            {"hinge_axis_error_deg", number(e.hinge_axis_error)},
                            {"slider_axis_error_deg", number(e.slider_axis_error)},
                            {"door_error_deg", number(e.door_error)},
                            {"drawer_error_m", number(e.drawer_error)}};
  return doc.dump(2) + "\n";
}

}  // namespace partsim::vision
