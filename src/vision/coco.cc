// Binary masks and COCO's run-length encoding.
#include "partsim/vision/coco.h"

#include <algorithm>
#include <limits>

#include "partsim/core/check.h"

namespace partsim::vision {

Mask::Mask(int width, int height, std::uint8_t value) : width(width), height(height) {
  PARTSIM_THROW_UNLESS(width >= 0 && height >= 0, "Mask: size must be non-negative, got " +
                                                      std::to_string(width) + " x " +
                                                      std::to_string(height));
  data.assign(static_cast<std::size_t>(width) * height, value);
}

Rle EncodeMask(const Mask& mask) {
  PARTSIM_THROW_UNLESS(mask.width >= 0 && mask.height >= 0 &&
                           mask.data.size() == static_cast<std::size_t>(mask.width) * mask.height,
                       "EncodeMask: the mask holds " + std::to_string(mask.data.size()) +
                           " values for " + std::to_string(mask.width) + " x " +
                           std::to_string(mask.height) + " pixels");
  Rle rle;
  rle.height = mask.height;
  rle.width = mask.width;
  // column-major walk; a run ends where the value changes, starting with background
  bool value = false;
  std::uint32_t run = 0;
  for (int x = 0; x < mask.width; ++x) {
    for (int y = 0; y < mask.height; ++y) {
      const bool v = mask(x, y) != 0;
      if (v != value) {
        rle.counts.push_back(run);
        run = 0;
        value = v;
      }
      ++run;
    }
  }
  rle.counts.push_back(run);
  return rle;
}

void CheckRle(const Rle& rle, const std::string& what) {
  PARTSIM_THROW_UNLESS(rle.height >= 0 && rle.width >= 0,
                       what + ": size must be non-negative, got [" + std::to_string(rle.height) +
                           ", " + std::to_string(rle.width) + "]");
  std::uint64_t sum = 0;
  for (std::uint32_t c : rle.counts) sum += c;
  const std::uint64_t pixels = static_cast<std::uint64_t>(rle.height) * rle.width;
  PARTSIM_THROW_UNLESS(sum == pixels, what + ": the counts add up to " + std::to_string(sum) +
                                          " pixels, the size [" + std::to_string(rle.height) +
                                          ", " + std::to_string(rle.width) + "] has " +
                                          std::to_string(pixels));
}

Mask DecodeRle(const Rle& rle) {
  CheckRle(rle, "DecodeRle");
  const std::int64_t pixels = static_cast<std::int64_t>(rle.height) * rle.width;
  PARTSIM_THROW_UNLESS(pixels <= kMaxDecodedPixels,
                       "DecodeRle: a mask of [" + std::to_string(rle.height) + ", " +
                           std::to_string(rle.width) + "] is too large to decode (more than " +
                           std::to_string(kMaxDecodedPixels) + " pixels)");
  Mask mask(rle.width, rle.height);
  // runs in column-major order: index i is pixel (i / height, i % height)
  std::int64_t i = 0;
  for (std::size_t k = 0; k < rle.counts.size(); ++k) {
    const std::int64_t end = i + rle.counts[k];
    if (k % 2 == 1) {
      for (std::int64_t j = i; j < end; ++j)
        mask(static_cast<int>(j / rle.height), static_cast<int>(j % rle.height)) = 1;
    }
    i = end;
  }
  return mask;
}

std::string CompressRleCounts(const std::vector<std::uint32_t>& counts) {
  std::string text;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    // from the fourth count on (COCO's "i > 2"), the difference to the count of the same kind
    // two places before
    std::int64_t x = counts[i];
    if (i > 2) x -= counts[i - 2];
    // 5 bits per character, least significant first; bit 5 flags a continuation, and the last
    // group's bit 4 carries the sign (arithmetic shift keeps it)
    bool more = true;
    while (more) {
      int c = static_cast<int>(x & 0x1f);
      x >>= 5;
      more = (c & 0x10) ? x != -1 : x != 0;
      if (more) c |= 0x20;
      text += static_cast<char>(c + 48);
    }
  }
  return text;
}

