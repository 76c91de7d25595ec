// Masks and COCO RLE: hand-written encodings, round trips through both counts forms, and area,
// box and IoU on the runs held against the same quantities counted on decoded pixels.
#include "partsim/vision/coco.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "error_of.h"
#include "partsim/core/error.h"

namespace partsim::vision {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

using partsim::testing::ErrorOf;

// a mask of `width` x `height` with each pixel foreground with probability `density`
Mask RandomMask(int width, int height, double density, std::mt19937* rng) {
  std::bernoulli_distribution on(density);
  Mask m(width, height);
  for (auto& v : m.data) v = on(*rng) ? 1 : 0;
  return m;
}

// a rectangle of foreground [x0, x1) x [y0, y1) in a blank mask
Mask Rectangle(int width, int height, int x0, int y0, int x1, int y1) {
  Mask m(width, height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) m(x, y) = 1;
  return m;
}

TEST(VisionCocoTest, EncodesColumnMajorStartingWithBackground) {
  // 3 wide, 2 high:   row 0: 0 1 1
  //                   row 1: 0 0 1
  // column-major: (col 0) 0 0, (col 1) 1 0, (col 2) 1 1 -> runs 2 zeros, 1 one, 1 zero, 2 ones
  Mask m(3, 2);
  m(1, 0) = m(2, 0) = m(2, 1) = 1;
  const Rle rle = EncodeMask(m);
  EXPECT_EQ(rle.height, 2);
  EXPECT_EQ(rle.width, 3);
  EXPECT_THAT(rle.counts, ElementsAre(2, 1, 1, 2));
  EXPECT_EQ(RleArea(rle), 3u);
  // foreground spans columns 1..2 and rows 0..1
  EXPECT_THAT(RleBoundingBox(rle), ElementsAre(1, 0, 2, 2));
  // pixel (0, 0) in the foreground: the first run of background is empty
  m(0, 0) = 1;
  EXPECT_THAT(EncodeMask(m).counts, ElementsAre(0, 1, 1, 1, 1, 2));
}

TEST(VisionCocoTest, EmptyFullAndSizeless) {
  EXPECT_THAT(EncodeMask(Mask(5, 3, 0)).counts, ElementsAre(15));
  EXPECT_THAT(EncodeMask(Mask(5, 3, 1)).counts, ElementsAre(0, 15));
  EXPECT_THAT(EncodeMask(Mask(0, 4)).counts, ElementsAre(0));
  EXPECT_THAT(EncodeMask(Mask(0, 0)).counts, ElementsAre(0));
  EXPECT_EQ(RleArea(EncodeMask(Mask(5, 3, 1))), 15u);
  EXPECT_THAT(RleBoundingBox(EncodeMask(Mask(5, 3, 0))), ElementsAre(0, 0, 0, 0));
  EXPECT_THAT(RleBoundingBox(EncodeMask(Mask(5, 3, 1))), ElementsAre(0, 0, 5, 3));
  // any non-zero value is foreground
  Mask m(2, 2);
  m(1, 1) = 255;
  EXPECT_THAT(EncodeMask(m).counts, ElementsAre(3, 1));
  for (const Mask& mask : {Mask(5, 3, 0), Mask(5, 3, 1), Mask(0, 4), Mask(3, 0, 1)}) {
    const Mask back = DecodeRle(EncodeMask(mask));
    EXPECT_EQ(back.width, mask.width);
    EXPECT_EQ(back.height, mask.height);
    EXPECT_EQ(back.data, mask.data);
  }
}

TEST(VisionCocoTest, CompressedTextByHand) {
  // counts 5, 3, 10 are written as they are (COCO differences only from the fourth count on):
  // one character each, 48 + n: '5', '3', ':'. The fourth, 2, is written as 2 - 3 = -1: low 5
  // bits 31 (0b11111), and what is left after shifting is -1 with the sign bit (bit 4) set, so
  // no continuation: 48 + 31 = 'O'.
  EXPECT_EQ(CompressRleCounts({5, 3, 10, 2}), "53:O");
  EXPECT_THAT(DecompressRleCounts("53:O"), ElementsAre(5, 3, 10, 2));
  // 20 = 0b10100: bit 4 set, so a second group follows to say the number is positive: the first
  // character carries 20 | 0x20 = 52 -> 'd', the second 0 -> '0'
  EXPECT_EQ(CompressRleCounts({20}), "d0");
  EXPECT_THAT(DecompressRleCounts("d0"), ElementsAre(20));
  // the third count is not a difference, the fifth is (5 - 3 = 2)
  EXPECT_EQ(CompressRleCounts({1, 2, 3}), "123");
  EXPECT_EQ(CompressRleCounts({1, 2, 3, 4, 5}), "12322");
  // 100 = 0b11_00100: groups 4 (with continuation: 36 -> 'T') then 3 -> '3'
  EXPECT_EQ(CompressRleCounts({100}), "T3");
  EXPECT_EQ(CompressRleCounts({}), "");
  EXPECT_TRUE(DecompressRleCounts("").empty());
}

TEST(VisionCocoTest, CompressedTextRoundTripsLargeAndDecreasingCounts) {
  const std::vector<std::uint32_t> counts = {0,           4294967295u, 0,  7,  4294967295u, 1,
                                             4294967295u, 0,           31, 32, 16,          15};
  EXPECT_EQ(DecompressRleCounts(CompressRleCounts(counts)), counts);
}

TEST(VisionCocoTest, RandomMasksRoundTripThroughBothForms) {
  std::mt19937 rng(7);
  const std::vector<std::pair<int, int>> sizes = {{1, 1},   {1, 7},   {7, 1},   {3, 5},
                                                  {13, 17}, {64, 48}, {101, 3}, {2, 999}};
  for (const auto& [w, h] : sizes) {
    for (double density : {0.0, 0.02, 0.5, 0.97, 1.0}) {
      const Mask mask = RandomMask(w, h, density, &rng);
      const Rle rle = EncodeMask(mask);
      // counts list -> mask
      EXPECT_EQ(DecodeRle(rle).data, mask.data) << w << "x" << h << " at " << density;
      // compressed text -> counts -> mask
      Rle again = rle;
      again.counts = DecompressRleCounts(CompressRleCounts(rle.counts));
      EXPECT_EQ(again.counts, rle.counts);
      EXPECT_EQ(DecodeRle(again).data, mask.data);
      const auto area =
          std::count_if(mask.data.begin(), mask.data.end(), [](std::uint8_t v) { return v != 0; });
      EXPECT_EQ(RleArea(rle), static_cast<std::uint64_t>(area));
    }
  }
}

TEST(VisionCocoTest, BoundingBoxMatchesDecodedPixels) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> size(1, 40);
  for (int trial = 0; trial < 300; ++trial) {
    const int w = size(rng), h = size(rng);
    std::uniform_int_distribution<int> px(0, w), py(0, h);
    int x0 = px(rng), x1 = px(rng), y0 = py(rng), y1 = py(rng);
    if (x0 > x1) std::swap(x0, x1);
    if (y0 > y1) std::swap(y0, y1);
    // a rectangle, sometimes with noise outside it
    Mask m = Rectangle(w, h, x0, y0, x1, y1);
    if (trial % 3 == 0) {
      const Mask noise = RandomMask(w, h, 0.01, &rng);
      for (std::size_t i = 0; i < m.data.size(); ++i) m.data[i] |= noise.data[i];
    }
    int bx0 = w, bx1 = -1, by0 = h, by1 = -1;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (m(x, y)) {
          bx0 = std::min(bx0, x);
          bx1 = std::max(bx1, x);
          by0 = std::min(by0, y);
          by1 = std::max(by1, y);
        }
    const auto box = RleBoundingBox(EncodeMask(m));
    if (bx1 < 0) {
      EXPECT_THAT(box, ElementsAre(0, 0, 0, 0));
    } else {
      EXPECT_THAT(box, ElementsAre(bx0, by0, bx1 - bx0 + 1, by1 - by0 + 1))
          << w << "x" << h << " trial " << trial;
    }
  }
  // a run that wraps from the bottom of column 0 to the top of column 1, and nothing else:
  // rows 0 and 2 of a 3-high mask are both covered
  Rle wrap{3, 2, {2, 2, 2}};
  EXPECT_THAT(RleBoundingBox(wrap), ElementsAre(0, 0, 2, 3));
}

