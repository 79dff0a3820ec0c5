// Limits, workgroup sizes and the visibility-key layout of the render
// passes (DESIGN.md section 6), shared by the C++ that records the passes
// and the shaders.
//
// Visibility key (64 bits, one per pixel, atomicMin wins):
//   bits 63..34  depth: the float bits of the clip depth d = z/w in [0, 1].
//                Non-negative floats order like their bit patterns, and
//                floatBitsToUint(1.0) = 0x3F800000 < 2^30, so the depth fits
//                in 30 bits WITHOUT rounding: nearer is smaller.
//   bits 33..0   payload, 34 bits, pipeline-specific:
//                compute:     fiblet << 6 | segment within the fiblet,
//                             the fiblet numbered over every dataset of the
//                             frame (shared/scene_table.h: the models drawn
//                             together share the 2^28 = 268 M fiblets; 64
//                             segments: the paper's 10 M fibers / 140 M
//                             fiblets fit);
//                raw-compute: the global index of the segment's first point
//                             (2^34 = 17 G points; the paper's largest is 8.1 G).
//   kEmptyKey (all ones) is larger than every drawn key.
// Equal depths resolve to the smaller payload; fiblets are stored in fiber
// order and points in order within a fiblet (and datasets follow each other
// in the scene's numbering), so that is the smaller (fiber, point) pair, as
// in the CPU reference (src/render/reference_raster.h) of the datasets'
// union.
#ifndef FIBSCOPE_SHADERS_SHARED_RENDER_CONFIG_H
#define FIBSCOPE_SHADERS_SHARED_RENDER_CONFIG_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define RENDER_CONST inline constexpr
#else
#define RENDER_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// One workgroup per fiblet, one invocation per point (kFibletMaxPoints = 60
// <= 64); the scan works for any subgroup size (shared memory + barriers).
RENDER_CONST uint kRasterGroupSize = 64u;
// Segments per workgroup in the raw-compute raster.
RENDER_CONST uint kRawRasterGroupSize = 64u;
// Fiblets per workgroup in the cull passes (and the bounds pass).
RENDER_CONST uint kCullGroupSize = 64u;
// Fiblets per workgroup of the far-view LoD raster (one segment each); the
// LoD list is finalised for this many items a group.
RENDER_CONST uint kLodRasterGroupSize = 64u;
// Per-pixel passes (clear, resolve, shade) run in 8 x 8 tiles.
RENDER_CONST uint kPixelGroupSize = 8u;

RENDER_CONST uint kKeyPayloadBits = 34u;
RENDER_CONST uint kKeySegmentBits = 6u;  // compute payload: segment within the fiblet
RENDER_CONST uint kMaxFiblets = 268435456u;  // 2^(34 - 6)

// The largest line width in pixels (the CPU reference's kMaxLineWidth).
RENDER_CONST float kMaxLineWidthPx = 4.0f;

// Marks an empty G-buffer texel (fiber field) and "no fiber" elsewhere.
RENDER_CONST uint kNoFiberId = 0xFFFFFFFFu;
// The fiber field of a drawn pixel that belongs to no fiber (an anatomical
// slice): covered for shading and AO, no fiber for picking and attributes.
RENDER_CONST uint kNoFiberObject = 0xFFFFFFFEu;

// Tiles of kPixelGroupSize pixels covering `pixels` along one axis: the
// workgroups of a per-pixel pass.
SHADER_FN uint pixelGroups(uint pixels) { return (pixels + kPixelGroupSize - 1u) / kPixelGroupSize; }

SHADER_FN uint64_t visibilityKey(float depth, uint64_t payload) {
  return (uint64_t(floatBitsToUint(depth)) << kKeyPayloadBits) | payload;
}
SHADER_FN float visibilityDepth(uint64_t key) { return uintBitsToFloat(uint(key >> kKeyPayloadBits)); }
SHADER_FN uint64_t visibilityPayload(uint64_t key) { return key & ((uint64_t(1) << kKeyPayloadBits) - uint64_t(1)); }

// The visibility buffer stores its keys in blocks of 4 x 2 pixels, one
// 64-byte cache line each (blocks row by row): a line drawn through it
// touches a third fewer cache lines than in rows of pixels, whichever way
// it runs (a 2 x 2 candidate block of a short segment often lies in one),
// which measured 5 % of the raster on lavapipe. Width padded to a multiple
// of 4, height to a multiple of 2 (visibilityKeyCount).
SHADER_FN uint visibilityIndex(uint x, uint y, uint width) {
  return ((y >> 1u) * ((width + 3u) >> 2u) + (x >> 2u)) * 8u + (y & 1u) * 4u + (x & 3u);
}
SHADER_FN uint visibilityKeyCount(uint width, uint height) { return ((width + 3u) & ~3u) * ((height + 1u) & ~1u); }

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(0x3F800000u < (1u << 30), "depth in [0, 1] fits in 30 bits");
static_assert(fibscope::shader::kMaxFiblets == (1u << (34 - 6)), "fiblet index bits");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_RENDER_CONFIG_H
