// Fiber filter over a raw tractogram: one invocation per streamline copies
// its kept bit (the combine's words, scene fiber = streamline) to a bit
// per point, which raw_raster.comp reads for each segment's first point
// (it has no per-point streamline index; a search per point would cost
// more than the raster). Neighbouring streamlines share words: atomicOr,
// into words cleared first.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "glsl/raw_tractogram.glsl"
#include "glsl/filter_regions.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kFilterGroupSize

layout(push_constant, std430) uniform Push { FilterPassPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer PointBitsRef { uint words[]; };

void main() {
  const RawTractogram t = RawTractogramRef(pc.source).t;
  const uint s = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationIndex;
  if (s >= t.streamline_count) return;
  if ((UintsRef(pc.kept).values[s >> 5u] & (1u << (s & 31u))) == 0u) return;
  RawOffsetsRef offsets = RawOffsetsRef(t.offsets);
  const uint64_t first = offsets.values[s], end = offsets.values[s + 1u];
  PointBitsRef bits = PointBitsRef(pc.point_bits);
  uint64_t i = first;
  while (i < end) {
    const uint word = uint(i >> 5ul);
    const uint lo = uint(i & 31ul);
    const uint64_t word_end = min(end, (uint64_t(word) + 1ul) << 5ul);
    const uint hi = uint(word_end - (uint64_t(word) << 5ul));  // exclusive, 1..32
    const uint mask = (hi == 32u ? 0xFFFFFFFFu : ((1u << hi) - 1u)) & ~((1u << lo) - 1u);
    atomicOr(bits.words[word], mask);
    i = word_end;
  }
}
