// The split view's camera arithmetic (split_view.h) and the box helpers it
// uses (render/camera.h), against values worked out by hand; the GPU test
// (gpu_viewer_bundling_test.cpp) checks the pictures.
#include <gtest/gtest.h>

#include <cmath>

#include "app/viewer/split_view.h"

namespace fibscope {
namespace {

TEST(SplitView, boxHelpersGiveTheUnionItsCornersAndHalfTheDiagonal) {
  const Bounds a{{0, 0, 0}, {2, 4, 6}}, b{{-1, 1, 1}, {1, 5, 3}};
  const Bounds u = boundsUnion(a, b);
  EXPECT_EQ(u.min, (Vec3d{-1, 0, 0}));
  EXPECT_EQ(u.max, (Vec3d{2, 5, 6}));
  const auto corners = boundsCorners(a);
  EXPECT_EQ(corners[0], (Vec3d{0, 0, 0}));
  EXPECT_EQ(corners[5], (Vec3d{2, 0, 6}));  // bits 0 and 2: max x, max z
  EXPECT_EQ(corners[7], (Vec3d{2, 4, 6}));
  EXPECT_DOUBLE_EQ(boundingRadius(a), std::sqrt(4.0 + 16 + 36) / 2);
  EXPECT_DOUBLE_EQ(boundingRadius(Bounds{{1, 1, 1}, {1.5, 1, 1}}), 1.0) << "1 mm at least";
}

TEST(SplitView, distanceFactorIsTwiceTheRatioOfTheShownToTheFramedSphereAndNeverBelowTwo) {
  const Bounds framed{{-10, -10, -10}, {10, 10, 10}};
  EXPECT_DOUBLE_EQ(splitDistanceFactor(framed, framed), 2.0);
  EXPECT_DOUBLE_EQ(splitDistanceFactor(framed, Bounds{{-20, -20, -20}, {20, 20, 20}}), 4.0);
  EXPECT_DOUBLE_EQ(splitDistanceFactor(framed, Bounds{{-5, -5, -5}, {5, 5, 5}}), 2.0) << "smaller: kept at 2";
  const Bounds broken{{0, 0, 0}, {NAN, 0, 0}};
  EXPECT_DOUBLE_EQ(splitDistanceFactor(framed, broken), 2.0);
}

TEST(SplitView, halfCameraMovesTheEyeBackAndItsPlanesEncloseTheShownBox) {
  Camera c;
  c.eye = {0, 0, 100}, c.target = {0, 0, 0}, c.near_mm = 90, c.far_mm = 110, c.width = 101, c.height = 50;
  const Bounds shown{{-30, -30, -30}, {30, 30, 30}};
  const Camera left = splitHalfCamera(c, false, 3.0, shown), right = splitHalfCamera(c, true, 3.0, shown);
  EXPECT_EQ(left.width, 50u);
  EXPECT_EQ(right.width, 51u);
  EXPECT_EQ(left.eye, (Vec3d{0, 0, 300}));
  EXPECT_EQ(left.target, c.target);
  // The full camera's planes 200 mm farther (290, 310), widened to the
  // shown box's depths 270-330 with 1 % margins.
  EXPECT_DOUBLE_EQ(left.near_mm, 0.99 * 270);
  EXPECT_DOUBLE_EQ(left.far_mm, 1.01 * 330);
  EXPECT_DOUBLE_EQ(right.near_mm, left.near_mm);
}

}  // namespace
}  // namespace fibscope
