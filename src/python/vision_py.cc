// Python bindings of the vision layer: COCO masks and RLE, the detection and motion
// evaluators, and a dataset's picture with its annotations drawn (show). They live in the
// extension's submodule `_vision`, named partsim.vision, which python/partsim/vision.py
// re-exports beside its pure-Python parts.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "partsim/core/error.h"
#include "partsim/vision/coco.h"
#include "partsim/vision/coco_dataset.h"
#include "partsim/vision/evaluate.h"
#include "partsim/vision/show.h"

namespace partsim::python {
namespace {

using vision::Rle;

// {"size": [height, width], "counts": str, bytes or [int, ...]} -> Rle, checked
Rle RleFromDict(const py::dict& rle, const std::string& name) {
  for (const char* key : {"size", "counts"})
    if (!rle.contains(key)) throw Error(name + ": missing key '" + key + "'");
  const auto size = rle["size"].cast<std::vector<long long>>();
  constexpr long long kMaxSize = std::numeric_limits<int>::max();
  if (size.size() != 2 || size[0] < 0 || size[1] < 0 || size[0] > kMaxSize || size[1] > kMaxSize)
    throw Error(name + ": 'size' must be [height, width] with sizes from 0 to 2^31 - 1");
  Rle out;
  out.height = static_cast<int>(size[0]);
  out.width = static_cast<int>(size[1]);
  py::object counts = rle["counts"];
  if (py::isinstance<py::bytes>(counts) || py::isinstance<py::str>(counts)) {
    out.counts = vision::DecompressRleCounts(counts.cast<std::string>());
  } else {
    for (const long long c : counts.cast<std::vector<long long>>()) {
      if (c < 0 || c > static_cast<long long>(std::numeric_limits<std::uint32_t>::max()))
        throw Error(name + ": counts must be from 0 to 2^32 - 1, got " + std::to_string(c));
      out.counts.push_back(static_cast<std::uint32_t>(c));
    }
  }
  vision::CheckRle(out, name);
  return out;
}

py::dict RleToDict(const Rle& rle, bool compressed) {
  py::list size;
  size.append(rle.height);
  size.append(rle.width);
  py::dict d;
  d["size"] = size;
  if (compressed)
    d["counts"] = vision::CompressRleCounts(rle.counts);
  else
    d["counts"] = py::cast(rle.counts);
  return d;
}

// a JSON document given as a path (str or os.PathLike: read by C++) or as Python data (dumped to
// JSON text, numpy numbers and arrays as lists); returns (is_path, path or text)
std::pair<bool, std::string> Document(const py::object& value) {
  py::module_ os = py::module_::import("os");
  if (py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__"))
    return {true, os.attr("fspath")(value).cast<std::string>()};
  py::cpp_function plain([](const py::object& o) -> py::object {
    if (py::hasattr(o, "tolist")) return o.attr("tolist")();
    if (py::isinstance<py::bytes>(o)) return py::str(o.cast<std::string>());
    throw py::type_error("cannot write " + py::repr(o).cast<std::string>() + " as JSON");
  });
  py::module_ json = py::module_::import("json");
  return {false, json.attr("dumps")(value, py::arg("default") = plain).cast<std::string>()};
}

}  // namespace

void BindVision(py::module_& m) {
  py::module_ v =
      m.def_submodule("_vision", "COCO masks and RLE, and the perception benchmark's evaluators.");
  // the names its classes and functions report: where python/partsim/vision.py exports them
  v.attr("__name__") = "partsim.vision";

  v.def(
      "encode_mask",
      [](py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast> mask,
         bool compressed) {
        if (mask.ndim() != 2)
          throw Error("encode_mask: mask must be 2-D (height, width), got " +
                      std::to_string(mask.ndim()) + " dimensions");
        vision::Mask mk;
        mk.height = static_cast<int>(mask.shape(0));
        mk.width = static_cast<int>(mask.shape(1));
        mk.data.assign(mask.data(), mask.data() + mask.size());
        return RleToDict(vision::EncodeMask(mk), compressed);
      },
      py::arg("mask"), py::arg("compressed") = true,
      "COCO's RLE of a binary mask (height, width), any non-zero value foreground: "
      "{'size': [height, width], 'counts': str}, the counts as COCO's compressed text, or as a "
      "list of run lengths (column-major, background first) when compressed is False.");
  v.def(
      "decode_rle",
      [](const py::dict& rle) {
        const vision::Mask mask = vision::DecodeRle(RleFromDict(rle, "decode_rle: rle"));
        py::array_t<std::uint8_t> out({mask.height, mask.width});
        std::copy(mask.data.begin(), mask.data.end(), out.mutable_data());
        return out;
      },
      py::arg("rle"),
      "The mask (height, width) of uint8 0 and 1 of an RLE dict {'size', 'counts'} (counts as "
      "COCO's compressed str or bytes, or a list). Raises PartsimError when the counts do not "
      "add up to height * width.");
  v.def("compress_rle_counts", &vision::CompressRleCounts, py::arg("counts"),
        "COCO's compressed text of a list of run lengths.");
  v.def("decompress_rle_counts", &vision::DecompressRleCounts, py::arg("text"),
        "The run lengths of COCO's compressed text; raises PartsimError naming the character "
        "at fault.");
  v.def(
      "rle_area", [](const py::dict& rle) { return vision::RleArea(RleFromDict(rle, "rle")); },
      py::arg("rle"), "Foreground pixels of an RLE dict, counted on its runs.");
  v.def(
      "rle_bbox",
      [](const py::dict& rle) { return vision::RleBoundingBox(RleFromDict(rle, "rle")); },
      py::arg("rle"),
      "[x, y, w, h] in pixels of the tightest box around an RLE dict's foreground ([0, 0, 0, "
      "0] when empty), as COCO's toBbox.");
  v.def(
      "rle_iou",
      [](const py::dict& detection, const py::dict& ground_truth, bool crowd) {
        return vision::RleIou(RleFromDict(detection, "rle_iou: detection"),
                              RleFromDict(ground_truth, "rle_iou: ground_truth"), crowd);
      },
      py::arg("detection"), py::arg("ground_truth"), py::arg("crowd") = false,
      "Intersection over union of two RLE dicts of one size, computed on the runs; with crowd "
      "(the ground truth is an iscrowd region) intersection over the detection's area.");

  py::class_<vision::CategoryAp>(v, "CategoryAp", "The detection result of one category.")
      .def_readonly("category_id", &vision::CategoryAp::category_id, "The category's id.")
      .def_readonly("name", &vision::CategoryAp::name, "Its name, e.g. 'Cabinet/rotation_door'.")
      .def_readonly("object_category", &vision::CategoryAp::object_category,
                    "The name before its first '/' ('' without one): the table's row.")
      .def_readonly("part", &vision::CategoryAp::part,
                    "The name after its first '/' (the whole name without one): the column.")
      .def_readonly("present", &vision::CategoryAp::present,
                    "Whether it has ground truth (iscrowd aside); absent ones are not in the mAP.")
      .def_readonly("ap", &vision::CategoryAp::ap,
                    "Average precision in [0, 1] (101-point, COCO's); nan when absent.")
      .def_readonly("ground_truths", &vision::CategoryAp::ground_truths,
                    "Annotations, iscrowd ones not counted.")
      .def_readonly("crowd", &vision::CategoryAp::crowd, "iscrowd annotations.")
      .def_readonly("detections", &vision::CategoryAp::detections,
                    "Results of the category, before the per-image cut.")
      .def_readonly("true_positives", &vision::CategoryAp::true_positives,
                    "Kept detections matched to a ground truth.")
      .def_readonly("false_positives", &vision::CategoryAp::false_positives,
                    "Kept detections matched to nothing.")
      .def_readonly("ignored", &vision::CategoryAp::ignored,
                    "Kept detections on an iscrowd region only: neither true nor false.")
      .def("__repr__", [](const vision::CategoryAp& c) {
        return "CategoryAp('" + c.name + "', ap=" + std::to_string(c.ap) + ")";
      });

  py::class_<vision::DetectionEvaluation>(v, "DetectionEvaluation",
                                          "AP per category and their mean (evaluate_detection).")
      .def_readonly("categories", &vision::DetectionEvaluation::categories,
                    "CategoryAp of each category, in the ground truth's order.")
      .def_readonly("map", &vision::DetectionEvaluation::map,
                    "Mean AP over the present categories, in [0, 1]; nan when none is.")
      .def_readonly("present", &vision::DetectionEvaluation::present,
                    "Number of categories in the mean.")
      .def_property_readonly(
          "iou_threshold",
          [](const vision::DetectionEvaluation& e) { return e.options.iou_threshold; },
          "Mask IoU a match needs.")
      .def_property_readonly(
          "max_detections",
          [](const vision::DetectionEvaluation& e) { return e.options.max_detections; },
          "Detections kept per image and category.")
      .def("to_markdown", &vision::DetectionTableMarkdown,
           "The paper's table as Markdown: object categories by part labels, AP in percent.")
      .def("to_csv", &vision::DetectionTableCsv, "The same table as CSV.")
      .def("to_json", &vision::DetectionMetricsJson,
           "Everything as JSON text, numbers in full (the CLI's metrics.json).");

  v.def(
      "evaluate_detection",
      [](const py::object& ground_truth, const py::object& results, double iou_threshold,
         int max_detections) {
        const auto [gt_is_path, gt] = Document(ground_truth);
        const auto [results_is_path, res] = Document(results);
        vision::DetectionOptions options;
        options.iou_threshold = iou_threshold;
        options.max_detections = max_detections;
        py::gil_scoped_release release;
        const vision::CocoDataset dataset =
            gt_is_path ? vision::LoadCocoDataset(gt)
                       : vision::ParseCocoDataset(gt, "COCO ground truth (dict)");
        const std::vector<vision::CocoDetection> detections =
            results_is_path ? vision::LoadCocoResults(res, dataset)
                            : vision::ParseCocoResults(res, dataset, "COCO results (list)");
        return vision::EvaluateDetection(dataset, detections, options);
      },
      py::arg("ground_truth"), py::arg("results"), py::arg("iou_threshold") = 0.5,
      py::arg("max_detections") = 100,
      "AP per category at mask IoU iou_threshold and their mean, COCO's protocol (see "
      "docs/vision.md). ground_truth: a COCO instances JSON file (path) or its dict; results: "
      "a COCO results JSON file (path) or its list of {image_id, category_id, segmentation "
      "(RLE), score}. Raises PartsimError naming the entry at fault.");

  py::class_<vision::MotionEvaluation>(v, "MotionEvaluation",
                                       "The paper's Table 2 (evaluate_motion); means over the "
                                       "samples of each ground-truth type, nan when none.")
      .def_readonly("slider_range", &vision::MotionEvaluation::slider_range,
                    "Metres: the ground truth's slider-state normalisation.")
      .def_readonly("hinges", &vision::MotionEvaluation::hinges, "Hinge samples.")
      .def_readonly("sliders", &vision::MotionEvaluation::sliders, "Slider samples.")
      .def_readonly("hinge_accuracy", &vision::MotionEvaluation::hinge_accuracy,
                    "H acc: fraction of hinges predicted as hinges.")
      .def_readonly("slider_accuracy", &vision::MotionEvaluation::slider_accuracy,
                    "S acc: fraction of sliders predicted as sliders.")
      .def_readonly("hinge_origin_error", &vision::MotionEvaluation::hinge_origin_error,
                    "H_o err: mean distance from the predicted pivot to the true axis line, m.")
      .def_readonly("hinge_axis_error", &vision::MotionEvaluation::hinge_axis_error,
                    "H_a err: mean sign-free angle between hinge axes, degrees.")
      .def_readonly("slider_axis_error", &vision::MotionEvaluation::slider_axis_error,
                    "S_a err: mean sign-free angle between slider axes, degrees.")
      .def_readonly("door_error", &vision::MotionEvaluation::door_error,
                    "Mean |x_door error| * 360, degrees.")
      .def_readonly("drawer_error", &vision::MotionEvaluation::drawer_error,
                    "Mean |x_drawer error| * slider_range, metres.")
      .def("to_markdown", &vision::MotionTableMarkdown, "Table 2 as Markdown.")
      .def("to_csv", &vision::MotionTableCsv, "The same row as CSV with a header.")
      .def("to_json", &vision::MotionMetricsJson,
           "Everything as JSON text, numbers in full (the CLI's metrics.json).");

  v.def(
      "evaluate_motion",
      [](const py::object& ground_truth, const py::object& predictions) {
        const auto [gt_is_path, gt] = Document(ground_truth);
        const auto [predictions_is_path, pred] = Document(predictions);
        py::gil_scoped_release release;
        return vision::EvaluateMotion(
            gt_is_path ? vision::LoadMotionGroundTruth(gt)
                       : vision::ParseMotionGroundTruth(gt, "motion ground truth (dict)"),
            predictions_is_path
                ? vision::LoadMotionPredictions(pred)
                : vision::ParseMotionPredictions(pred, "motion predictions (dict)"));
      },
      py::arg("ground_truth"), py::arg("predictions"),
      "The motion-attribute metrics (H acc, S acc, H_o, H_a, S_a, door and drawer errors). "
      "ground_truth: a file (path) or dict {'slider_range': R, 'samples': [{'sample_id', 'm': "
      "[13 numbers]}]}; predictions: a file or dict {'samples': [...]}, one per sample. m = "
      "(T_r, T_t, pivot (3), hinge axis (3), slider axis (3), x_door, x_drawer), camera frame.");

  v.def(
      "show",
      [](const py::object& dir, long long index, const py::object& out, const std::string& split,
         const std::optional<std::string>& kind) {
        py::module_ os = py::module_::import("os");
        vision::ShowOptions o;
        o.dir = os.attr("fspath")(dir).cast<std::string>();
        o.index = index;
        o.split = split;
        if (kind) {
          const std::string& k = *kind;
          if (k != "detection" && k != "motion")
            throw Error("show: kind must be 'detection', 'motion' or None, got '" + k + "'");
          o.kind =
              k == "detection" ? vision::DatasetKind::kDetection : vision::DatasetKind::kMotion;
        }
        const std::string path =
            out.is_none() ? std::string() : os.attr("fspath")(out).cast<std::string>();
        vision::ShownImage image;
        {
          py::gil_scoped_release release;
          image = path.empty() ? vision::ShowDatasetImage(o) : vision::WriteShowPng(o, path);
        }
        py::array_t<std::uint8_t> rgb({image.height, image.width, 3});
        std::copy(image.rgb.begin(), image.rgb.end(), rgb.mutable_data());
        return rgb;
      },
      py::arg("dir"), py::arg("index") = 0, py::arg("out") = py::none(), py::arg("split") = "train",
      py::arg("kind") = py::none(),
      "The picture of a dataset that partsim vision detection-dataset or motion-dataset wrote "
      "into dir, with its annotations drawn (partsim vision show): detection, the COCO image "
      "index of instances_<split>.json (file order) with every part's mask blended in its own "
      "colour, outlined, and labelled; motion, sample index of motion_<split>.json with the "
      "target's mask and label, the axis projected with the camera's K (a hinge's line through "
      "the pivot dot, a slider's arrow from the mask's centroid) and a caption with type and "
      "state. kind: 'detection', 'motion' or None (the kind whose split files dir holds). "
      "Returns the picture as a (height, width, 3) uint8 array and, when out is a path, writes "
      "it there as a PNG. Raises PartsimError for a folder without dataset files, an index out "
      "of range (giving the range) or a picture that cannot be read.");
}

}  // namespace partsim::python
