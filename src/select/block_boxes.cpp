#include "select/block_boxes.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace fibscope {
namespace {

// The box of n points by a running min and max per coordinate.
void scalarBox(const float* xyz, size_t n, float* box) {
  float l[3] = {INFINITY, INFINITY, INFINITY}, h[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      const float v = xyz[3 * i + k];
      l[k] = v < l[k] ? v : l[k];
      h[k] = v > h[k] ? v : h[k];
    }
  for (int k = 0; k < 3; ++k) box[k] = l[k], box[3 + k] = h[k];
}

// The box of one run of kBlockPoints points. Its coordinates are read as
// groups of 4 points, 12 floats in 3 vectors whose lanes hold x y z x | y z
// x y | z x y z; the minimum of each lane position is kept and the lanes
// of each coordinate are folded at the end. (A loop per point with its x, y
// and z did not vectorise: it ran a scalar min per coordinate.)
void blockBox(const float* xyz, float* box) {
#if defined(__SSE2__)
  __m128 l0 = _mm_set1_ps(INFINITY), l1 = l0, l2 = l0;
  __m128 h0 = _mm_set1_ps(-INFINITY), h1 = h0, h2 = h0;
  for (size_t g = 0; g < BlockBoxes::kBlockPoints / 4; ++g) {
    const float* p = xyz + 12 * g;
    // minps(a, b) gives b when a is NaN: the running value stays.
    l0 = _mm_min_ps(_mm_loadu_ps(p), l0), h0 = _mm_max_ps(_mm_loadu_ps(p), h0);
    l1 = _mm_min_ps(_mm_loadu_ps(p + 4), l1), h1 = _mm_max_ps(_mm_loadu_ps(p + 4), h1);
    l2 = _mm_min_ps(_mm_loadu_ps(p + 8), l2), h2 = _mm_max_ps(_mm_loadu_ps(p + 8), h2);
  }
  float l[12], h[12];
  _mm_storeu_ps(l, l0), _mm_storeu_ps(l + 4, l1), _mm_storeu_ps(l + 8, l2);
  _mm_storeu_ps(h, h0), _mm_storeu_ps(h + 4, h1), _mm_storeu_ps(h + 8, h2);
  for (int k = 0; k < 3; ++k) {
    box[k] = std::min({l[k], l[k + 3], l[k + 6], l[k + 9]});
    box[3 + k] = std::max({h[k], h[k + 3], h[k + 6], h[k + 9]});
  }
#else
  scalarBox(xyz, BlockBoxes::kBlockPoints, box);
#endif
}

}  // namespace

void computeBlockBoxes(const float* xyz, size_t n, BlockBoxes& out) {
  constexpr size_t B = BlockBoxes::kBlockPoints;
  const size_t whole = n / B, blocks = (n + B - 1) / B;
  out.boxes.resize(6 * blocks);
  for (size_t b = 0; b < whole; ++b) blockBox(xyz + 3 * B * b, out.boxes.data() + 6 * b);
  if (blocks > whole) scalarBox(xyz + 3 * B * whole, n - B * whole, out.boxes.data() + 6 * whole);
  for (int k = 0; k < 3; ++k) out.lo[k] = INFINITY, out.hi[k] = -INFINITY;
  for (size_t b = 0; b < blocks; ++b) {
    const float* box = out.box(b);
    for (int k = 0; k < 3; ++k) {
      out.lo[k] = std::min(out.lo[k], box[k]);
      out.hi[k] = std::max(out.hi[k], box[3 + k]);
    }
  }
}

}  // namespace fibscope
