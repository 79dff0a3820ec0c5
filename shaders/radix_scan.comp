// Radix sort pass 2 (shared/svo.h RadixPush): the exclusive scan of the
// digit-major counts in place, by one invocation (kRadixDigits * blocks
// additions: a few thousand at the sizes sorted here).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo.h"

layout(local_size_x = 1) in;

layout(push_constant, std430) uniform Push { RadixPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer CountsRef { uint counts[]; };

void main() {
  uint sum = 0u;
  const uint n = kRadixDigits * pc.blocks;
  for (uint i = 0u; i < n; ++i) {
    const uint c = CountsRef(pc.counts).counts[i];
    CountsRef(pc.counts).counts[i] = sum;
    sum += c;
  }
}