TEST(VisionCocoTest, IouOnRunsEqualsIouOfDecodedMasks) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> size(1, 30);
  std::uniform_real_distribution<double> density(0, 1);
  for (int trial = 0; trial < 300; ++trial) {
    const int w = size(rng), h = size(rng);
    const Mask a = RandomMask(w, h, density(rng), &rng);
    const Mask b = RandomMask(w, h, density(rng), &rng);
    std::uint64_t both = 0, either = 0, in_a = 0;
    for (std::size_t i = 0; i < a.data.size(); ++i) {
      both += a.data[i] && b.data[i];
      either += a.data[i] || b.data[i];
      in_a += a.data[i] != 0;
    }
    const Rle ra = EncodeMask(a), rb = EncodeMask(b);
    EXPECT_EQ(RleIntersection(ra, rb), both);
    EXPECT_EQ(RleIou(ra, rb), either ? static_cast<double>(both) / either : 0.0);
    EXPECT_EQ(RleIou(rb, ra), RleIou(ra, rb));
    // against a crowd region: intersection over the detection's area
    EXPECT_EQ(RleIou(ra, rb, true), in_a ? static_cast<double>(both) / in_a : 0.0);
  }
}

TEST(VisionCocoTest, IouOfHandCases) {
  // two 2x2 squares in a 4x4 image overlapping in one column of 2 pixels: 2 / (4 + 4 - 2)
  const Rle a = EncodeMask(Rectangle(4, 4, 0, 0, 2, 2));
  const Rle b = EncodeMask(Rectangle(4, 4, 1, 0, 3, 2));
  EXPECT_DOUBLE_EQ(RleIou(a, b), 2.0 / 6.0);
  EXPECT_DOUBLE_EQ(RleIou(a, b, true), 2.0 / 4.0);
  EXPECT_EQ(RleIou(a, a), 1.0);
  // empty masks: 0, not NaN
  const Rle empty = EncodeMask(Mask(4, 4));
  EXPECT_EQ(RleIou(empty, empty), 0.0);
  EXPECT_EQ(RleIou(empty, a, true), 0.0);
  // non-canonical counts with empty runs inside describe the same mask
  const Rle split{4, 4, {0, 1, 0, 1, 2, 2, 10}};
  EXPECT_EQ(DecodeRle(split).data, Rectangle(4, 4, 0, 0, 2, 2).data);
  EXPECT_EQ(RleIou(split, a), 1.0);
}

