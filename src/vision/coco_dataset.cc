// COCO instance-segmentation files: reading with checks, writing.
#include "partsim/vision/coco_dataset.h"

#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "partsim/core/error.h"
#include "vision/json_fields.h"

namespace partsim::vision {
namespace {

using internal::ArrayField;
using internal::AsInteger;
using internal::AsNumber;
using internal::AsString;
using internal::Describe;
using internal::Field;
using internal::json;

// a pixel size: an integer from 0 to INT_MAX
int AsSize(const json& value, const std::string& what) {
  const std::int64_t n = AsInteger(value, what);
  if (n < 0 || n > std::numeric_limits<int>::max())
    throw Error(what + " must be from 0 to " + std::to_string(std::numeric_limits<int>::max()) +
                ", got " + std::to_string(n));
  return static_cast<int>(n);
}

// {"size": [h, w], "counts": "text" or [n, ...]} of `image`'s size
Rle ParseRle(const json& segmentation, const CocoImage& image, const std::string& where) {
  const std::string what = where + ": 'segmentation'";
  if (segmentation.is_array())
    throw Error(what +
                " is a polygon list; only RLE masks are supported ({\"size\": [height, "
                "width], \"counts\": ...})");
  if (!segmentation.is_object())
    throw Error(what + " must be an RLE object {\"size\", \"counts\"}, got " +
                Describe(segmentation));
  Rle rle;
  const json& size = Field(segmentation, "size", what);
  if (!size.is_array() || size.size() != 2)
    throw Error(what + ": 'size' must be [height, width], got " + Describe(size));
  rle.height = AsSize(size[0], what + ": size[0] (height)");
  rle.width = AsSize(size[1], what + ": size[1] (width)");
  const json& counts = Field(segmentation, "counts", what);
  if (counts.is_string()) {
    try {
      rle.counts = DecompressRleCounts(counts.get<std::string>());
    } catch (const Error& e) {
      throw Error(what + ": " + e.what());
    }
  } else if (counts.is_array()) {
    rle.counts.reserve(counts.size());
    for (std::size_t k = 0; k < counts.size(); ++k) {
      const std::int64_t n = AsInteger(counts[k], what + ": counts[" + std::to_string(k) + "]");
      if (n < 0 || n > std::numeric_limits<std::uint32_t>::max())
        throw Error(what + ": counts[" + std::to_string(k) + "] must be from 0 to 2^32 - 1, got " +
                    std::to_string(n));
      rle.counts.push_back(static_cast<std::uint32_t>(n));
    }
  } else {
    throw Error(what + ": 'counts' must be a string (compressed) or a list of integers, got " +
                Describe(counts));
  }
  CheckRle(rle, what);
  if (rle.height != image.height || rle.width != image.width)
    throw Error(what + ": the mask's size [" + std::to_string(rle.height) + ", " +
                std::to_string(rle.width) + "] differs from image " + std::to_string(image.id) +
                "'s [height, width] = [" + std::to_string(image.height) + ", " +
                std::to_string(image.width) + "]");
  return rle;
}

// image id -> index into `images`
std::unordered_map<std::int64_t, std::size_t> ImageIndex(const std::vector<CocoImage>& images) {
  std::unordered_map<std::int64_t, std::size_t> index;
  for (std::size_t i = 0; i < images.size(); ++i) index.emplace(images[i].id, i);
  return index;
}

json RleJson(const Rle& rle) {
  return json{{"size", {rle.height, rle.width}}, {"counts", CompressRleCounts(rle.counts)}};
}

}  // namespace

CocoDataset ParseCocoDataset(const std::string& json_text, const std::string& source) {
  const json doc = internal::ParseDocument(json_text, source);
  if (!doc.is_object())
    throw Error(source + ": expected an object with images, annotations and categories, got " +
                Describe(doc));
  CocoDataset out;

  const json& images = ArrayField(doc, "images", source);
  std::unordered_set<std::int64_t> image_ids;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const std::string where = source + ": images[" + std::to_string(i) + "]";
    CocoImage image;
    image.id = AsInteger(Field(images[i], "id", where), where + ": 'id'");
    const std::string at = where + " (id " + std::to_string(image.id) + ")";
    image.width = AsSize(Field(images[i], "width", at), at + ": 'width'");
    image.height = AsSize(Field(images[i], "height", at), at + ": 'height'");
    if (images[i].contains("file_name"))
      image.file_name = AsString(images[i]["file_name"], at + ": 'file_name'");
    if (!image_ids.insert(image.id).second)
      throw Error(at + ": the image id " + std::to_string(image.id) + " appears twice");
    out.images.push_back(std::move(image));
  }

  const json& categories = ArrayField(doc, "categories", source);
  std::unordered_set<std::int64_t> category_ids;
  for (std::size_t i = 0; i < categories.size(); ++i) {
    const std::string where = source + ": categories[" + std::to_string(i) + "]";
    CocoCategory category;
    category.id = AsInteger(Field(categories[i], "id", where), where + ": 'id'");
    const std::string at = where + " (id " + std::to_string(category.id) + ")";
    category.name = AsString(Field(categories[i], "name", at), at + ": 'name'");
    if (categories[i].contains("supercategory"))
      category.supercategory = AsString(categories[i]["supercategory"], at + ": 'supercategory'");
    if (!category_ids.insert(category.id).second)
      throw Error(at + ": the category id " + std::to_string(category.id) + " appears twice");
    out.categories.push_back(std::move(category));
  }

