// Binary masks and COCO's run-length encoding (RLE) of them, as the COCO tools (pycocotools'
// maskApi) write them: the pixels in column-major order, as alternating runs of background and
// foreground, either as a list of counts or as COCO's compressed text. Area, bounding box and
// IoU are computed on the runs, without decoding.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace partsim::vision {

/// A binary mask of `height` x `width` pixels, row-major: pixel (x, y), column x and row y, is
/// `data[y * width + x]`. 0 is background, any other value foreground.
struct Mask {
  int width = 0;                   ///< pixels
  int height = 0;                  ///< pixels
  std::vector<std::uint8_t> data;  ///< height * width values, row-major

  Mask() = default;
  /// `width` x `height` pixels, each `value`; throws Error for a negative size.
  Mask(int width, int height, std::uint8_t value = 0);

  /// Pixel (x, y), 0 <= x < width, 0 <= y < height (unchecked).
  std::uint8_t& operator()(int x, int y) { return data[static_cast<std::size_t>(y) * width + x]; }
  /// Pixel (x, y), 0 <= x < width, 0 <= y < height (unchecked).
  std::uint8_t operator()(int x, int y) const {
    return data[static_cast<std::size_t>(y) * width + x];
  }
};

/// COCO's run-length encoding of a binary mask. The pixels are read in column-major order (down
/// column 0, then column 1, ...) and cut into runs of equal value; `counts` holds the run
/// lengths, alternately background and foreground, starting with background (so the first
/// count is 0 when pixel (0, 0) is foreground). Valid when the counts add up to height * width.
/// In COCO JSON: {"size": [height, width], "counts": [...] or "compressed text"}.
struct Rle {
  int height = 0;                     ///< pixels (COCO's size[0])
  int width = 0;                      ///< pixels (COCO's size[1])
  std::vector<std::uint32_t> counts;  ///< run lengths, background first
};

/// Largest mask DecodeRle makes: 2^31 pixels.
constexpr std::int64_t kMaxDecodedPixels = std::int64_t{1} << 31;

/// The RLE of `mask`, as COCO's encoder makes it: an empty or all-background mask gives one
/// count (height * width; [0] for a mask of no pixels), a full one [0, height * width].
Rle EncodeMask(const Mask& mask);

/// The mask of `rle` (pixels 0 and 1). Throws Error when CheckRle fails or the mask would have
/// more than kMaxDecodedPixels pixels.
Mask DecodeRle(const Rle& rle);

/// Throws Error "`what`: ..." unless the size is non-negative and the counts add up to
/// height * width (the message gives both).
void CheckRle(const Rle& rle, const std::string& what);

/// COCO's compressed text of `counts` (maskApi's rleToString): each count from the third on
/// minus the count two places before it, written as groups of 5 bits, least significant first,
/// in characters '0' (48) to 'o' (111): bit 5 of a character says that another follows, bit 4
/// of the last is the sign.
std::string CompressRleCounts(const std::vector<std::uint32_t>& counts);

/// The counts of COCO's compressed text (maskApi's rleFrString). Throws Error naming the
/// character position when a character is outside '0'..'o', the text ends inside a number, a
/// number is too long, or a count comes out negative or above 2^32 - 1.
std::vector<std::uint32_t> DecompressRleCounts(const std::string& text);

/// Foreground pixels of `rle`: the sum of its odd-numbered counts.
std::uint64_t RleArea(const Rle& rle);

/// The tightest box [x, y, w, h] around the foreground of `rle`, in pixels (x, y: its top-left
/// pixel; w, h: its size), [0, 0, 0, 0] when the mask is empty; COCO's toBbox.
std::array<double, 4> RleBoundingBox(const Rle& rle);

/// Foreground pixels in both `a` and `b`, computed on the runs. Throws Error when the sizes
/// differ.
std::uint64_t RleIntersection(const Rle& a, const Rle& b);

/// Intersection over union of `detection` and `ground_truth`, computed on the runs (COCO's
/// maskUtils.iou): |D and G| / |D or G|, or, when `crowd` (the ground truth is an iscrowd
/// region), |D and G| / |D|; 0 when the denominator is 0. Throws Error when the sizes differ.
double RleIou(const Rle& detection, const Rle& ground_truth, bool crowd = false);

}  // namespace partsim::vision
