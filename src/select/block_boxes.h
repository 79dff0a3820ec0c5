// The bounding boxes of a streamline's runs of kBlockPoints points, and of
// the whole: the per-point pass of the fiber filter. A region whose box
// misses a run's box holds none of its points, so a streamline that comes
// near a region (its whole box meets the region's) is tested point by
// point only in the runs that do, a few of its hundreds of points.
#pragma once

#include <cstddef>
#include <vector>

namespace fibscope {

struct BlockBoxes {
  static constexpr size_t kBlockPoints = 32;
  // Per run: lo x, y, z, hi x, y, z (the last run holds the n % 32 rest).
  std::vector<float> boxes;
  float lo[3], hi[3];  // of all points (+inf / -inf for none)
  size_t blocks() const { return boxes.size() / 6; }
  const float* box(size_t b) const { return boxes.data() + 6 * b; }
};

// Fills `out` for the n points (x, y, z interleaved) at xyz. A NaN
// coordinate does not widen a box (it is in no region anyway).
void computeBlockBoxes(const float* xyz, size_t n, BlockBoxes& out);

// Whether the box (lo x, y, z, hi x, y, z) meets the box `b` (same layout).
inline bool boxesMeet(const float* a, const float* b) {
  return !(a[3] < b[0] || a[0] > b[3] || a[4] < b[1] || a[1] > b[4] || a[5] < b[2] || a[2] > b[5]);
}

}  // namespace fibscope
