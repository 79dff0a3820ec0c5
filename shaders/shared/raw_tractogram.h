// An uncompressed tractogram on the GPU (render/gpu/raw_tractogram.h
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

// The points come in chunks of whole streamlines, one device buffer each
// (render/gpu/raw_tractogram.h): a single buffer may exceed neither the
// device's largest allocation (4 GiB on NVIDIA, while the paper's 500 k
// fiber tractogram has 4.8 GiB of vertices) nor its largest buffer. A
// streamline never straddles two chunks, so the lines pipeline draws each
// chunk on its own and a segment i -> i + 1 always lies in one chunk.
//
// A chunk's buffer: float x, y, z per point, tightly packed (12 bytes),
// world RAS+ mm (Tractogram::positions as is), then its end bits: uint
// words, bit (j % 32) of word j / 32 set when the chunk's point j is the
// last point of its streamline, so segment j -> j + 1 would join two
// streamlines and is not drawn (1/96 of the points' bytes; the raster needs
// no per-point fiber table). 40 bytes in std430 (array stride 40).
struct RawChunk {
  uint64_t points;       // address of the chunk's first point
  uint64_t ends;         // address of its end words (points + 12 * point_count)
  uint64_t first_point;  // global index of the chunk's first point
  uint64_t point_count;
  uint first_streamline;  // the chunk holds streamlines [first, first + count)
  uint streamline_count;
};

// std430 and C++ agree: 64-bit members first, then 4-byte scalars.
struct RawTractogram {
  // RawChunk x chunk_count, in point order: chunk c holds the global points
  // [first_point, first_point + point_count), the first chunk's first
  // point is 0, each next one starts where the previous one ends.
  uint64_t chunks;
  // uint64_t x (streamline_count + 1): streamline s owns the global points
  // [offsets[s], offsets[s + 1]) (Tractogram::offsets as is). Global, not
  // split: 8 bytes a streamline.
  uint64_t offsets;
  // VkDrawIndirectCommand per streamline (lines): vertexCount = its points,
  // instanceCount = 1, firstVertex = 0, firstInstance = the streamline
  // index. The vertex shader finds its point as offsets[instance] + vertex
  // in the chunk the draw is recorded for, so point indices beyond 2^32
  // need no 32-bit firstVertex. Global, not split: 16 bytes a streamline.
  uint64_t draws;
  uint64_t point_count;
  // Segments drawn: the sum over streamlines of max(points - 1, 0).
  uint64_t segment_count;
  uint streamline_count;
  uint chunk_count;  // at least 1
};

// raw_raster.comp: one dispatch per chunk, one invocation per candidate
// segment j -> j + 1 of the chunk, j < its point_count - 1,
// kRawRasterGroupSize per workgroup, on a 2D grid (flattened as
// gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x).
struct RawRasterPush {
  uint64_t tractogram;  // RawTractogram block
  uint64_t camera;      // CameraBlock
  uint64_t visibility;  // uint64_t key per pixel; payload = global index of the segment's first point
  // The fiber filter's bit per point (GpuScene::kept_point_bits): a
  // segment is drawn when its first point's bit is set; 0: all drawn.
  uint64_t kept_points;
  uint chunk;           // the chunk this dispatch rasterises
  uint pad0;
};

// raw_resolve.comp: visibility key -> G-buffer texel.
struct RawResolvePush {
  uint64_t tractogram;
  uint64_t visibility;
  uint64_t gbuffer;
  uint width;
  uint height;
};

// lines.vert / lines.frag: the draws of one chunk's streamlines.
struct LinesPush {
  uint64_t tractogram;
  uint64_t camera;
  uint64_t kept;  // the fiber filter's kept bits over the streamlines (GpuScene::kept_bits); 0: all drawn
  uint chunk;
  uint pad0;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::RawChunk) == 40, "a raw chunk entry is 40 bytes in std430 (stride 40)");
static_assert(offsetof(fibscope::shader::RawChunk, first_streamline) == 32, "scalars follow the 64-bit members");
static_assert(sizeof(fibscope::shader::RawTractogram) == 48, "the raw tractogram block is 48 bytes in std430");
static_assert(offsetof(fibscope::shader::RawTractogram, streamline_count) == 40, "scalars follow the addresses");
static_assert(sizeof(fibscope::shader::RawRasterPush) == 40, "");
static_assert(sizeof(fibscope::shader::RawResolvePush) == 32, "");
static_assert(sizeof(fibscope::shader::LinesPush) == 32, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_RAW_TRACTOGRAM_H
