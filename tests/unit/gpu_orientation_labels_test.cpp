// The orientation overlay in `fibscope render`'s PNGs, as a user reads it:
// seen from above with anterior up (the axial standard view) the glyph of
// L is at the left edge, R at the right, A at the top, P at the bottom, each
// matching the glyph bitmap cell for cell; seen from below, L and R swap;
// the triad's red axis (x, R) points right from above and left from below,
// the green one (y, A) up. --no-orientation-labels draws none of it; and
// `render --anatomy` draws a volume's slices under the phantom.
// Validation layers on. Skipped without a Vulkan device.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "render/orientation_labels.h"
#include "shared/orientation_overlay.h"
#include "test_support.h"

namespace fibscope {
namespace {

test::CommandResult runGpuFibscope(const std::string& args) {
  return test::runCommand(std::string(FIBSCOPE_EXE) + " " + args);
}

uint32_t rgbaAt(const test::Png& png, int x, int y) {
  const uint8_t* p = png.at(uint32_t(x), uint32_t(y));
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// Whether glyph g (shared/orientation_overlay.h's bitmap) is in the image
// with its top-left cell at (x0, y0) and cells of s x s pixels: every pixel
// of a set cell in the label colour, none of an unset cell.
bool glyphAt(const test::Png& png, uint32_t g, int x0, int y0, int s) {
  if (x0 < 0 || y0 < 0 || x0 + 5 * s > int(png.width) || y0 + 7 * s > int(png.height)) return false;
  for (int cy = 0; cy < 7; ++cy)
    for (int cx = 0; cx < 5; ++cx) {
      const bool set = (shader::kOrientationGlyphRows[7 * g + uint32_t(cy)] >> (4 - cx)) & 1u;
      for (int py = 0; py < s; ++py)
        for (int px = 0; px < s; ++px)
          if ((rgbaAt(png, x0 + cx * s + px, y0 + cy * s + py) == shader::kOrientationLabelColor) != set) return false;
    }
  return true;
}

// The letters found anywhere in [x0, x1) x [y0, y1) (their top-left
// corner), at any scale.
std::string lettersIn(const test::Png& png, int x0, int x1, int y0, int y1) {
  std::string found;
  for (uint32_t g = 0; g < shader::kOrientationGlyphs; ++g)
    for (int s = 1; s <= 4; ++s)
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
          if (glyphAt(png, g, x, y, s)) found += orientationLetter(Orientation(g));
  return found;
}

// Left, right, top and bottom edges' letters: the bands along the middle
// of each edge (the triad's corner left out).
std::string edgeLetters(const test::Png& png) {
  const int w = int(png.width), h = int(png.height);
  return lettersIn(png, 0, w / 4, h / 4, 3 * h / 4) + "," + lettersIn(png, 3 * w / 4, w, h / 4, 3 * h / 4) + "," +
         lettersIn(png, w / 4, 3 * w / 4, 0, h / 4) + "," + lettersIn(png, w / 4, 3 * w / 4, 3 * h / 4, h);
}

class GpuOrientationLabels : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = runGpuFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
  test::Png render(const std::string& options) {
    const std::string png = dir_.file("labels.png");
    const auto r = runGpuFibscope("render --validate --phantom-streamlines 200 --size 320x240 " + options + " -o " + png);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return test::readOurPng(png);
  }
  test::TempDir dir_;
};

TEST_F(GpuOrientationLabels, fromAboveLeftIsOnTheLeftAndFromBelowLeftAndRightSwap) {
  const test::Png above = render("--view axial");
  ASSERT_EQ(above.width, 320u);
  EXPECT_EQ(edgeLetters(above), "L,R,A,P");
  // Elevation -90: the eye below the head, anterior still up.
  const test::Png below = render("--camera 90,-90,0");
  EXPECT_EQ(edgeLetters(below), "R,L,A,P");
  const test::Png none = render("--view axial --no-orientation-labels");
  EXPECT_EQ(edgeLetters(none), ",,,");
}

TEST_F(GpuOrientationLabels, theTriadsRedAxisPointsToTheSubjectsRight) {
  // shared/orientation_overlay.h's layout at scale 1 (320 x 240).
  const int s = int(orientationScale(320, 240)), m = 4 * s;
  const int cx = 320 - m - 13 * s, cy = 240 - m - 13 * s;
  const test::Png above = render("--view axial");
  EXPECT_EQ(rgbaAt(above, cx + 8 * s, cy), shader::kOrientationAxisXColor);
  EXPECT_EQ(rgbaAt(above, cx, cy - 8 * s), shader::kOrientationAxisYColor);
  EXPECT_EQ(rgbaAt(above, cx, cy), shader::kOrientationAxisZColor);  // towards the viewer: on top, a dot
  EXPECT_NE(rgbaAt(above, cx - 8 * s, cy), shader::kOrientationAxisXColor);
  const test::Png below = render("--camera 90,-90,0");
  EXPECT_EQ(rgbaAt(below, cx - 8 * s, cy), shader::kOrientationAxisXColor);
  EXPECT_EQ(rgbaAt(below, cx, cy - 8 * s), shader::kOrientationAxisYColor);
  EXPECT_NE(rgbaAt(below, cx + 8 * s, cy), shader::kOrientationAxisXColor);
}

TEST_F(GpuOrientationLabels, renderDrawsAnAnatomyUnderThePhantom) {
  const std::string python = test::pythonWithNibabel();
  if (python.empty()) GTEST_SKIP() << "needs /usr/bin/python3 with nibabel and numpy";
  const std::string head = dir_.file("head.nii.gz");
  const auto made = test::runCommand(python + " " + test::toolPath("anatomy_make.py") + " head " + head);
  ASSERT_EQ(made.exit_code, 0) << made.output;
  // Only the axial slice, a slab of 10 mm about it: grey around the fibers.
  const test::Png png = render("--view axial --no-ssao --anatomy " + head +
                               " --no-show-slice-i --no-show-slice-j --slab 10 --slab-follows-slice");
  size_t grey = 0, coloured = 0;
  for (uint32_t y = 0; y < png.height; ++y)
    for (uint32_t x = 0; x < png.width; ++x) {
      const uint8_t* p = png.at(x, y);
      if (p[0] == p[1] && p[1] == p[2] && p[0] > 60) ++grey;
      else if (p[0] != p[1] || p[1] != p[2]) ++coloured;
    }
  EXPECT_GT(grey, size_t(png.width) * png.height / 5) << "the slice covers much of the view";
  EXPECT_GT(coloured, 500u) << "fibers in the slab over it";
  const test::Png off = render("--view axial --no-ssao --anatomy " + head + " --anatomy-opacity 0");
  size_t grey_off = 0;
  for (uint32_t y = 0; y < off.height; ++y)
    for (uint32_t x = 0; x < off.width; ++x) {
      const uint8_t* p = off.at(x, y);
      grey_off += p[0] == p[1] && p[1] == p[2] && p[0] > 60;
    }
  EXPECT_LT(grey_off, grey / 10);
}

}  // namespace
}  // namespace fibscope
