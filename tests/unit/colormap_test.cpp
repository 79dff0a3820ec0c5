// The colormap tables (src/render/colormap.h) against their control points
// and the published maps' landmarks.
#include "render/colormap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace fibscope {
namespace {

std::array<int, 3> rgb(uint32_t c) { return {int(c & 255u), int((c >> 8) & 255u), int((c >> 16) & 255u)}; }

TEST(Colormap, tablesRunFromTheFirstToTheLastControlPoint) {
  for (Colormap map : {Colormap::Viridis, Colormap::Magma, Colormap::Grayscale, Colormap::CoolWarm}) {
    SCOPED_TRACE(std::string(colormapName(map)));
    const std::vector<uint32_t> table = colormapTable(map);
    ASSERT_EQ(table.size(), kColormapEntries);
    const auto points = colormapControlPoints(map);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(rgb(table.front())[k], std::lround(points.front()[k] * 255.0f));
      EXPECT_EQ(rgb(table.back())[k], std::lround(points.back()[k] * 255.0f));
    }
    for (uint32_t c : table) EXPECT_EQ(c >> 24, 255u) << "opaque";
    // Neighbouring entries differ by little: no jumps.
    for (size_t i = 1; i < table.size(); ++i)
      for (int k = 0; k < 3; ++k) EXPECT_LE(std::abs(rgb(table[i])[k] - rgb(table[i - 1])[k]), 12) << "entry " << i;
  }
}

TEST(Colormap, landmarksOfThePublishedMaps) {
  // Viridis: dark purple -> teal -> yellow, lightness increasing.
  const auto viridis = colormapTable(Colormap::Viridis);
  EXPECT_GT(rgb(viridis[0])[2], rgb(viridis[0])[1]);      // purple-blue start
  EXPECT_GT(rgb(viridis[128])[1], rgb(viridis[128])[0]);  // green-teal middle
  EXPECT_GT(rgb(viridis[255])[0], 200);                   // yellow end
  EXPECT_GT(rgb(viridis[255])[1], 200);
  auto luma = [](std::array<int, 3> c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; };
  for (size_t i = 16; i < 256; i += 16) EXPECT_GT(luma(rgb(viridis[i])), luma(rgb(viridis[i - 16]))) << i;
  // Magma: near black to pale yellow, lightness increasing.
  const auto magma = colormapTable(Colormap::Magma);
  EXPECT_LT(luma(rgb(magma[0])), 5);
  EXPECT_GT(luma(rgb(magma[255])), 230);
  for (size_t i = 16; i < 256; i += 16) EXPECT_GT(luma(rgb(magma[i])), luma(rgb(magma[i - 16]))) << i;
  // Grayscale: entry i is grey i.
  const auto gray = colormapTable(Colormap::Grayscale);
  for (uint32_t i = 0; i < 256; ++i) EXPECT_EQ(rgb(gray[i]), (std::array<int, 3>{int(i), int(i), int(i)}));
  // Cool-warm (Moreland): blue end, neutral grey middle, red end.
  const auto cw = colormapTable(Colormap::CoolWarm);
  EXPECT_EQ(rgb(cw[0]), (std::array<int, 3>{59, 76, 192}));
  EXPECT_EQ(rgb(cw[255]), (std::array<int, 3>{180, 4, 38}));
  const auto mid = rgb(cw[128]);
  EXPECT_LE(std::abs(mid[0] - mid[2]), 10);
  EXPECT_GT(mid[0], 200);
}

TEST(Colormap, indexClampsTheRangeAndHandlesDegenerateInput) {
  EXPECT_EQ(colormapIndex(10.0f, 10.0f, 30.0f), 0u);
  EXPECT_EQ(colormapIndex(30.0f, 10.0f, 30.0f), 255u);
  EXPECT_EQ(colormapIndex(20.0f, 10.0f, 30.0f), 128u);
  EXPECT_EQ(colormapIndex(-1e30f, 10.0f, 30.0f), 0u);
  EXPECT_EQ(colormapIndex(1e30f, 10.0f, 30.0f), 255u);
  EXPECT_EQ(colormapIndex(std::numeric_limits<float>::quiet_NaN(), 10.0f, 30.0f), 0u);
  EXPECT_EQ(colormapIndex(3.0f, 5.0f, 5.0f), 128u);  // empty range: the middle
  EXPECT_EQ(allColormapTables().size(), kColormapCount * kColormapEntries);
  EXPECT_EQ(parseColormap("coolwarm"), Colormap::CoolWarm);
  EXPECT_EQ(colormapName(Colormap::Magma), "magma");
  EXPECT_EQ(parseColorMode("scalar"), ColorMode::Scalar);
  EXPECT_EQ(parseColorMode("normal"), ColorMode::Normal);
}

}  // namespace
}  // namespace fibscope

namespace fibscope {
namespace {

TEST(Colormap, finiteRangeSkipsNanAndInfinitiesAndLeavesTheRangeWhenNoneIsFinite) {
  float lo = -7, hi = 7;
  const std::vector<float> lengths = {NAN, 42.5f, INFINITY, 20.0f, -INFINITY, 250.0f};
  EXPECT_TRUE(finiteRange(lengths, lo, hi));
  EXPECT_EQ(lo, 20.0f);
  EXPECT_EQ(hi, 250.0f);
  lo = -7, hi = 7;
  const std::vector<float> damaged = {NAN, INFINITY};
  EXPECT_FALSE(finiteRange(damaged, lo, hi));
  EXPECT_EQ(lo, -7.0f);
  EXPECT_EQ(hi, 7.0f);
  EXPECT_FALSE(finiteRange({}, lo, hi));
}

}  // namespace
}  // namespace fibscope
