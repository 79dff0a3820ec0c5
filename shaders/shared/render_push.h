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
  // resolve needs no decode. Indexed by the GLOBAL fiblet.
  uint64_t tangents;
  // The dataset's first fiblet in the scene's numbering (shared/scene_table.h):
  // keys and the tangent cache use fiblet_base + the dataset's fiblet.
  uint fiblet_base;
  uint pad;
};

// fiblet_resolve.comp: visibility key -> G-buffer texel (the global
// fiblet's dataset from the scene table, the global fiber from the dataset's
// per-fiblet fiber table, the tangent from the cache or by decoding the
// fiblet up to the segment).
struct FibletResolvePush {
  uint64_t scene;  // SceneTableHeader + SceneDataset[count] (shared/scene_table.h)
  uint64_t visibility;
  uint64_t gbuffer;   // GBufferTexel per pixel
  uint64_t tangents;  // 0: decode the fiblet up to the segment; else the rasters' tangent cache
  uint width;
  uint height;
};

// fiblet_lines.vert (+ fiblet_lines.geom, or fiblet_lines.tesc/.tese) and
// fiblet_lines.frag: the graphics fiblet pipelines, one draw per dataset.
struct FibletDrawPush {
  uint64_t dataset;  // FibletDataset block
  uint64_t camera;   // CameraBlock
  // 0: the fiblet is gl_VertexIndex (every fiblet of the dataset).
  // Otherwise a FibletList (the cull's): fiblet list.fiblets[gl_VertexIndex].
  uint64_t list;
  // The dataset's first fiber in the scene's numbering (shared/scene_table.h):
  // the G-buffer's fiber is fiber_base + fiblet_fiber[fiblet], as the resolve's.
  uint fiber_base;
  uint pad;
};

// fiblet_draw_args.comp: a cull list's count -> a VkDrawIndirectCommand
// (count vertices: one point or one one-vertex patch per fiblet).
// fiblet_draw_args.comp: `commands` VkDrawIndirectCommand from one cull
// list, command k drawing list slots [k * chunk, (k + 1) * chunk) (fewer or
// none past the list's count).
struct FibletDrawArgsPush {
  uint64_t list;  // FibletList
  uint64_t args;  // the region's first VkDrawIndirectCommand (4 uints each)
  uint chunk;     // list slots per command (0xFFFFFFFF: one command for all)
  uint commands;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::FibletDrawPush) == 32, "");
static_assert(sizeof(fibscope::shader::FibletDrawArgsPush) == 24, "");
static_assert(sizeof(fibscope::shader::FibletRasterPush) == 48, "");
static_assert(sizeof(fibscope::shader::FibletResolvePush) == 40, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_RENDER_PUSH_H
