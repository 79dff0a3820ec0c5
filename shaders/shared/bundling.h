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
//   splat     (anisotropic mode, instead of count and density) per sample:
//             adds K(q) = 1 - (q.d)^2 / Ra^2 - |q - d (q.d)|^2 / Rb^2 (>= 0)
//             at every voxel centre q (voxels from the sample) to the
//             density, d the fiber's direction at the sample, Ra = R along
//             it, Rb = anisotropy R across (an ellipsoid elongated along
//             the fiber); fixed point (kBundleSplatScale per unit) so the
//             integer atomics keep bundling deterministic
//   gradient  central differences of the density (one-sided at the grid's
//             faces), world units: taken by the advection at the 8 voxels
//             around each sample (glsl/bundling.glsl), so no gradient grid
//             is kept; the gradient pass writes that grid only for the
//             tests (GpuBundlerOptions::keep_stages)
//   structure (structure-aware advection, after the density) per cell of
//             `cell` voxels a side: the cell's mean density; then per cell
//             the tensor J = mean of G G^T over the cell and its up to 26
//             neighbours, G the cell means' central differences (6 floats a
//             cell: xx xy xz yy yz zz; bundling/bundle_reference.h)
//   advect    per sample: p += R h (g - d (d . g)) / |g| with g the
//             trilinear gradient at p, d the fiber's unit direction there;
//             structure-aware: g in the numerator becomes M g, M = (J /
//             lambda1)^power, J trilinear between cell centres
//   smooth    per sample: p = (1 - phi) p + phi mean(p_j, |j - i| <= k)
//   relax     per sample: p = o + alpha (p - o), o its unbundled position
//   map back  per fiber: every original point moves by its sample
//             displacement interpolated at its arc length, in place
// Resampling and mapping back see the model's points a chunk of whole
// fibers at a time (fiber_first, point_base), so the input points are not
// on the device during the iterations.
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
// Splatted density units per kernel unit (the splat's integer atomics).
BUNDLE_CONST float kBundleSplatScale = 256.0f;

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

// Resampling and mapping back (one invocation per fiber of a chunk).
struct BundleFiberPush {
  uint64_t points;          // float x, y, z per point of the chunk (point_offsets[f] - point_base)
  uint64_t point_offsets;   // uint per fiber + 1 (the whole model's)
  uint64_t sample_offsets;  // uint per fiber + 1
  uint64_t samples;         // resample: out; map back: the bundled samples (vec4)
  uint64_t originals;       // map back: the unbundled samples (vec4)
  uint64_t moved;           // map back: float x, y, z per point of the chunk (may be `points`)
  uint fiber_count;         // fibers in the chunk
  uint fiber_first;         // the chunk's first fiber
  uint point_base;          // point_offsets[fiber_first]: the chunk's first point
  uint pad0;
};

// Counting, advection, smoothing and relaxation (one invocation per sample).
struct BundleSamplePush {
  BundleGridBlock grid;
  uint64_t src;             // vec4 per sample (w unused)
  uint64_t dst;             // vec4 per sample
  uint64_t sample_fiber;    // uint per sample: its fiber
  uint64_t sample_offsets;  // uint per fiber + 1
  uint64_t field;           // count: uint per voxel; advect: the density per voxel; relax: the originals
  uint sample_count;
  float step;               // advect: R h (mm); smooth: phi; relax: alpha
  uint window;              // smooth: k
  uint anchor_ends;         // 1: the first and last sample of a fiber stay
  float radius_along;       // splat: Ra (voxels)
  float radius_across;      // splat: Rb (voxels)
  uint field_is_count;      // advect: 1 when the density is the splat's fixed point (uint)
  float field_scale;        // advect: field_is_count's uint values times this
  uint64_t structure;       // advect: 6 floats per cell, 0 for the plain advection
  uint structure_cell;      // advect: voxels a side of a cell (its grid: bundleStructureCells)
  uint structure_power;     // advect: the filter's power
};

// Density along one axis and gradient (one invocation per voxel).
struct BundleGridPush {
  BundleGridBlock grid;
  uint64_t src;       // density: uint counts (src_is_count) or float; gradient: the density
  uint64_t dst;       // float per voxel (the y pass may write into the counts); gradient: vec4 per voxel
  uint axis;          // 0 x, 1 y, 2 z
  uint src_is_count;  // 1: src holds uint counts
  float radius;       // R in voxels
  float inv_radius2;  // 1 / R^2
  float src_scale;    // gradient, structure mean: src_is_count's uint values times this
  uint cell;          // structure mean: voxels a side of a cell
};

#ifdef __cplusplus
static_assert(sizeof(BundleGridBlock) == 32);
static_assert(sizeof(BundleFiberPush) == 64);
static_assert(offsetof(BundleFiberPush, fiber_count) == 48);
static_assert(sizeof(BundleSamplePush) == 120);
static_assert(offsetof(BundleSamplePush, structure) == 104);
static_assert(offsetof(BundleSamplePush, src) == 32);
static_assert(offsetof(BundleSamplePush, sample_count) == 72);
static_assert(sizeof(BundleGridPush) == 72);
static_assert(offsetof(BundleGridPush, axis) == 48);
#endif

// The 1-D kernel weight at integer offset d (voxels): 1 - d^2 / R^2, the
// caller keeps |d| <= floor(R) (the weight is 0 or more there).
SHADER_FN float bundleKernelWeight(float d, float inv_radius2) {
  SHADER_PRECISE float d2 = d * d;
  SHADER_PRECISE float w = 1.0f - d2 * inv_radius2;
  return max(w, 0.0f);
}

// The anisotropic splat's kernel at offset q (voxels) from a sample whose
// fiber runs along unit d (0: isotropic with Rb), times kBundleSplatScale
// and rounded: the integer the splat adds.
SHADER_FN uint bundleSplatWeight(vec3 q, vec3 d, float inv_along2, float inv_across2) {
  SHADER_PRECISE float a = (q.x * d.x + q.y * d.y) + q.z * d.z;
  SHADER_PRECISE float q2 = (q.x * q.x + q.y * q.y) + q.z * q.z;
  SHADER_PRECISE float b2 = max(q2 - a * a, 0.0f);
  SHADER_PRECISE float k = (1.0f - a * a * inv_along2) - b2 * inv_across2;
  if (!(k > 0.0f)) return 0u;
  SHADER_PRECISE float scaled = k * kBundleSplatScale + 0.5f;
  return uint(floor(scaled));
}

SHADER_NAMESPACE_END

#endif  // FIBSCOPE_SHADERS_SHARED_BUNDLING_H
