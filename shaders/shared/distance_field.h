// Distance-field ambient occlusion and soft shadows (issue 16 item 4;
// McGraw's seed after Evans, "Fast approximations for global illumination
// on dynamic scenes", SIGGRAPH 2006 course): a dense low-resolution signed
// distance field of the tubes (the union of capsules, seed eq. 1), built
// once per tube model by svo_voxelize.comp over a box of the tubes plus a
// margin, its ordered keys turned into floats clamped to the band by
// df_finalize.comp, and sampled trilinearly by df_ao.comp and
// df_shadow.comp. Shared by src/svo (CPU reference, the same arithmetic)
// and the shaders.
//
// The grid: size_x * size_y * size_z voxels, voxel (i, j, k) centred at
// origin + (i + 1/2, j + 1/2, k + 1/2) * voxel, stored x fastest
// (index (k * size_y + j) * size_x + i), float mm per voxel, every value in
// [-r, band]: "band or more" where no tube is nearer than the band.
//
// Sampling (dfTrilinear): at p, g = (p - origin) / voxel - 1/2, the 8
// voxels around g (indices clamped to the grid), weights from the
// fraction of g; outside the box the value is the band.
#ifndef FIBSCOPE_SHADERS_SHARED_DISTANCE_FIELD_H
#define FIBSCOPE_SHADERS_SHARED_DISTANCE_FIELD_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define DF_CONST inline constexpr
#else
#define DF_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// The field's band (clamp) in voxels: the AO's reach (N delta) and every
// sphere-tracing step of the shadows are at most this.
DF_CONST float kDfBandVoxels = 8.0f;
// The largest field (bytes) the automatic voxel allows (RenderSettings::
// df_voxel_mm = 0): 64 MB of floats.
DF_CONST uint kDfMaxAutoVoxels = 16u << 20;
// AO: the first sample lies kDfSelfOffsetVoxels voxels off the surface
// before the N steps of delta: within a voxel of a tube the trilinear
// field is least exact (the tube's curvature, the kink at its axis), so
// the pixel's own tube would read as an occluder there.
DF_CONST float kDfSelfOffsetVoxels = 0.5f;
DF_CONST uint kDfMaxAoSteps = 8u;
// Shadows: the sphere trace starts kDfShadowStartVoxels voxels off the
// surface along the normal (the same reason), takes at most
// kDfShadowSteps steps of at least kDfShadowMinStepVoxels voxels, and
// counts a sample in the penumbra estimate only where the field is below
// kDfShadowOpenFraction of the band (beyond it the clamped field says
// nothing about how far the nearest tube is: open space).
DF_CONST float kDfShadowStartVoxels = 1.0f;
DF_CONST uint kDfShadowSteps = 96u;
DF_CONST float kDfShadowMinStepVoxels = 0.25f;
DF_CONST float kDfShadowOpenFraction = 0.95f;

DF_CONST uint kDfFinalizeGroupSize = 256u;

// Trilinear interpolation of the 8 corner values c_xyz (x fastest) at the
// fraction f of the cell: the order of operations fixed, so the CPU
// reference and the shaders sample alike.
SHADER_FN float dfLerp(float a, float b, float t) {
  SHADER_PRECISE float r = a + (b - a) * t;
  return r;
}
SHADER_FN float dfTrilinear(float c000, float c100, float c010, float c110, float c001, float c101, float c011,
                            float c111, float fx, float fy, float fz) {
  SHADER_PRECISE float x00 = dfLerp(c000, c100, fx);
  SHADER_PRECISE float x10 = dfLerp(c010, c110, fx);
  SHADER_PRECISE float x01 = dfLerp(c001, c101, fx);
  SHADER_PRECISE float x11 = dfLerp(c011, c111, fx);
  return dfLerp(dfLerp(x00, x10, fy), dfLerp(x01, x11, fy), fz);
}

// The field's placement, in every pass's push constants.
struct DfGrid {
  float origin_x, origin_y, origin_z;  // corner of voxel (0, 0, 0), mm
  float voxel;                         // mm
  uint size_x, size_y, size_z;
  float band;  // mm: the clamp (kDfBandVoxels * voxel)
};

// df_finalize.comp: one invocation per voxel: the ordered key the
// voxelisation left (svoOrderedKey, kSvoFar where no tube is within the
// band) -> the float min(f, band), in place.
struct DfFinalizePush {
  uint64_t field;
  uint count;  // voxels
  float band;
};

// df_ao.comp: per covered pixel (tile list) with p its world position (the
// depth along the pixel's ray) and n its normal (a surface's from the
// surface target, turned to the eye; a line's the view-facing normal in
// the plane of its tangent and the eye ray), h_i = eps + i delta,
// eps = kDfSelfOffsetVoxels * voxel, and d the field:
//   ao = clamp(1 - (k / delta) sum_{i=1..N} 2^-i max(min(h_i, band) - d(p + h_i n), 0), 0, 1)
// Evans' formula with k made per delta (k = 1: a sample at distance 0 of
// its tube costs 2^-i h_i / delta), each term at least 0 (a sample farther
// from every tube than h_i is open, whatever the trilinear error) and
// h_i capped at the band (the clamped field cannot tell more). Slices and
// empty pixels: 1.
struct DfAoPush {
  uint64_t camera;   // CameraBlock
  uint64_t gbuffer;  // GBufferTexel per pixel
  uint64_t surface;  // SurfaceTexel per pixel, or 0 (no surfaces this frame)
  uint64_t field;    // float per voxel
  uint64_t ao;       // float per pixel (written)
  uint64_t tiles;    // the covered tiles
  DfGrid grid;
  uint width;
  uint height;
  uint steps;  // N, 1 .. kDfMaxAoSteps
  float delta;
  float strength;  // k
  uint pad0;
};

// df_shadow.comp: per covered pixel, p and n as df_ao.comp, l the shade
// pass's headlight (shared/shade_push.h kShadeLightView*, in world space),
// s = kDfShadowStartVoxels * voxel, the ray q(t) = p + s n + t l from
// t_0 = s, t_{j+1} = t_j + max(d(q(t_j)), kDfShadowMinStepVoxels * voxel),
// until q leaves the field's box or after kDfShadowSteps samples:
//   shadow = clamp(min_j softness * d(q(t_j)) / t_j, 0, 1)
// over the samples with d < kDfShadowOpenFraction * band (Quilez's
// penumbra estimate; the softness k_s: larger is harder). Surfaces facing
// away from the light (n.l <= 0) take 1: their direct light is 0 already.
// Written to the shadow buffer; shade scales the direct (diffuse and
// specular) light by it. Slices and empty pixels: 1.
struct DfShadowPush {
  uint64_t camera;
  uint64_t gbuffer;
  uint64_t surface;  // or 0
  uint64_t field;
  uint64_t shadow;  // float per pixel (written)
  uint64_t tiles;
  DfGrid grid;
  uint width;
  uint height;
  float softness;  // k_s
  uint pad0;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::DfGrid) == 32, "");
static_assert(sizeof(fibscope::shader::DfFinalizePush) == 16, "");
static_assert(sizeof(fibscope::shader::DfAoPush) == 104, "");
static_assert(offsetof(fibscope::shader::DfAoPush, grid) == 48, "");
static_assert(offsetof(fibscope::shader::DfAoPush, width) == 80, "");
static_assert(sizeof(fibscope::shader::DfShadowPush) == 96, "");
static_assert(offsetof(fibscope::shader::DfShadowPush, width) == 80, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_DISTANCE_FIELD_H
