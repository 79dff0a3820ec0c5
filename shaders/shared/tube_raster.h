// Spline tubes ray-cast in the fragment shader (Salm, seed section 3.2 and
// figure 17; issue 15 item 3): the push constants of the two passes.
//
// 1. "tube boxes" (tube_box.vert + tube_box.frag): one instance per
//    quadratic sub-segment (shared/tubes.h), 36 vertices: the 12 triangles
//    of its tight oriented box (glsl/tube_box.glsl). Each fragment casts
//    the eye ray through its pixel centre against the sub-segment
//    (tubeIntersect, glsl/tube_intersect.glsl) and does a 64-bit atomicMin
//    of the key (clip depth bits << 32 | sub-segment item) into a
//    visibility buffer of one uint64 per pixel (row-major), cleared to ~0.
//    Clip depths in [0, 1] are non-negative floats, whose bits order as
//    their values, so the smallest key is the nearest hit and, among equal
//    depths, the smaller item: the compute caster's order.
// 2. "tube resolve" (tube_raster_resolve.comp): per pixel, the winning item
//    is intersected again and, when strictly nearer than the surface
//    target's depth, its texel written by the same function the compute
//    caster uses (glsl/tube_texel.glsl), so both variants write the same
//    texels.
#ifndef FIBSCOPE_SHADERS_SHARED_TUBE_RASTER_H
#define FIBSCOPE_SHADERS_SHARED_TUBE_RASTER_H

#include "shared/glsl_cpp.h"

SHADER_NAMESPACE_BEGIN

// Vertices of one box instance: 6 faces of 2 triangles (a list, no strip,
// so a face the eye sees from outside is collapsed alone).
#ifdef __cplusplus
inline constexpr uint kTubeBoxVertices = 36u;
inline constexpr uint kTubeResolveGroupSize = 8u;  // 8 x 8 pixels per workgroup
#else
const uint kTubeBoxVertices = 36u;
const uint kTubeResolveGroupSize = 8u;
#endif

struct TubeBoxPush {
  uint64_t camera;      // CameraBlock
  uint64_t nodes;       // TubeNode[]
  uint64_t segments;    // TubeSegment[]
  uint64_t visibility;  // uint64_t per pixel, row-major; cleared to ~0 before the pass
  uint width;           // frame width (pixels), the visibility buffer's row length
  uint pad0;
};

struct TubeRasterResolvePush {
  uint64_t camera;
  uint64_t nodes;
  uint64_t segments;
  uint64_t visibility;  // the keys of pass 1
  uint64_t surface;     // SurfaceTexel per pixel (read and written)
  uint width;
  uint height;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::TubeBoxPush) == 40, "");
static_assert(offsetof(fibscope::shader::TubeBoxPush, width) == 32, "");
static_assert(sizeof(fibscope::shader::TubeRasterResolvePush) == 48, "");
static_assert(offsetof(fibscope::shader::TubeRasterResolvePush, width) == 40, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_TUBE_RASTER_H
