// Radix sort pass 2, second half (shared/svo.h RadixScanPush): each chunk's
// scanned total (the counts of all chunks before it) added to its words,
// which radix_scan.comp scanned within the chunk only.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo.h"

layout(local_size_x = 256) in;  // kRadixScanGroup

layout(push_constant, std430) uniform Push { RadixScanPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer DataRef { uint words[]; };

void main() {
  const uint chunk = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (chunk * kRadixScanChunk >= pc.count) return;
  const uint add = DataRef(pc.sums).words[chunk];
  for (uint k = 0u; k < 4u; ++k) {
    const uint i = chunk * kRadixScanChunk + k * kRadixScanGroup + gl_LocalInvocationID.x;
    if (i < pc.count) DataRef(pc.data).words[i] += add;
  }
}
