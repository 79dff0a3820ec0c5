// Reading an uncompressed tractogram (shared/raw_tractogram.h) through
// buffer references. Point indices are 64-bit, so a point is reached by
// address arithmetic (GLSL array indices are 32-bit) rather than by
// indexing one float array. Requires GL_EXT_buffer_reference and
// GL_EXT_shader_explicit_arithmetic_types_int64 in the including shader.
#ifndef FIBSCOPE_GLSL_RAW_TRACTOGRAM_GLSL
#define FIBSCOPE_GLSL_RAW_TRACTOGRAM_GLSL

#include "shared/raw_tractogram.h"
#include "glsl/render_buffers.glsl"

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer RawTractogramRef { RawTractogram t; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer RawPointRef { float xyz[3]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer RawOffsetsRef { uint64_t values[]; };

// Point i, world mm.
vec3 rawPoint(RawTractogram t, uint64_t i) {
  RawPointRef p = RawPointRef(t.points + 12ul * i);
  return vec3(p.xyz[0], p.xyz[1], p.xyz[2]);
}

// Whether point i is the last of its streamline (segment i -> i + 1 joins
// two streamlines).
bool rawPointEndsStreamline(RawTractogram t, uint64_t i) {
  const uint word = UintsRef(t.ends).values[uint(i >> 5ul)];
  return ((word >> uint(i & 31ul)) & 1u) != 0u;
}

// The streamline that owns point i < point_count: the s with offsets[s] <=
// i < offsets[s + 1] (unique; streamlines of no points have an empty range
// and are never the answer). Binary search, about log2(streamlines) loads.
uint rawStreamlineOfPoint(RawTractogram t, uint64_t i) {
  RawOffsetsRef offsets = RawOffsetsRef(t.offsets);
  uint lo = 0u, hi = t.streamline_count;  // offsets[lo] <= i < offsets[hi]
  while (hi - lo > 1u) {
    const uint mid = lo + (hi - lo) / 2u;
    if (offsets.values[mid] <= i) lo = mid; else hi = mid;
  }
  return lo;
}

#endif
