// Push constants and shared arithmetic of the cull passes of the compute
// pipeline (DESIGN.md section 6, step 1): fiblet_cull.comp,
// fiblet_list_finalize.comp, depth_pyramid.comp and fiblet_lod_raster.comp.
//
// Two-phase occlusion culling (conservative; no visible fiblet is culled):
//   phase 1  fiblets visible last frame and inside the dilated frustum are
//            drawn;
//   pyramid  a max-depth mip chain of the visibility buffer after phase 1;
//   phase 2  every fiblet inside the frustum is tested against the pyramid
//            (its bounding sphere's nearest depth against the farthest depth
//            over its screen rectangle), its "visible" bit is rewritten, and
//            those not drawn in phase 1 and not occluded are drawn.
// A fiblet culled in phase 2 is behind depths already in the visibility
// buffer at every pixel it could cover, and the buffer only gets nearer, so
// its keys would lose every atomicMin: the final visibility buffer is the
// one drawing every fiblet gives, bit for bit.
#ifndef FIBSCOPE_SHADERS_SHARED_CULL_PUSH_H
#define FIBSCOPE_SHADERS_SHARED_CULL_PUSH_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define CULL_CONST inline constexpr
#else
#define CULL_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// FibletCullPush::mode.
CULL_CONST uint kCullFrustum = 0u;  // dilated frustum + LoD, no occlusion (CullingMode::Frustum)
CULL_CONST uint kCullPhase1 = 1u;   // ... restricted to fiblets whose visible bit is set
CULL_CONST uint kCullPhase2 = 2u;   // ... + pyramid test, rewrites the visible bits, skips phase-1 fiblets
// Every fiblet of a kept fiber to the full list, no frustum or LoD
// (CullingMode::None while a fiber filter is on). Every mode skips the
// fiblets of fibers the filter dropped (FibletCullPush::kept).
CULL_CONST uint kCullKeptOnly = 3u;
// The paper's coverage buffer (CullingMode::Coverage, shared/coverage_push.h):
// Frustum + the pyramid test against the re-projected previous frame, in
// one pass: no visible bits, and NOT conservative (a fiblet the last frame
// hid and this one uncovers may be culled).
CULL_CONST uint kCullCoverage = 4u;

// The largest pyramid: 16384 px per side (createFrameTargets' limit) has 15
// levels.
CULL_CONST uint kPyramidMaxLevels = 16u;

// Slack of the conservative tests, on top of exact bounds: the bounding
// sphere's radius is scaled by (1 + kCullRadiusSlack); screen rectangles
// and the dilated frustum get kCullPixelSlack extra pixels on every side;
// an occluder must be kCullDepthSlack nearer than the sphere's nearest
// depth. They absorb the float rounding by which the raster's projection of
// a point can differ from the cull pass's.
CULL_CONST float kCullRadiusSlack = 1.0e-3f;
CULL_CONST float kCullPixelSlack = 1.0f;
CULL_CONST float kCullDepthSlack = 1.0e-5f;

// Absolute slack of the precomputed fiblet spheres (fiblet_bounds.comp), as
// a fraction of the dataset's reach: mm_per_unit (the normalised cube's
// side) plus the largest |translation| component. The bounds pass decodes
// serially; the parallel-prefix rasters compose the same transforms in
// another order, so their points differ from the bounds pass's by float
// rounding. Each composition rounds the translation (|t| <= sqrt(3) in
// normalised units) by a few ulps, about 8e-7; over at most 59
// compositions that is 5e-5 even if every rounding went the same way
// (fiblet_decode_test.cpp holds both orders within 2e-6 of a double
// reference, in normalised units, on random records; the rotations' rounding moves points by a relative
// amount of the distance travelled, which kCullRadiusSlack covers). The
// world transform rounds each coordinate by an ulp of its magnitude, 1e-7
// of the reach. 1e-4 is twice the worst case of both, and still only
// 0.02 mm of a 200 mm brain: nothing next to a line's width.
CULL_CONST float kCullBoundsSlack = 1.0e-4f;

