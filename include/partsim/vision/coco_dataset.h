// COCO instance-segmentation files: the ground truth ("instances" JSON: images, categories,
// annotations with RLE masks) and detection results (a JSON list of image_id, category_id,
// segmentation, score), read with checks that name the file and the entry at fault, and written
// back as the COCO tools read them.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "partsim/vision/coco.h"

namespace partsim::vision {

/// One entry of "images".
struct CocoImage {
  std::int64_t id = 0;
  int width = 0;          ///< pixels
  int height = 0;         ///< pixels
  std::string file_name;  ///< "" when the file gives none
};

/// One entry of "categories". Part categories are named "<object category>/<part label>"
/// ("Cabinet/rotation_door"); the tables split the name at its first '/'.
struct CocoCategory {
  std::int64_t id = 0;
  std::string name;
  std::string supercategory;  ///< "" when the file gives none
};

/// One entry of "annotations": an instance mask of a category in an image.
struct CocoAnnotation {
  std::int64_t id = 0;
  std::int64_t image_id = 0;
  std::int64_t category_id = 0;
  Rle segmentation;              ///< the image's size
  bool iscrowd = false;          ///< a crowd region: detections on it count neither way
  double area = 0;               ///< pixels; the file's, else RleArea
  std::array<double, 4> bbox{};  ///< [x, y, w, h] pixels; the file's, else RleBoundingBox
};

/// A COCO ground-truth file.
struct CocoDataset {
  std::vector<CocoImage> images;
  std::vector<CocoCategory> categories;
  std::vector<CocoAnnotation> annotations;
};

/// One entry of a COCO results file: a detected instance mask with its confidence.
struct CocoDetection {
  std::int64_t image_id = 0;
  std::int64_t category_id = 0;
  Rle segmentation;  ///< the image's size
  double score = 0;  ///< confidence; higher ranks first
};

/// Reads a ground-truth document: an object with arrays "images" (id, width, height, optional
/// file_name), "categories" (id, name, optional supercategory) and "annotations" (id, image_id,
/// category_id, segmentation as RLE with compressed or list counts, optional iscrowd, area and
/// bbox). Ids are integers, unique within their array; an annotation's image and category must
/// exist and its mask must have its image's size. Polygon segmentations are refused (use RLE).
/// Throws Error naming `source` (a file name or a description) and the entry at fault
/// ("annotations[3] (id 17): ...").
CocoDataset ParseCocoDataset(const std::string& json_text, const std::string& source);

/// ParseCocoDataset of the file at `path`.
CocoDataset LoadCocoDataset(const std::string& path);

/// Reads a results document: a JSON array of {"image_id", "category_id", "segmentation" (RLE of
/// the image's size), "score" (finite)}, each image and category one of `ground_truth`'s; other
/// keys (e.g. "bbox") are ignored. Throws Error naming `source` and the entry at fault.
std::vector<CocoDetection> ParseCocoResults(const std::string& json_text,
                                            const CocoDataset& ground_truth,
                                            const std::string& source);

/// ParseCocoResults of the file at `path`.
std::vector<CocoDetection> LoadCocoResults(const std::string& path,
                                           const CocoDataset& ground_truth);

/// `dataset` as COCO JSON (masks as compressed RLE), as ParseCocoDataset and the COCO tools read
/// it.
std::string CocoDatasetToJson(const CocoDataset& dataset);

/// `detections` as a COCO results JSON array (masks as compressed RLE).
std::string CocoResultsToJson(const std::vector<CocoDetection>& detections);

}  // namespace partsim::vision
