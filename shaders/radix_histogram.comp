// Radix sort pass 1 (shared/svo.h RadixPush): block b's count of each
// 4-bit digit at `shift`, to counts[digit * blocks + b].
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo.h"

layout(local_size_x = 256) in;  // kRadixBlock

layout(push_constant, std430) uniform Push { RadixPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer KeysRef { uint keys[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer CountsRef { uint counts[]; };

shared uint s_hist[kRadixDigits];

void main() {
  const uint block = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (block >= pc.blocks) return;
  if (gl_LocalInvocationID.x < kRadixDigits) s_hist[gl_LocalInvocationID.x] = 0u;
  barrier();
  const uint i = block * kRadixBlock + gl_LocalInvocationID.x;
  if (i < pc.count) atomicAdd(s_hist[(KeysRef(pc.keys_in).keys[i] >> pc.shift) & (kRadixDigits - 1u)], 1u);
  barrier();
  if (gl_LocalInvocationID.x < kRadixDigits)
    CountsRef(pc.counts).counts[gl_LocalInvocationID.x * pc.blocks + block] = s_hist[gl_LocalInvocationID.x];
}
