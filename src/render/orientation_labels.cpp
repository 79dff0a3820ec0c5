#include "render/orientation_labels.h"

#include <algorithm>
#include <cmath>

namespace fibscope {
namespace {

// The label of the edge the world direction v points to.
Orientation dominant(double x, double y, double z) {
  const double c[3] = {x, y, z};
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (std::fabs(c[a]) > std::fabs(c[axis])) axis = a;
  return Orientation(2 * axis + (c[axis] > 0 ? 1 : 0));
}

Orientation opposite(Orientation o) { return Orientation(uint8_t(o) ^ 1u); }

}  // namespace

OrientationLabels orientationLabels(const Camera& camera) {
  // The view matrix's rows are the view's right, up and back axes in world
  // space (column-major: m[4 * column + row]).
  const std::array<double, 16> v = viewMatrixD(camera);
  const Orientation right = dominant(v[0], v[4], v[8]);
  const Orientation up = dominant(v[1], v[5], v[9]);
  return {opposite(right), right, up, opposite(up)};
}

char orientationLetter(Orientation o) {
  constexpr char kLetters[] = {'L', 'R', 'P', 'A', 'I', 'S'};
  return kLetters[uint8_t(o)];
}

uint32_t orientationScale(uint32_t width, uint32_t height) {
  return std::clamp<uint32_t>(std::min(width, height) / 200, 1, 4);
}

}  // namespace fibscope