std::vector<std::uint32_t> DecompressRleCounts(const std::string& text) {
  // a count needs at most 34 bits (a difference of two 32-bit counts, signed): 7 groups of 5
  constexpr int kMaxGroups = 7;
  std::vector<std::uint32_t> counts;
  std::size_t p = 0;
  while (p < text.size()) {
    const std::size_t start = p;
    std::int64_t x = 0;
    int k = 0;
    bool more = true;
    while (more) {
      PARTSIM_THROW_UNLESS(p < text.size(),
                           "RLE counts: the text ends inside the number at "
                           "character " +
                               std::to_string(start));
      const int c = static_cast<unsigned char>(text[p]) - 48;
      PARTSIM_THROW_UNLESS(c >= 0 && c < 64, "RLE counts: character " + std::to_string(p) + " ('" +
                                                 std::string(1, text[p]) +
                                                 "') is not one of '0' to 'o'");
      PARTSIM_THROW_UNLESS(k < kMaxGroups, "RLE counts: the number at character " +
                                               std::to_string(start) + " is longer than " +
                                               std::to_string(kMaxGroups) + " characters");
      x |= static_cast<std::int64_t>(c & 0x1f) << (5 * k);
      more = (c & 0x20) != 0;
      ++p;
      ++k;
      if (!more && (c & 0x10)) x |= static_cast<std::int64_t>(~std::uint64_t{0} << (5 * k));
    }
    if (counts.size() > 2) x += counts[counts.size() - 2];
    PARTSIM_THROW_UNLESS(x >= 0 && x <= std::numeric_limits<std::uint32_t>::max(),
                         "RLE counts: count " + std::to_string(counts.size()) + " (at character " +
                             std::to_string(start) + ") is " + std::to_string(x) +
                             ", outside 0 to 2^32 - 1");
    counts.push_back(static_cast<std::uint32_t>(x));
  }
  return counts;
}

std::uint64_t RleArea(const Rle& rle) {
  std::uint64_t area = 0;
  for (std::size_t k = 1; k < rle.counts.size(); k += 2) area += rle.counts[k];
  return area;
}

std::array<double, 4> RleBoundingBox(const Rle& rle) {
  if (rle.height <= 0) return {0, 0, 0, 0};
  const std::uint64_t h = static_cast<std::uint64_t>(rle.height);
  std::uint64_t x0 = std::numeric_limits<std::uint64_t>::max(), x1 = 0;
  std::uint64_t y0 = h, y1 = 0;
  bool any = false;
  std::uint64_t i = 0;
  for (std::size_t k = 0; k < rle.counts.size(); ++k) {
    const std::uint64_t n = rle.counts[k];
    if (k % 2 == 1 && n > 0) {
      // a foreground run from pixel index i to i + n - 1, column-major
      const std::uint64_t first = i, last = i + n - 1;
      const std::uint64_t cx0 = first / h, cx1 = last / h;
      x0 = std::min(x0, cx0);
      x1 = std::max(x1, cx1);
      if (cx0 == cx1) {
        y0 = std::min(y0, first % h);
        y1 = std::max(y1, last % h);
      } else {
        // the run wraps into the next column: it holds the last row of one column and the
        // first row of the next
        y0 = 0;
        y1 = h - 1;
      }
      any = true;
    }
    i += n;
  }
  if (!any) return {0, 0, 0, 0};
  return {static_cast<double>(x0), static_cast<double>(y0), static_cast<double>(x1 - x0 + 1),
          static_cast<double>(y1 - y0 + 1)};
}

std::uint64_t RleIntersection(const Rle& a, const Rle& b) {
  PARTSIM_THROW_UNLESS(a.height == b.height && a.width == b.width,
                       "RLE intersection: masks of different sizes, [" + std::to_string(a.height) +
                           ", " + std::to_string(a.width) + "] and [" + std::to_string(b.height) +
                           ", " + std::to_string(b.width) + "]");
  // walk both run lists at once: each step advances to the nearer run end; runs at odd
  // positions are foreground
  std::uint64_t inter = 0;
  std::size_t i = 0, j = 0;
  std::uint64_t left_a = a.counts.empty() ? 0 : a.counts[0];
  std::uint64_t left_b = b.counts.empty() ? 0 : b.counts[0];
  while (i < a.counts.size() && j < b.counts.size()) {
    const std::uint64_t step = std::min(left_a, left_b);
    if (i % 2 == 1 && j % 2 == 1) inter += step;
    left_a -= step;
    left_b -= step;
    if (left_a == 0 && ++i < a.counts.size()) left_a = a.counts[i];
    if (left_b == 0 && ++j < b.counts.size()) left_b = b.counts[j];
  }
  return inter;
}

double RleIou(const Rle& detection, const Rle& ground_truth, bool crowd) {
  const std::uint64_t inter = RleIntersection(detection, ground_truth);
  const std::uint64_t area_d = RleArea(detection);
  const std::uint64_t denominator = crowd ? area_d : area_d + RleArea(ground_truth) - inter;
  return denominator == 0 ? 0.0 : static_cast<double>(inter) / static_cast<double>(denominator);
}

}  // namespace partsim::vision