TEST(VisionCocoTest, BadInputIsNamed) {
  EXPECT_THAT(ErrorOf([] {
                RleIou(Rle{2, 2, {4}}, Rle{2, 3, {6}});
              }),
              HasSubstr("different sizes, [2, 2] and [2, 3]"));
  EXPECT_THAT(ErrorOf([] {
                DecodeRle(Rle{2, 2, {3}});
              }),
              HasSubstr("the counts add up to 3 pixels, the size [2, 2] has 4"));
  EXPECT_THAT(ErrorOf([] {
                CheckRle(Rle{-1, 2, {}}, "mask");
              }),
              HasSubstr("mask: size must be non-negative"));
  EXPECT_THAT(ErrorOf([] {
                DecodeRle(Rle{65536, 65536, {4294967295u, 1}});
              }),
              HasSubstr("too large to decode"));
  EXPECT_THAT(ErrorOf([] { Mask(-1, 2); }), HasSubstr("non-negative"));
  // '~' is past 'o'; 'd' announces a continuation that never comes; 'O' alone is -1
  EXPECT_THAT(ErrorOf([] { DecompressRleCounts("12~"); }), HasSubstr("character 2 ('~')"));
  EXPECT_THAT(ErrorOf([] { DecompressRleCounts("5d"); }), HasSubstr("ends inside the number"));
  EXPECT_THAT(ErrorOf([] { DecompressRleCounts("O"); }), HasSubstr("is -1, outside"));
  EXPECT_THAT(ErrorOf([] { DecompressRleCounts("oooooooo0"); }), HasSubstr("longer than 7"));
  Mask torn(3, 3);
  torn.data.pop_back();
  EXPECT_THAT(ErrorOf([&] { EncodeMask(torn); }), HasSubstr("holds 8 values for 3 x 3"));
}

}  // namespace
}  // namespace partsim::vision
