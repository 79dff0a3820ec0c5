// Quality figures of a bundling run (issue 17 item 1): how far the points
// moved from their original positions, and the ink (pixels covered by the
// fibers in a fixed view, the CPU reference rasteriser's coverage) before
// and after: bundling should lower the ink while moving points little.
#pragma once

#include <cstdint>
#include <span>

#include "core/tractogram.h"
#include "render/camera.h"

namespace fibscope {

struct BundleDisplacement {
  double mean_mm = 0;
  double max_mm = 0;
};
// Over every point; `moved` holds x y z per point of `original`.
BundleDisplacement bundleDisplacement(const Tractogram& original, std::span<const float> moved);

// The fixed view of the ink: the coronal standard view of the original's
// bounding box, `size` x `size` px (the same camera before and after).
Camera bundleInkCamera(const Tractogram& original, uint32_t size = 512);
// Pixels covered by `tractogram`'s 1 px lines seen by `camera`.
uint64_t bundleInk(const Tractogram& tractogram, const Camera& camera);

}  // namespace fibscope
