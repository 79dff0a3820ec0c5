// Which letter each image edge shows (render/orientation_labels.h), for
// views whose anatomy is known from the camera conventions (camera.h), and
// the overlay's scale. No GPU.
#include <gtest/gtest.h>

#include <string>

#include "render/camera.h"
#include "render/orientation_labels.h"

namespace fibscope {
namespace {

Bounds headBox() {
  Bounds b;
  b.min = {-70, -85, -60};
  b.max = {70, 85, 60};
  return b;
}

std::string letters(const OrientationLabels& l) {
  return {orientationLetter(l.left), orientationLetter(l.right), orientationLetter(l.top), orientationLetter(l.bottom)};
}

TEST(OrientationLabels, eachEdgeShowsTheAnatomicalDirectionThatLiesThatWay) {
  // Left, right, top, bottom, from what the views show (camera.h):
  // axial from above, anterior up: the subject's right on the right.
  EXPECT_EQ(letters(orientationLabels(standardView(headBox(), StandardView::Axial, 64, 48))), "LRAP");
  // Coronal, facing the subject: its right on the image's left.
  EXPECT_EQ(letters(orientationLabels(standardView(headBox(), StandardView::Coronal, 64, 48))), "RLSI");
  // Sagittal from the right: anterior to the right.
  EXPECT_EQ(letters(orientationLabels(standardView(headBox(), StandardView::Sagittal, 64, 48))), "PASI");
  // Axial from below, anterior up (radiological): right and left swap.
  EXPECT_EQ(letters(orientationLabels(orbitCamera(headBox(), 90, -90, 64, 48))), "RLAP");
  // Oblique: the nearest axis wins (looking from front-left-above).
  EXPECT_EQ(letters(orientationLabels(orbitCamera(headBox(), 125, 20, 64, 48))), "RLSI");
}

TEST(OrientationLabels, theOverlayScalesWithTheImage) {
  EXPECT_EQ(orientationScale(160, 120), 1u);
  EXPECT_EQ(orientationScale(640, 480), 2u);
  EXPECT_EQ(orientationScale(1920, 1080), 4u);
}

}  // namespace
}  // namespace fibscope
