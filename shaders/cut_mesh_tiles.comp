// Mesh cut, tiles (shared/cut_mesh.h): one invocation per tile summarises
// the depth ranges of the tile's pixels and of its 8 neighbour tiles' (the
// dilation: a sphere's screen rectangle is rounded out to whole tiles, and
// the neighbours absorb the cull's pixel slack), for the cull pass.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "glsl/render_buffers.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kCutTileGroupSize

layout(push_constant, std430) uniform Push { CutMeshTilesPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer TilesOutRef { CutTile tiles[]; };

void main() {
  const uint t = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationIndex;
  if (t >= pc.tiles_x * pc.tiles_y) return;
  const int tx = int(t % pc.tiles_x), ty = int(t / pc.tiles_x);
  const int ts = int(kCutTileSize);
  const int x0 = max((tx - 1) * ts, 0), x1 = min((tx + 2) * ts, int(pc.width));
  const int y0 = max((ty - 1) * ts, 0), y1 = min((ty + 2) * ts, int(pc.height));
  UintsRef front = UintsRef(pc.front), back = UintsRef(pc.back);
  float max_front = 0.0, min_back = 1.0e30;
  bool any = false, all = true;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const uint i = uint(y) * pc.width + uint(x);
      const uint fb = front.values[i], bb = back.values[i];
      if (bb == kCutDepthNone) {
        all = false;
        continue;
      }
      any = true;
      const float b = uintBitsToFloat(bb);
      const float f = fb == kCutDepthNone ? 0.0 : uintBitsToFloat(fb);
      max_front = max(max_front, f <= b ? f : 0.0);
      min_back = min(min_back, b);
    }
  CutTile tile;
  tile.max_front = max_front;
  tile.min_back = min_back;
  tile.flags = (any ? kCutTileAnyCovered : 0u) | (all ? kCutTileAllCovered : 0u);
  tile.pad0 = 0u;
  TilesOutRef(pc.tiles).tiles[t] = tile;
}
