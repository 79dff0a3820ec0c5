// Radix sort pass 2, first half (shared/svo.h RadixScanPush): the exclusive
// scan of the digit-major counts in place, chunk by chunk: one workgroup
// per kRadixScanChunk counts (4 per invocation, then a Hillis-Steele scan
// of the invocations' sums in shared memory), each chunk's total to
// sums[chunk] for the level above (radix_scan_add.comp adds it back). A
// single invocation over every count was wrong on lavapipe past 2^16 counts
// (about a million keys) and the slowest part of the sort.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo.h"

layout(local_size_x = 256) in;  // kRadixScanGroup

layout(push_constant, std430) uniform Push { RadixScanPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer DataRef { uint words[]; };

shared uint s_sum[kRadixScanGroup];

void main() {
  const uint chunk = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (chunk * kRadixScanChunk >= pc.count) return;  // the whole workgroup
  const uint lid = gl_LocalInvocationID.x;
  const uint base = chunk * kRadixScanChunk + 4u * lid;
  uint v[4];
  uint total = 0u;
  for (uint k = 0u; k < 4u; ++k) {
    v[k] = base + k < pc.count ? DataRef(pc.data).words[base + k] : 0u;
    total += v[k];
  }
  s_sum[lid] = total;
  barrier();
  for (uint offset = 1u; offset < kRadixScanGroup; offset <<= 1u) {
    const uint t = lid >= offset ? s_sum[lid - offset] : 0u;
    barrier();
    s_sum[lid] += t;
    barrier();
  }
  uint run = s_sum[lid] - total;  // the counts before this invocation's four
  for (uint k = 0u; k < 4u; ++k) {
    if (base + k < pc.count) DataRef(pc.data).words[base + k] = run;
    run += v[k];
  }
  if (lid == kRadixScanGroup - 1u) DataRef(pc.sums).words[chunk] = s_sum[lid];
}
