// Anatomical slices (DESIGN.md section 2): a scalar NIfTI volume shown as
// its own voxel planes i = const, j = const, k = const, in world space
// through the affine nibabel chooses (so oblique where the sform is), drawn
// into the surface target (shared/gbuffer.h) by anatomy_slices.comp and
// depth-composited with the fibers by the merge.
//
// Voxel coordinates: voxel (i, j, k)'s centre is at integer coordinates
// (the NIfTI convention: affine * (i, j, k, 1) is the centre), the volume
// spans [-0.5, dim - 0.5] along each axis; outside that nothing is drawn.
//
// anatomy_slices.comp, per pixel: the eye ray through the pixel centre
// (world origin camera.eye, unit direction -pixelToEye) in voxel space
// (origin eye_voxel, direction world_to_voxel's 3x3 times the world
// direction, so that the ray parameter t stays in world mm), against the
// plane of each shown axis a: t = (position[a] - o[a]) / d[a]; the hit is
// kept where t > 0, the other two coordinates lie within the volume's
// extent (closed), its clip depth lies in [0, 1] and is strictly nearer
// than the surface texel's, and the sampled value is not NaN; the nearest
// of the three planes wins. Sampling (kAnatomySpecSampling):
//   nearest:   the voxel round(q) (floor(q + 0.5)), clamped to the grid;
//   trilinear: q clamped to [0, dim - 1] (the outer half voxel takes the
//              edge value, as a clamp-to-edge texture), the 8 voxels around
//              it weighted by the fractions, mixed along i, then j, then k.
// Grey: g = clamp((value - value_min) / (value_max - value_min), 0, 1)
// (value_max == value_min: 1 at or above it, else 0), stored as
// round(255 g) in R, G and B; the colour's alpha is the opacity (alpha,
// 1..255: an own colour, shared/gbuffer.h). The normal is the plane's,
// turned towards the eye; the fiber field kNoFiberObject.
#ifndef FIBSCOPE_SHADERS_SHARED_ANATOMY_H
#define FIBSCOPE_SHADERS_SHARED_ANATOMY_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define ANATOMY_CONST inline constexpr
#else
#define ANATOMY_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// anatomy_slices.comp's constant_id for the sampling.
ANATOMY_CONST uint kAnatomySpecSampling = 0u;
ANATOMY_CONST uint kAnatomySamplingNearest = 0u;
ANATOMY_CONST uint kAnatomySamplingTrilinear = 1u;

// The parameters of one frame's slices (written by the anatomy stage with
// the frame's commands).
struct AnatomySliceBlock {
  vec4 world_to_voxel[4];  // world mm -> voxel coordinates, columns (only the 3x3 is used)
  vec4 eye_voxel;          // xyz: the camera's eye in voxel coordinates (made in double); w: 0
  vec4 normal[3];          // xyz: unit world normal of the plane of axis a (towards +a); w: 0
  vec4 position;           // xyz: the slice of each axis, a voxel coordinate; w: 0
  uint dim_x;
  uint dim_y;
  uint dim_z;
  uint shown;  // bit a: the slice of axis a is drawn
  float value_min;  // black
  float value_max;  // white
  uint alpha;       // the opacity as the colour's alpha, 1 .. 255
  uint pad0;
};

struct AnatomySlicePush {
  uint64_t camera;   // CameraBlock
  uint64_t block;    // AnatomySliceBlock
  uint64_t values;   // float per voxel, i fastest, then j, then k
  uint64_t surface;  // SurfaceTexel per pixel (read and written)
  uint width;
  uint height;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::AnatomySliceBlock) == 176, "");
static_assert(offsetof(fibscope::shader::AnatomySliceBlock, eye_voxel) == 64, "");
static_assert(offsetof(fibscope::shader::AnatomySliceBlock, dim_x) == 144, "");
static_assert(sizeof(fibscope::shader::AnatomySlicePush) == 40, "");
static_assert(offsetof(fibscope::shader::AnatomySlicePush, width) == 32, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_ANATOMY_H
