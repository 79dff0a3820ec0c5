// Reading an uncompressed tractogram (shared/raw_tractogram.h) through
// buffer references: the points of a chunk, its end bits, and the searches
// from a global point index to its chunk and streamline. Point indices are
// 64-bit, so a point is reached by address arithmetic (GLSL array indices
// are 32-bit) rather than by indexing one float array. Requires
// GL_EXT_buffer_reference and GL_EXT_shader_explicit_arithmetic_types_int64
// in the including shader.
#ifndef FIBSCOPE_GLSL_RAW_TRACTOGRAM_GLSL
#define FIBSCOPE_GLSL_RAW_TRACTOGRAM_GLSL

#include "shared/raw_tractogram.h"
#include "glsl/render_buffers.glsl"

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer RawTractogramRef { RawTractogram t; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer RawChunksRef { RawChunk chunks[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer RawPointRef { float xyz[3]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer RawOffsetsRef { uint64_t values[]; };

RawChunk rawChunk(RawTractogram t, uint c) { return RawChunksRef(t.chunks).chunks[c]; }

// The chunk's point j (a chunk-local index), world mm.
vec3 rawChunkPoint(RawChunk c, uint64_t j) {
  RawPointRef p = RawPointRef(c.points + 12ul * j);
  return vec3(p.xyz[0], p.xyz[1], p.xyz[2]);
}

// Whether the chunk's point j is the last of its streamline (segment j ->
// j + 1 joins two streamlines).
bool rawChunkPointEndsStreamline(RawChunk c, uint64_t j) {
  const uint word = UintsRef(c.ends).values[uint(j >> 5ul)];
  return ((word >> uint(j & 31ul)) & 1u) != 0u;
}

// The chunk that holds global point i < point_count: the last c with
// first_point <= i (chunks are in point order and none is empty but a lone
// first one). Binary search over the small chunk table (a handful of
// entries at 1 GiB a chunk), about log2(chunks) loads.
uint rawChunkOfPoint(RawTractogram t, uint64_t i) {
  RawChunksRef chunks = RawChunksRef(t.chunks);
  uint lo = 0u, hi = t.chunk_count;  // first_point[lo] <= i, and i < first_point[hi] where hi < chunk_count
  while (hi - lo > 1u) {
    const uint mid = lo + (hi - lo) / 2u;
    if (chunks.chunks[mid].first_point <= i) lo = mid; else hi = mid;
  }
  return lo;
}

// The streamline that owns global point i of chunk c: the s with
// offsets[s] <= i < offsets[s + 1] (unique; streamlines of no points have
// an empty range and are never the answer), searched among the chunk's
// streamlines only, about log2(their count) loads.
uint rawStreamlineOfPoint(RawTractogram t, RawChunk c, uint64_t i) {
  RawOffsetsRef offsets = RawOffsetsRef(t.offsets);
  uint lo = c.first_streamline, hi = c.first_streamline + c.streamline_count;  // offsets[lo] <= i < offsets[hi]
  while (hi - lo > 1u) {
    const uint mid = lo + (hi - lo) / 2u;
    if (offsets.values[mid] <= i) lo = mid; else hi = mid;
  }
  return lo;
}

#endif
