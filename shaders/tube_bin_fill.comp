// Spline tubes, compute ray casting, pass 3 (shared/tubes.h TubeBinPush):
// one invocation per quadratic sub-segment, appended to the list of every
// tile its box covers (the same tiles as the count pass: glsl/tube_bin.glsl).
// tile_ends[tile] holds the list's start (the offsets pass) and is the
// append cursor, so it ends as the list's end; items past the buffer are
// not written (their tile tests every sub-segment).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/tubes.h"
#include "shared/workgroup.h"
#include "glsl/tube_bin.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kTubeBinGroupSize

layout(push_constant, std430) uniform Push { TubeBinPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer EndsRef { uint ends[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer ListsRef { uint items[]; };

void main() {
  uint item;
  uvec2 tmin, tmax;
  if (!tubeBinItem(pc, item) || !tubeBinTiles(pc, item, tmin, tmax)) return;
  for (uint ty = tmin.y; ty <= tmax.y; ++ty)
    for (uint tx = tmin.x; tx <= tmax.x; ++tx) {
      const uint slot = atomicAdd(EndsRef(pc.tile_ends).ends[ty * pc.tiles_x + tx], 1u);
      if (slot < pc.list_capacity) ListsRef(pc.tile_lists).items[slot] = item;
    }
}
