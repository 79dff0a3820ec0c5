// Spline tubes, compute ray casting, pass 2 (shared/tubes.h
// TubeBinOffsetsPush): one workgroup over every tile (a frame has tens of
// thousands: 32,400 at 1920 x 1080, so one group's serial chunks cost less
// than a multi-level scan's dispatches). Each invocation sums a chunk of
// consecutive tiles' counts, the chunk sums are scanned in shared memory,
// and each tile gets its list's start in tile_ends. The sums saturate at
// kSaturated, above any list capacity (2^28 items at most, gpu_tubes.h),
// so a start plus a tile's count (< 2^31) never wraps in the fill pass's
// cursor.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require  // the push constants' addresses

#include "shared/tubes.h"
#include "shared/workgroup.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kTubeScanGroupSize

layout(push_constant, std430) uniform Push { TubeBinOffsetsPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer CountsRef { uint counts[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer EndsRef { uint ends[]; };

const uint kSaturated = 0x80000000u;

// a + b, or kSaturated where that is less (a <= kSaturated).
uint addSaturated(uint a, uint b) { return b >= kSaturated - a ? kSaturated : a + b; }

shared uint s_sums[kTubeScanGroupSize];
shared uint s_overflowed;

void main() {
  const uint i = gl_LocalInvocationID.x;
  const uint chunk = (pc.tiles + kTubeScanGroupSize - 1u) / kTubeScanGroupSize;
  const uint first = min(i * chunk, pc.tiles), last = min(first + chunk, pc.tiles);
  CountsRef counts = CountsRef(pc.tile_counts);
  uint sum = 0u;
  for (uint t = first; t < last; ++t) sum = addSaturated(sum, counts.counts[t]);
  s_sums[i] = sum;
  if (i == 0u) s_overflowed = 0u;
  barrier();
  if (i == 0u) {
    uint running = 0u;
    for (uint k = 0u; k < kTubeScanGroupSize; ++k) {
      const uint v = s_sums[k];
      s_sums[k] = running;
      running = addSaturated(running, v);
    }
    counts.counts[pc.tiles + 1u] = running;
  }
  barrier();
  uint start = s_sums[i];
  uint overflowed = 0u;
  for (uint t = first; t < last; ++t) {
    const uint n = counts.counts[t];
    EndsRef(pc.tile_ends).ends[t] = start;
    start = addSaturated(start, n);
    if (n > 0u && start > pc.list_capacity) ++overflowed;
  }
  if (overflowed > 0u) atomicAdd(s_overflowed, overflowed);
  barrier();
  if (i == 0u) counts.counts[pc.tiles] = s_overflowed;
}
