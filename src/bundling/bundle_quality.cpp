#include "bundling/bundle_quality.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "render/reference_raster.h"

namespace fibscope {

BundleDisplacement bundleDisplacement(const Tractogram& original, std::span<const float> moved) {
  if (moved.size() != original.positions.size()) throw Error("bundling: the moved points are not the model's");
  BundleDisplacement d;
  const size_t n = original.pointCount();
  for (size_t i = 0; i < n; ++i) {
    const double dx = double(moved[3 * i]) - original.positions[3 * i];
    const double dy = double(moved[3 * i + 1]) - original.positions[3 * i + 1];
    const double dz = double(moved[3 * i + 2]) - original.positions[3 * i + 2];
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    d.mean_mm += len;
    d.max_mm = std::max(d.max_mm, len);
  }
  if (n > 0) d.mean_mm /= double(n);
  return d;
}

Camera bundleInkCamera(const Tractogram& original, uint32_t size) {
  return standardView(tractogramBounds(original), StandardView::Coronal, size, size);
}

uint64_t bundleInk(const Tractogram& tractogram, const Camera& camera) {
  return rasterizeReference(tractogram, camera, 1.0f).coveredPixels();
}

}  // namespace fibscope
