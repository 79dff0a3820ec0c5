// An uncompressed tractogram on the GPU (render/gpu_raw_tractogram.h
// uploads it) for the two baseline pipelines every speed figure is compared
// against (DESIGN.md section 6): `lines` (line strips through the graphics
// pipeline) and `raw-compute` (the compute raster over raw vertices, the
// role of the paper's point-cloud compute column). Shared by the shaders and
// the C++ that fills it, like fiblet_dataset.h.
//
// Point indices are 64-bit: the paper's largest tractogram has 8.1 G
// points. Streamline indices are 32-bit (kNoFiberId is reserved), and so is
// a streamline's point count (a draw's vertexCount).
#ifndef FIBSCOPE_SHADERS_SHARED_RAW_TRACTOGRAM_H
#define FIBSCOPE_SHADERS_SHARED_RAW_TRACTOGRAM_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#include <cstddef>
#endif

SHADER_NAMESPACE_BEGIN

// std430 and C++ agree: 64-bit members first, then 4-byte scalars.
struct RawTractogram {
  // float x, y, z per point, tightly packed (12 bytes), world RAS+ mm:
  // Tractogram::positions as is.
  uint64_t points;
  // uint64_t x (streamline_count + 1): streamline s owns points
  // [offsets[s], offsets[s + 1]) (Tractogram::offsets as is).
  uint64_t offsets;
  // uint words, one bit per point: bit (i % 32) of word i / 32 is set when
  // point i is the last point of its streamline, so segment i -> i + 1
  // would join two streamlines and is not drawn. 1/96 of the points'
  // bytes; the raster needs no per-point fiber table.
  uint64_t ends;
  // VkDrawIndirectCommand per streamline (lines): vertexCount = its points,
  // instanceCount = 1, firstVertex = 0, firstInstance = the streamline
  // index. The vertex shader finds its point as offsets[instance] + vertex,
  // so point indices beyond 2^32 need no 32-bit firstVertex.
  uint64_t draws;
  uint64_t point_count;
  // Segments drawn: the sum over streamlines of max(points - 1, 0).
  uint64_t segment_count;
  uint streamline_count;
  uint pad0;
};

// raw_raster.comp: one invocation per candidate segment i -> i + 1, i <
// point_count - 1, kRawRasterGroupSize per workgroup, on a 2D grid
// (flattened as gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x).
struct RawRasterPush {
  uint64_t tractogram;  // RawTractogram block
  uint64_t camera;      // CameraBlock
  uint64_t visibility;  // uint64_t key per pixel; payload = global index of the segment's first point
};

// raw_resolve.comp: visibility key -> G-buffer texel.
struct RawResolvePush {
  uint64_t tractogram;
  uint64_t visibility;
  uint64_t gbuffer;
  uint width;
  uint height;
};

// lines.vert / lines.frag.
struct LinesPush {
  uint64_t tractogram;
  uint64_t camera;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::RawTractogram) == 56, "the raw tractogram block is 56 bytes in std430");
static_assert(offsetof(fibscope::shader::RawTractogram, streamline_count) == 48, "scalars follow the addresses");
static_assert(sizeof(fibscope::shader::RawRasterPush) == 24, "");
static_assert(sizeof(fibscope::shader::RawResolvePush) == 32, "");
static_assert(sizeof(fibscope::shader::LinesPush) == 16, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_RAW_TRACTOGRAM_H
