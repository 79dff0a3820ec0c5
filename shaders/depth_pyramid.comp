// One level of the max-depth pyramid of two-phase occlusion culling
// (shared/cull_push.h): level 0 is the visibility buffer's depth per pixel
// (1, the far plane, where nothing is drawn), each next level ceil(size / 2)
// per side with the largest depth of its (up to 4) children. A texel thus
// holds the farthest depth drawn over the pixels below it. One dispatch per
// level, a barrier between levels.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "shared/cull_push.h"
#include "glsl/render_buffers.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { DepthPyramidPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer PyramidRef { float depths[]; };

void main() {
  const uint w = pyramidLevelSize(pc.width, pc.level), h = pyramidLevelSize(pc.height, pc.level);
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= w || p.y >= h) return;
  PyramidRef pyramid = PyramidRef(pc.pyramid);
  float depth;
  if (pc.level == 0u && pc.gbuffer != 0ul) {
    depth = GBufferRef(pc.gbuffer).texels[p.y * w + p.x].depth;  // 1 where nothing is drawn
  } else if (pc.level == 0u) {
    const uint64_t key = VisibilityRef(pc.visibility).keys[visibilityIndex(p.x, p.y, w)];
    depth = key == 0xFFFFFFFFFFFFFFFFul ? 1.0 : visibilityDepth(key);
  } else {
    const uint pw = pyramidLevelSize(pc.width, pc.level - 1u), ph = pyramidLevelSize(pc.height, pc.level - 1u);
    const uint source = pyramidLevelOffset(pc.width, pc.height, pc.level - 1u);
    const uvec2 c = 2u * p;
    depth = pyramid.depths[source + c.y * pw + c.x];
    if (c.x + 1u < pw) depth = max(depth, pyramid.depths[source + c.y * pw + c.x + 1u]);
    if (c.y + 1u < ph) {
      depth = max(depth, pyramid.depths[source + (c.y + 1u) * pw + c.x]);
      if (c.x + 1u < pw) depth = max(depth, pyramid.depths[source + (c.y + 1u) * pw + c.x + 1u]);
    }
  }
  pyramid.depths[pyramidLevelOffset(pc.width, pc.height, pc.level) + p.y * w + p.x] = depth;
}
