// Lists the kPixelGroupSize x kPixelGroupSize tiles of the frame that hold a
// covered pixel (shared/shade_push.h, TileClassifyPush), so that SSAO, its
// blur and shading run one workgroup per covered tile. On a CPU device a
// pixel pass costs nearly as much for an empty pixel as for a covered one
// (the SIMD lanes run both sides of every branch under a mask), and a
// whole-brain view leaves over half of the tiles empty.
// One invocation per pixel; per subgroup one atomic at most: the first
// subgroup to set a tile's flag appends the tile.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require

#include "shared/workgroup.h"
#include "shared/shade_push.h"
#include "glsl/render_buffers.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { TileClassifyPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer FlagsRef { uint flags[]; };

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  const bool inside = p.x < pc.width && p.y < pc.height;
  // No early return: the vote below needs every invocation of the subgroup.
  const bool covered = inside && GBufferRef(pc.gbuffer).texels[p.y * pc.width + p.x].fiber != kNoFiberId;
  if (subgroupAny(covered) && subgroupElect()) {
    const uint tile = gl_WorkGroupID.y * pixelGroups(pc.width) + gl_WorkGroupID.x;
    if (atomicOr(FlagsRef(pc.flags).flags[tile], 1u) == 0u) {
      TileListRef list = TileListRef(pc.tiles);
      list.tiles[atomicAdd(list.header.count, 1u)] = tile;
    }
  }
}
