// Which anatomical direction each image edge shows (mrview's orientation
// labels), for the orientation overlay (shaders/shared/orientation_overlay.h)
// and its tests.
#pragma once

#include <cstdint>

#include "render/camera.h"

namespace fibscope {

// Glyphs of shared/orientation_overlay.h: 2 * axis + (1 when positive).
enum class Orientation : uint8_t { L = 0, R = 1, P = 2, A = 3, I = 4, S = 5 };

struct OrientationLabels {
  Orientation left, right, top, bottom;
};

// For the right edge: the world axis with the largest |component| of the
// view's right vector (ties: x before y before z), R/A/S where that
// component is positive, else L/P/I; the left edge the opposite; the top
// and bottom the same for the view's up vector. The camera must be valid
// (validateCamera).
OrientationLabels orientationLabels(const Camera& camera);

char orientationLetter(Orientation o);

// The overlay's scale s (shared/orientation_overlay.h): min(width, height)
// / 200, clamped to 1 .. 4.
uint32_t orientationScale(uint32_t width, uint32_t height);

}  // namespace fibscope