  const auto image_index = ImageIndex(out.images);
  const json& annotations = ArrayField(doc, "annotations", source);
  std::unordered_set<std::int64_t> annotation_ids;
  out.annotations.reserve(annotations.size());
  for (std::size_t i = 0; i < annotations.size(); ++i) {
    const json& entry = annotations[i];
    const std::string where = source + ": annotations[" + std::to_string(i) + "]";
    CocoAnnotation a;
    a.id = AsInteger(Field(entry, "id", where), where + ": 'id'");
    const std::string at = where + " (id " + std::to_string(a.id) + ")";
    if (!annotation_ids.insert(a.id).second)
      throw Error(at + ": the annotation id " + std::to_string(a.id) + " appears twice");
    a.image_id = AsInteger(Field(entry, "image_id", at), at + ": 'image_id'");
    auto image = image_index.find(a.image_id);
    if (image == image_index.end())
      throw Error(at + ": image_id " + std::to_string(a.image_id) + " is not in 'images'");
    a.category_id = AsInteger(Field(entry, "category_id", at), at + ": 'category_id'");
    if (!category_ids.count(a.category_id))
      throw Error(at + ": category_id " + std::to_string(a.category_id) +
                  " is not in 'categories'");
    a.segmentation = ParseRle(Field(entry, "segmentation", at), out.images[image->second], at);
    if (entry.contains("iscrowd")) {
      const json& crowd = entry["iscrowd"];
      if (crowd.is_boolean()) {
        a.iscrowd = crowd.get<bool>();
      } else {
        const std::int64_t c = AsInteger(crowd, at + ": 'iscrowd'");
        if (c != 0 && c != 1)
          throw Error(at + ": 'iscrowd' must be 0 or 1, got " + Describe(crowd));
        a.iscrowd = c == 1;
      }
    }
    a.area = entry.contains("area") ? AsNumber(entry["area"], at + ": 'area'")
                                    : static_cast<double>(RleArea(a.segmentation));
    if (entry.contains("bbox")) {
      const json& box = entry["bbox"];
      if (!box.is_array() || box.size() != 4)
        throw Error(at + ": 'bbox' must be [x, y, width, height], got " + Describe(box));
      for (int k = 0; k < 4; ++k)
        a.bbox[k] = AsNumber(box[k], at + ": bbox[" + std::to_string(k) + "]");
    } else {
      a.bbox = RleBoundingBox(a.segmentation);
    }
    out.annotations.push_back(std::move(a));
  }
  return out;
}

CocoDataset LoadCocoDataset(const std::string& path) {
  const std::string source = "COCO ground truth '" + path + "'";
  return ParseCocoDataset(internal::ReadDocument(path, "COCO ground truth"), source);
}

std::vector<CocoDetection> ParseCocoResults(const std::string& json_text,
                                            const CocoDataset& ground_truth,
                                            const std::string& source) {
  const json doc = internal::ParseDocument(json_text, source);
  if (!doc.is_array())
    throw Error(source +
                ": expected a list of results {image_id, category_id, segmentation, "
                "score}, got " +
                Describe(doc));
  const auto image_index = ImageIndex(ground_truth.images);
  std::unordered_set<std::int64_t> category_ids;
  for (const CocoCategory& c : ground_truth.categories) category_ids.insert(c.id);
  std::vector<CocoDetection> out;
  out.reserve(doc.size());
  for (std::size_t i = 0; i < doc.size(); ++i) {
    const json& entry = doc[i];
    const std::string where = source + ": [" + std::to_string(i) + "]";
    CocoDetection d;
    d.image_id = AsInteger(Field(entry, "image_id", where), where + ": 'image_id'");
    auto image = image_index.find(d.image_id);
    if (image == image_index.end())
      throw Error(where + ": image_id " + std::to_string(d.image_id) +
                  " is not an image of the ground truth");
    d.category_id = AsInteger(Field(entry, "category_id", where), where + ": 'category_id'");
    if (!category_ids.count(d.category_id))
      throw Error(where + ": category_id " + std::to_string(d.category_id) +
                  " is not a category of the ground truth");
    d.segmentation =
        ParseRle(Field(entry, "segmentation", where), ground_truth.images[image->second], where);
    d.score = AsNumber(Field(entry, "score", where), where + ": 'score'");
    out.push_back(std::move(d));
  }
  return out;
}

std::vector<CocoDetection> LoadCocoResults(const std::string& path,
                                           const CocoDataset& ground_truth) {
  const std::string source = "COCO results '" + path + "'";
  return ParseCocoResults(internal::ReadDocument(path, "COCO results"), ground_truth, source);
}

std::string CocoDatasetToJson(const CocoDataset& dataset) {
  json images = json::array(), categories = json::array(), annotations = json::array();
  for (const CocoImage& image : dataset.images)
    images.push_back({{"id", image.id},
                      {"width", image.width},
                      {"height", image.height},
                      {"file_name", image.file_name}});
  for (const CocoCategory& c : dataset.categories)
    categories.push_back({{"id", c.id}, {"name", c.name}, {"supercategory", c.supercategory}});
  for (const CocoAnnotation& a : dataset.annotations)
    annotations.push_back({{"id", a.id},
                           {"image_id", a.image_id},
                           {"category_id", a.category_id},
                           {"segmentation", RleJson(a.segmentation)},
                           {"area", a.area},
                           {"bbox", a.bbox},
                           {"iscrowd", a.iscrowd ? 1 : 0}});
  const json doc = {{"images", images}, {"annotations", annotations}, {"categories", categories}};
  return doc.dump() + "\n";
}

std::string CocoResultsToJson(const std::vector<CocoDetection>& detections) {
  json doc = json::array();
  for (const CocoDetection& d : detections)
    doc.push_back({{"image_id", d.image_id},
                   {"category_id", d.category_id},
                   {"segmentation", RleJson(d.segmentation)},
                   {"score", d.score}});
  return doc.dump() + "\n";
}

}  // namespace partsim::vision