// fiblet_cull.comp: one invocation per fiblet (kCullGroupSize per group).
struct FibletCullPush {
  uint64_t dataset;   // FibletDataset block
  uint64_t camera;    // CameraBlock
  uint64_t list;      // FibletList: fiblets drawn at full detail
  uint64_t lod_list;  // FibletList: fiblets drawn as one segment (LoD)
  // uint per 32 fiblets: bit set = visible last frame (kCullPhase1/2). The
  // dataset's own region of the scene's bits (CullBuffers::visible at its
  // word offset, a whole number of kCullGroupSize groups), so a workgroup
  // still owns its two words when several datasets share the buffer.
  uint64_t visible;
  uint64_t pyramid;   // float, every level of the max-depth pyramid (kCullPhase2, kCullCoverage)
  // The fiber filter's kept bits over the scene's fibers
  // (select/gpu/gpu_fiber_filter.h), or 0: every fiber kept. The dataset's
  // fiber f is the scene's fiber_base + f.
  uint64_t kept;
  uint mode;          // kCull*
  float lod_pixels;   // LoD below this projected diameter in px; 0: off
  float focal_px;     // projection scale in px: |P[1][1]| * height / 2
  uint fiber_base;
};

// fiblet_bounds.comp: one invocation per fiblet (kCullGroupSize per group)
// writes FibletDataset::fiblet_bounds.
struct FibletBoundsPush {
  uint64_t dataset;  // FibletDataset block (its fiblet_bounds may still be 0)
  uint64_t bounds;   // vec4 per fiblet: world centre, radius (< 0: draws nothing)
};

// A precomputed sphere's radius from the exact largest distance (world mm)
// of the serially decoded points to the centre: enlarged for the rounding
// by which the rasters' decode orders and their world transform differ
// (kCullRadiusSlack relative, kCullBoundsSlack of `reach_mm` = mm_per_unit
// + the largest |translation| component).
SHADER_FN float fibletBoundsRadius(float farthest_mm, float reach_mm) {
  return farthest_mm * (1.0f + kCullRadiusSlack) + kCullBoundsSlack * reach_mm;
}

// fiblet_list_finalize.comp: one invocation turns a list's count into its
// indirect dispatch size.
struct FibletListFinalizePush {
  uint64_t list;
  uint items_per_group;  // the fiblet raster: FibletPasses::raster_fiblets_per_group; 64: the LoD raster
  uint max_groups_x;     // maxComputeWorkGroupCount[0]
};

// depth_pyramid.comp: one dispatch per level.
struct DepthPyramidPush {
  uint64_t visibility;  // level 0 reads the visibility keys ...
  // ... or, when not 0, the G-buffer's depths (GBufferTexel per pixel): the
  // graphics fiblet pipelines, which write no visibility keys
  uint64_t gbuffer;
  uint64_t pyramid;
  uint width;  // level 0 = the frame size
  uint height;
  uint level;
  uint pad;
};

// fiblet_lod_raster.comp: one invocation per LoD fiblet.
struct FibletLodRasterPush {
  uint64_t dataset;
  uint64_t camera;
  uint64_t visibility;
  uint64_t list;
  uint64_t tangents;  // 0 or the tangent cache (render_push.h): segment 0's entry
  uint fiblet_base;   // as FibletRasterPush::fiblet_base
  uint pad;
};

// Size of pyramid level `level` of a width x height frame: level 0 is the
// frame, each next level ceil(previous / 2), down to 1 x 1.
SHADER_FN uint pyramidLevelSize(uint size, uint level) {
  uint s = size;
  for (uint i = 0u; i < level; ++i) s = (s + 1u) >> 1u;
  return s;
}
// Levels down to 1 x 1 inclusive.
SHADER_FN uint pyramidLevelCount(uint width, uint height) {
  uint levels = 1u;
  uint w = width, h = height;
  while (w > 1u || h > 1u) {
    w = (w + 1u) >> 1u;
    h = (h + 1u) >> 1u;
    ++levels;
  }
  return levels;
}
// Float offset of level `level` in the pyramid buffer (levels stored one
// after the other, row-major, top row first); level = levels gives the
// total size.
SHADER_FN uint pyramidLevelOffset(uint width, uint height, uint level) {
  uint offset = 0u;
  uint w = width, h = height;
  for (uint i = 0u; i < level; ++i) {
    offset += w * h;
    w = (w + 1u) >> 1u;
    h = (h + 1u) >> 1u;
  }
  return offset;
}

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::FibletCullPush) == 72, "");
static_assert(sizeof(fibscope::shader::FibletBoundsPush) == 16, "");
static_assert(sizeof(fibscope::shader::FibletListFinalizePush) == 16, "");
static_assert(sizeof(fibscope::shader::DepthPyramidPush) == 40, "");
static_assert(sizeof(fibscope::shader::FibletLodRasterPush) == 48, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_CULL_PUSH_H
