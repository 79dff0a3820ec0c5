#include <gtest/gtest.h>

#include "app/viewer/viewer_window.h"

namespace fibscope {
namespace {

TEST(ViewerWindow, cursorPositionsScaleToFramebufferPixelsOnHighDpiDisplays) {
  // A 2x display: 800 x 600 screen coordinates, 1600 x 1200 pixels.
  double x = 400.5, y = 10;
  screenToFramebuffer(x, y, 800, 600, 1600, 1200);
  EXPECT_DOUBLE_EQ(x, 801.0);
  EXPECT_DOUBLE_EQ(y, 20.0);
  // Fractional scales per axis (1.5 x 1.25).
  x = 100, y = 100;
  screenToFramebuffer(x, y, 800, 800, 1200, 1000);
  EXPECT_DOUBLE_EQ(x, 150.0);
  EXPECT_DOUBLE_EQ(y, 125.0);
  // The usual display: unchanged.
  x = 123.25, y = 45.5;
  screenToFramebuffer(x, y, 640, 480, 640, 480);
  EXPECT_DOUBLE_EQ(x, 123.25);
  EXPECT_DOUBLE_EQ(y, 45.5);
}

TEST(ViewerWindow, aMinimisedWindowLeavesCursorPositionsUnscaled) {
  double x = 10, y = 20;
  screenToFramebuffer(x, y, 800, 600, 0, 0);
  EXPECT_DOUBLE_EQ(x, 10.0);
  EXPECT_DOUBLE_EQ(y, 20.0);
  screenToFramebuffer(x, y, 0, 0, 800, 600);
  EXPECT_DOUBLE_EQ(x, 10.0);
  EXPECT_DOUBLE_EQ(y, 20.0);
}

}  // namespace
}  // namespace fibscope
