// Movable-part detection: AP at one mask IoU threshold per category, COCO's protocol, and the
// paper's table.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <unordered_map>
#include <utility>

#include "partsim/core/check.h"
#include "partsim/vision/evaluate.h"

namespace partsim::vision {
namespace {

constexpr int kRecallPoints = 101;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// COCOeval's recall thresholds, np.linspace(0, 1, 101): r * 0.01 in floating point (so 0.07 is
// 0.07000000000000001), the last exactly 1. The same doubles make the same searches.
std::array<double, kRecallPoints> RecallThresholds() {
  std::array<double, kRecallPoints> t{};
  for (int r = 0; r < kRecallPoints; ++r) t[r] = r * 0.01;
  t[kRecallPoints - 1] = 1.0;
  return t;
}

// a kept detection after matching, in its image's score order
struct Kept {
  double score = 0;
  bool matched = false;  // to a ground truth that is not a crowd region
};

// what one (category, image) pair holds: indices into the annotations and the detections
struct Group {
  std::vector<std::size_t> ground_truths, detections;
};

// Matches one image's detections of one category (COCOeval.evaluateImg) and appends the kept
// ones that count (true or false positives) to `kept`; counts into `result`.
void MatchImage(const std::vector<const CocoAnnotation*>& ground_truths,
                std::vector<const CocoDetection*> detections, const DetectionOptions& options,
                std::vector<Kept>* kept, CategoryAp* result) {
  // ground truths: ordinary ones first, crowd regions last, each in the file's order
  std::vector<const CocoAnnotation*> gts = ground_truths;
  std::stable_partition(gts.begin(), gts.end(),
                        [](const CocoAnnotation* g) { return !g->iscrowd; });
  // detections: highest score first, equal scores in the file's order; the first N kept
  std::stable_sort(
      detections.begin(), detections.end(),
      [](const CocoDetection* a, const CocoDetection* b) { return a->score > b->score; });
  if (detections.size() > static_cast<std::size_t>(options.max_detections))
    detections.resize(options.max_detections);

  // each detection in turn takes the best unmatched ground truth at IoU >= the threshold; a
  // crowd region is considered only when no ordinary one matched and may take many
  const double threshold = std::min(options.iou_threshold, 1 - 1e-10);
  std::vector<bool> taken(gts.size(), false);
  for (const CocoDetection* d : detections) {
    double best = threshold;
    int m = -1;
    for (std::size_t g = 0; g < gts.size(); ++g) {
      if (taken[g] && !gts[g]->iscrowd) continue;
      if (m > -1 && !gts[m]->iscrowd && gts[g]->iscrowd) break;
      const double iou = RleIou(d->segmentation, gts[g]->segmentation, gts[g]->iscrowd);
      if (iou < best) continue;
      best = iou;
      m = static_cast<int>(g);
    }
    if (m > -1 && gts[m]->iscrowd) {
      // on a crowd region: neither true nor false positive. COCOeval keeps such a detection in
      // its list with both flags off; it repeats the precision and recall of the one before (or
      // gives precision 0 at recall 0 when first), which changes no sampled point
      ++result->ignored;
      continue;
    }
    if (m > -1) {
      taken[m] = true;
      ++result->true_positives;
    } else {
      ++result->false_positives;
    }
    kept->push_back({d->score, m > -1});
  }
}

// AP of one category's kept detections (COCOeval.accumulate at one threshold, area and
// maxDets): precision-recall in score order, precision made non-increasing from the right,
// sampled at the 101 recall thresholds.
double AveragePrecision(std::vector<Kept> kept, int ground_truths) {
  std::stable_sort(kept.begin(), kept.end(),
                   [](const Kept& a, const Kept& b) { return a.score > b.score; });
  const std::size_t n = kept.size();
  std::vector<double> recall(n), precision(n);
  double tp = 0, fp = 0;
  for (std::size_t k = 0; k < n; ++k) {
    (kept[k].matched ? tp : fp) += 1;
    recall[k] = tp / ground_truths;
    precision[k] = tp / (tp + fp);
  }
  for (std::size_t k = n; k-- > 1;) precision[k - 1] = std::max(precision[k - 1], precision[k]);
  // the precision at the first point whose recall reaches each threshold, 0 past the last
  static const std::array<double, kRecallPoints> thresholds = RecallThresholds();
  double sum = 0;
  for (double t : thresholds) {
    const std::size_t k = std::lower_bound(recall.begin(), recall.end(), t) - recall.begin();
    if (k < n) sum += precision[k];
  }
  return sum / kRecallPoints;
}

std::string Percent(double fraction, const char* format) {
  if (std::isnan(fraction)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, 100 * fraction);
  return buf;
}

// the table's grid: object categories (rows) and part labels (columns) in the ground truth's
// order, and the category of each cell (-1: none)
struct Grid {
  std::vector<std::string> rows, columns;
  std::vector<std::vector<int>> cell;
  std::vector<double> row_mean;
};

Grid MakeGrid(const DetectionEvaluation& e) {
  Grid grid;
  auto index_of = [](std::vector<std::string>* names, const std::string& name) {
    auto it = std::find(names->begin(), names->end(), name);
    if (it != names->end()) return static_cast<int>(it - names->begin());
    names->push_back(name);
    return static_cast<int>(names->size() - 1);
  };
  std::vector<std::pair<int, int>> where;
  for (const CategoryAp& c : e.categories)
    where.emplace_back(index_of(&grid.rows, c.object_category), index_of(&grid.columns, c.part));
  grid.cell.assign(grid.rows.size(), std::vector<int>(grid.columns.size(), -1));
  for (std::size_t i = 0; i < where.size(); ++i) {
    int& cell = grid.cell[where[i].first][where[i].second];
    if (cell < 0) cell = static_cast<int>(i);  // a repeated name: the first category's
  }
  for (const auto& row : grid.cell) {
    double sum = 0;
    int n = 0;
    for (int i : row) {
      if (i >= 0 && e.categories[i].present) {
        sum += e.categories[i].ap;
        ++n;
      }
    }
    grid.row_mean.push_back(n ? sum / n : kNaN);
  }
  return grid;
}

std::string MarkdownCell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

std::string CsvCell(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string RowName(const std::string& object_category) {
  return object_category.empty() ? "(none)" : object_category;
}

}  // namespace

DetectionEvaluation EvaluateDetection(const CocoDataset& ground_truth,
                                      const std::vector<CocoDetection>& detections,
                                      const DetectionOptions& options) {
  PARTSIM_THROW_UNLESS(options.iou_threshold > 0 && options.iou_threshold <= 1,
                       "EvaluateDetection: iou_threshold must be in (0, 1], got " +
                           FormatNumber(options.iou_threshold));
  PARTSIM_THROW_UNLESS(options.max_detections >= 1,
                       "EvaluateDetection: max_detections must be at least 1, got " +
                           std::to_string(options.max_detections));
  // the annotations and detections of each category by image, images by id (COCOeval's
  // sorted imgIds)
  std::unordered_map<std::int64_t, std::map<std::int64_t, Group>> groups;
  for (std::size_t i = 0; i < ground_truth.annotations.size(); ++i) {
    const CocoAnnotation& a = ground_truth.annotations[i];
    groups[a.category_id][a.image_id].ground_truths.push_back(i);
  }
  std::unordered_map<std::int64_t, int> detection_count;
  for (std::size_t i = 0; i < detections.size(); ++i) {
    const CocoDetection& d = detections[i];
    groups[d.category_id][d.image_id].detections.push_back(i);
    ++detection_count[d.category_id];
  }

  DetectionEvaluation out;
  out.options = options;
  double sum = 0;
  for (const CocoCategory& category : ground_truth.categories) {
    CategoryAp r;
    r.category_id = category.id;
    r.name = category.name;
    const std::size_t slash = category.name.find('/');
    r.object_category = slash == std::string::npos ? "" : category.name.substr(0, slash);
    r.part = slash == std::string::npos ? category.name : category.name.substr(slash + 1);
    r.detections = detection_count[category.id];
    std::vector<Kept> kept;
    for (const auto& [image_id, group] : groups[category.id]) {
      std::vector<const CocoAnnotation*> gts;
      for (std::size_t i : group.ground_truths) {
        gts.push_back(&ground_truth.annotations[i]);
        ++(gts.back()->iscrowd ? r.crowd : r.ground_truths);
      }
      std::vector<const CocoDetection*> dts;
      for (std::size_t i : group.detections) dts.push_back(&detections[i]);
      MatchImage(gts, dts, options, &kept, &r);
    }
    r.present = r.ground_truths > 0;
    r.ap = r.present ? AveragePrecision(std::move(kept), r.ground_truths) : kNaN;
    if (r.present) {
      sum += r.ap;
      ++out.present;
    }
    out.categories.push_back(std::move(r));
  }
  out.map = out.present ? sum / out.present : kNaN;
  return out;
}

DetectionEvaluation EvaluateDetectionFiles(const std::string& ground_truth_path,
                                           const std::string& results_path,
                                           const DetectionOptions& options) {
  const CocoDataset gt = LoadCocoDataset(ground_truth_path);
  return EvaluateDetection(gt, LoadCocoResults(results_path, gt), options);
}

std::string DetectionTableMarkdown(const DetectionEvaluation& e) {
  const Grid grid = MakeGrid(e);
  std::string s = "| object category |";
  std::string rule = "|---|";
  for (const std::string& c : grid.columns) {
    s += " " + MarkdownCell(c) + " |";
    rule += "---:|";
  }
  s += " mAP |\n" + rule + "---:|\n";
  for (std::size_t r = 0; r < grid.rows.size(); ++r) {
    s += "| " + MarkdownCell(RowName(grid.rows[r])) + " |";
    for (int i : grid.cell[r]) s += i < 0 ? " |" : " " + Percent(e.categories[i].ap, "%.1f") + " |";
    s += " " + Percent(grid.row_mean[r], "%.1f") + " |\n";
  }
  s += "| **All** |";
  for (std::size_t c = 0; c < grid.columns.size(); ++c) s += " |";
  s += " **" + Percent(e.map, "%.1f") + "** |\n\n";
  s += "AP (%) of each part category at mask IoU " + FormatNumber(e.options.iou_threshold) +
       " (COCO's protocol: " + std::to_string(kRecallPoints) + " recall points, at most " +
       std::to_string(e.options.max_detections) +
       " detections per image and category); mAP: the mean over the " + std::to_string(e.present) +
       " part categories with ground truth.";
  std::string absent;
  for (const CategoryAp& c : e.categories)
    if (!c.present) absent += (absent.empty() ? "" : ", ") + MarkdownCell(c.name);
  if (!absent.empty()) s += " n/a: no ground truth, not in the mean: " + absent + ".";
  return s + "\n";
}

std::string DetectionTableCsv(const DetectionEvaluation& e) {
  const Grid grid = MakeGrid(e);
  std::string s = "object_category";
  for (const std::string& c : grid.columns) s += "," + CsvCell(c);
  s += ",mAP\n";
  for (std::size_t r = 0; r < grid.rows.size(); ++r) {
    s += CsvCell(RowName(grid.rows[r]));
    for (int i : grid.cell[r]) s += "," + (i < 0 ? "" : Percent(e.categories[i].ap, "%.6g"));
    s += "," + Percent(grid.row_mean[r], "%.6g") + "\n";
  }
  s += "All";
  for (std::size_t c = 0; c < grid.columns.size(); ++c) s += ",";
  return s + "," + Percent(e.map, "%.6g") + "\n";
}

std::string DetectionMetricsJson(const DetectionEvaluation& e) {
  using nlohmann::ordered_json;
  auto number = [](double v) { return std::isnan(v) ? ordered_json(nullptr) : ordered_json(v); };
  ordered_json categories = ordered_json::array(), absent = ordered_json::array();
  for (const CategoryAp& c : e.categories) {
    categories.push_back({{"id", c.category_id},
                          {"name", c.name},
                          {"object_category", c.object_category},
                          {"part", c.part},
                          {"present", c.present},
                          {"ap", number(c.ap)},
                          {"ground_truths", c.ground_truths},
                          {"crowd", c.crowd},
                          {"detections", c.detections},
                          {"true_positives", c.true_positives},
                          {"false_positives", c.false_positives},
                          {"ignored", c.ignored}});
    if (!c.present) absent.push_back(c.name);
  }
  const ordered_json doc = {{"iou_threshold", e.options.iou_threshold},
                            {"max_detections", e.options.max_detections},
                            {"recall_points", kRecallPoints},
                            {"map", number(e.map)},
                            {"present", e.present},
                            {"categories", categories},
                            {"absent", absent}};
  return doc.dump(2) + "\n";
}

}  // namespace partsim::vision
