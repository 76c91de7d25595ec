// `partsim vision show`: one picture of a dataset that GenerateDataset wrote, drawn with its
// annotations over it, what a person checks first. Detection: every part instance's mask
// blended half and half over the RGB in its own bright colour ((rgb + colour + 1) / 2 per
// channel), outlined in full colour, its part label on a dark box by the mask's bounding box.
// Motion: the target part's mask and label, the joint's axis projected with the camera's K (a hinge
// through the pivot, long enough to cross the part; a slider as an arrow from the mask's centroid),
// the pivot as a dot, and a caption with the type, the label and the state.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "partsim/vision/dataset.h"

namespace partsim::vision {

/// Which picture ShowDatasetImage draws.
struct ShowOptions {
  std::string dir;  ///< the dataset folder (GenerateDataset's out)
  /// Detection: the index of the image in the split file's "images" (file order); motion: the
  /// index of the sample in its "samples".
  long long index = 0;
  std::string split = "train";  ///< "train" or "test"
  /// The dataset's kind; none: the kind whose split files (instances_*.json or motion_*.json)
  /// the folder holds.
  std::optional<DatasetKind> kind;
};

/// A box of pixels on a picture: top-left corner (x, y) and size (w, h).
struct PixelBox {
  int x = 0, y = 0, w = 0, h = 0;
  /// Whether pixel (px, py) is inside.
  bool Contains(int px, int py) const { return px >= x && px < x + w && py >= y && py < y + h; }
};

/// One mask drawn.
struct ShownInstance {
  std::string label;                    ///< the text drawn: the part label ("drawer")
  std::array<std::uint8_t, 3> color{};  ///< its RGB colour
  std::array<double, 4> bbox{};         ///< the mask's [x, y, w, h], pixels
  PixelBox label_box;                   ///< the dark box holding the label (clipped to the picture)
};

/// A drawn picture and what was drawn where.
struct ShownImage {
  int width = 0, height = 0;      ///< pixels
  std::vector<std::uint8_t> rgb;  ///< height x width x 3, row-major, top row first
  DatasetKind kind = DatasetKind::kDetection;
  std::string split_file;                ///< the split file read ("instances_train.json")
  std::string rgb_file;                  ///< the picture drawn over, relative to the dataset folder
  std::string title;                     ///< "image 12 (id 13)", "sample 3 (cabinet_3/link_1_00)"
  std::vector<ShownInstance> instances;  ///< in drawing order; motion: the target only
  /// Motion: the caption (white, on a dark box at the bottom: "hinge rotation_door 37.5 deg",
  /// "slider drawer 0.186 m"), and the axis segment drawn, (x0, y0, x1, y1) pixels (a slider's
  /// arrow starts at (x0, y0)); `has_axis` is false when the axis could not be projected (pivot
  /// behind the camera, axis along the view ray).
  PixelBox caption_box;
  std::string caption;
  bool has_axis = false;
  std::array<double, 4> axis_segment{};
  /// Motion, hinges: the pivot's pixel (has_pivot false when behind the camera).
  bool has_pivot = false;
  std::array<double, 2> pivot_pixel{};
};

/// Colour of the axis line and of a slider's arrow.
constexpr std::array<std::uint8_t, 3> kShowAxisColor = {255, 255, 0};
/// Colour of the pivot's dot.
constexpr std::array<std::uint8_t, 3> kShowPivotColor = {255, 0, 255};
/// Colour of the boxes under labels and caption.
constexpr std::array<std::uint8_t, 3> kShowBoxColor = {16, 16, 16};

/// The bright colour of the `k`-th instance drawn (k >= 0; the colours repeat after 10).
std::array<std::uint8_t, 3> ShowInstanceColor(int k);

/// The picture of `options` with its annotations drawn (see the file comment). Throws Error for
/// a folder without dataset files (naming the files looked for), an index out of range (giving
/// the range), a malformed split file (naming the entry) and a picture or mask that cannot be
/// read or whose size is not the split file's.
ShownImage ShowDatasetImage(const ShowOptions& options);

/// ShowDatasetImage written as an RGB PNG at `out_png`; returns what was drawn.
ShownImage WriteShowPng(const ShowOptions& options, const std::string& out_png);

}  // namespace partsim::vision
