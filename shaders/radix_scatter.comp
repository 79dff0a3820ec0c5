// Radix sort pass 3 (shared/svo.h RadixPush): each key and its value to
// its digit's offset for its block plus its rank among the block's earlier
// keys of that digit (counted in shared memory: stable).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo.h"

layout(local_size_x = 256) in;  // kRadixBlock

layout(push_constant, std430) uniform Push { RadixPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer InRef { uint items[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer OutRef { uint items[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer CountsRef { uint counts[]; };

shared uint s_digit[kRadixBlock];

void main() {
  const uint block = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (block >= pc.blocks) return;
  const uint local = gl_LocalInvocationID.x;
  const uint i = block * kRadixBlock + local;
  uint key = 0u, digit = kRadixDigits;  // past the end: a digit no key has
  if (i < pc.count) {
    key = InRef(pc.keys_in).items[i];
    digit = (key >> pc.shift) & (kRadixDigits - 1u);
  }
  s_digit[local] = digit;
  barrier();
  if (i >= pc.count) return;
  uint rank = 0u;
  for (uint j = 0u; j < local; ++j) rank += s_digit[j] == digit ? 1u : 0u;
  const uint dst = CountsRef(pc.counts).counts[digit * pc.blocks + block] + rank;
  OutRef(pc.keys_out).items[dst] = key;
  OutRef(pc.values_out).items[dst] = InRef(pc.values_in).items[i];
}
