// Spline tubes, compute ray casting, pass 1 (shared/tubes.h TubeBinPush):
// one invocation per quadratic sub-segment, one added to the count of
// every tile its box covers (glsl/tube_bin.glsl), so the offsets pass can
// give each tile a list of exactly its length.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/tubes.h"
#include "shared/workgroup.h"
#include "glsl/tube_bin.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kTubeBinGroupSize

layout(push_constant, std430) uniform Push { TubeBinPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer CountsRef { uint counts[]; };

void main() {
  uint item;
  uvec2 tmin, tmax;
  if (!tubeBinItem(pc, item) || !tubeBinTiles(pc, item, tmin, tmax)) return;
  for (uint ty = tmin.y; ty <= tmax.y; ++ty)
    for (uint tx = tmin.x; tx <= tmax.x; ++tx) atomicAdd(CountsRef(pc.tile_counts).counts[ty * pc.tiles_x + tx], 1u);
}
