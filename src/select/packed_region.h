// A region of interest in the GPU filter's form (shared/fiber_filter.h's
// FilterRegion): the floats both the CPU filter and the kept-bit passes
// test vertices against, so the two decide every vertex alike.
#pragma once

#include "select/region.h"
#include "shared/fiber_filter.h"

namespace fibscope {

// The region as the shaders read it. Spheres are float already; a box's
// double corners become the floats that compare with a float vertex as
// the doubles do (min rounded up, max rounded down); an oriented box is
// tested in float (centre, half sizes and axes rounded to nearest), on the
// CPU too (regionContains), so both sides run the same arithmetic.
// A mask region gets its grid and world -> voxel rows (the
// shared/voxel_mask.h rule, as the CPU's VoxelMask::contains) and its box;
// its voxel bits (VoxelMask::bits) go to a buffer the caller makes, whose
// address it stores in `mask`.
shader::FilterRegion packRegion(const Region& region);
// Sets r.box to [lo, hi] rounded outward (for regions packed elsewhere).
void setRegionBox(shader::FilterRegion& r, const std::array<double, 3>& lo, const std::array<double, 3>& hi);

// The float forms of an oriented box (what packRegion stores).
struct OrientedBoxFloats {
  shader::vec3 center, half_size, axes[3];
};
OrientedBoxFloats orientedBoxFloats(const OrientedBoxRegion& box);

}  // namespace fibscope
