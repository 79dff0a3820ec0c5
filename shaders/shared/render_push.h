// Push constants of the render passes, one struct per pass (the pass's
// shader file names it). Buffers are device addresses; std430 and C++ agree
// because the uint64_t members come first and the rest are 4-byte scalars.
#ifndef FIBSCOPE_SHADERS_SHARED_RENDER_PUSH_H
#define FIBSCOPE_SHADERS_SHARED_RENDER_PUSH_H

#include "shared/glsl_cpp.h"

SHADER_NAMESPACE_BEGIN

// fiblet_raster.comp: decode + raster, one workgroup per fiblet.
struct FibletRasterPush {
  uint64_t dataset;     // FibletDataset block (shared/fiblet_dataset.h)
  uint64_t camera;      // CameraBlock (shared/camera.h)
  uint64_t visibility;  // uint64_t per pixel
  // 0: draw fiblet = the flat workgroup index, for every fiblet. Otherwise a
  // FibletList (shared/fiblet_list.h): draw fiblet list.fiblets[flat
  // index] for flat index < list.count.
  uint64_t list;
  // 0, or the tangent cache: uint per (fiblet, segment) at fiblet * 64 +
  // segment, the segment's packed unit tangent (glsl/tangent.glsl), so the
  // resolve needs no decode.
  uint64_t tangents;
};

// fiblet_resolve.comp: visibility key -> G-buffer texel (fiber from the
// per-fiblet fiber table, tangent by decoding the fiblet up to the segment).
struct FibletResolvePush {
  uint64_t dataset;
  uint64_t visibility;
  uint64_t gbuffer;   // GBufferTexel per pixel
  uint64_t tangents;  // 0: decode the fiblet up to the segment; else the rasters' tangent cache
  uint width;
  uint height;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::FibletRasterPush) == 40, "");
static_assert(sizeof(fibscope::shader::FibletResolvePush) == 40, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_RENDER_PUSH_H
