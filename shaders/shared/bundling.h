// GPU fiber bundling (FiberVisualizer section 7; src/bundling/gpu records
// the passes): the push constants of its passes, shared by the shaders and
// the C++ that fills them. One pass per stage:
//   resample  per fiber: its polyline at equal arc-length intervals
//   count     per sample: +1 in the voxel holding it (atomicAdd, uint)
//   density   per voxel, three times (x, y, z): a 1-D parabolic kernel
//             k(d) = 1 - d^2 / R^2 (|d| < R, d in voxels) along one axis;
//             the three together convolve with the PRODUCT kernel
//             k(dx) k(dy) k(dz), not the radial 1 - |d|^2 / R^2 (which is
//             not separable). src/bundling/bundle_reference.h's direct 3-D
//             convolution uses the same product kernel.
//   gradient  per voxel: central differences of the density (one-sided at
//             the grid's faces), world units
//   advect    per sample: p += R h (g - d (d . g)) / |g| with g the
//             trilinear gradient at p, d the fiber's unit direction there
//   smooth    per sample: p = (1 - phi) p + phi mean(p_j, |j - i| <= k)
//   relax     per sample: p = o + alpha (p - o), o its unbundled position
//   map back  per fiber: every original point moves by its sample
//             displacement interpolated at its arc length
// Grid: voxel (i, j, k) is the cube origin + h [i, i + 1) x ...; its
// centre is origin + h (i + 0.5, ...); index i + nx (j + ny k).
#ifndef FIBSCOPE_SHADERS_SHARED_BUNDLING_H
#define FIBSCOPE_SHADERS_SHARED_BUNDLING_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#include <cstddef>
#define BUNDLE_CONST inline constexpr
#else
#define BUNDLE_CONST const
#endif

SHADER_NAMESPACE_BEGIN

BUNDLE_CONST uint kBundleGroupSize = 64u;  // invocations per workgroup of every bundling pass
// A gradient shorter than this (density per mm) does not move its sample:
// its direction is noise.
BUNDLE_CONST float kBundleMinGradient = 1e-12f;

// The voxel grid, as every pass sees it (32 bytes).
struct BundleGridBlock {
  float origin_x;
  float origin_y;
  float origin_z;
  float voxel;  // mm, the side of a voxel
  uint nx;
  uint ny;
  uint nz;
  uint pad0;
};

// Resampling and mapping back (one invocation per fiber).
struct BundleFiberPush {
  uint64_t points;          // float x, y, z per original point
  uint64_t point_offsets;   // uint per fiber + 1
  uint64_t sample_offsets;  // uint per fiber + 1
  uint64_t samples;         // resample: out; map back: the bundled samples (vec4)
  uint64_t originals;       // map back: the unbundled samples (vec4)
  uint64_t moved;           // map back: float x, y, z per original point
  uint fiber_count;
  uint pad0;
  uint pad1;
  uint pad2;
};

// Counting, advection, smoothing and relaxation (one invocation per sample).
struct BundleSamplePush {
  BundleGridBlock grid;
  uint64_t src;             // vec4 per sample (w unused)
  uint64_t dst;             // vec4 per sample
  uint64_t sample_fiber;    // uint per sample: its fiber
  uint64_t sample_offsets;  // uint per fiber + 1
  uint64_t field;           // count: uint per voxel; advect: vec4 gradient per voxel; relax: the originals
  uint sample_count;
  float step;               // advect: R h (mm); smooth: phi; relax: alpha
  uint window;              // smooth: k
  uint anchor_ends;         // 1: the first and last sample of a fiber stay
};

// Density along one axis and gradient (one invocation per voxel).
struct BundleGridPush {
  BundleGridBlock grid;
  uint64_t src;       // density: uint counts (src_is_count) or float; gradient: float density
  uint64_t dst;       // float per voxel; gradient: vec4 per voxel
  uint axis;          // 0 x, 1 y, 2 z
  uint src_is_count;  // 1: src holds uint counts
  float radius;       // R in voxels
  float inv_radius2;  // 1 / R^2
};

#ifdef __cplusplus
static_assert(sizeof(BundleGridBlock) == 32);
static_assert(sizeof(BundleFiberPush) == 64);
static_assert(offsetof(BundleFiberPush, fiber_count) == 48);
static_assert(sizeof(BundleSamplePush) == 88);
static_assert(offsetof(BundleSamplePush, src) == 32);
static_assert(offsetof(BundleSamplePush, sample_count) == 72);
static_assert(sizeof(BundleGridPush) == 64);
static_assert(offsetof(BundleGridPush, axis) == 48);
#endif

// The 1-D kernel weight at integer offset d (voxels): 1 - d^2 / R^2, the
// caller keeps |d| <= floor(R) (the weight is 0 or more there).
SHADER_FN float bundleKernelWeight(float d, float inv_radius2) {
  SHADER_PRECISE float d2 = d * d;
  SHADER_PRECISE float w = 1.0f - d2 * inv_radius2;
  return max(w, 0.0f);
}

SHADER_NAMESPACE_END

#endif  // FIBSCOPE_SHADERS_SHARED_BUNDLING_H
