// Spline tubes, compute ray casting: the screen tiles one quadratic
// sub-segment's box overlaps, shared by the binning's count and fill passes
// (shared/tubes.h TubeBinPush) so both see the same tiles. A box reaching
// behind the eye plane covers the whole screen (conservative); one wholly
// beyond the far plane or beside the frustum covers none.
#ifndef FIBSCOPE_GLSL_TUBE_BIN_GLSL
#define FIBSCOPE_GLSL_TUBE_BIN_GLSL

#include "shared/tubes.h"
#include "glsl/render_buffers.glsl"
#include "glsl/tube_intersect.glsl"

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer TubeBinNodesRef { TubeNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer TubeBinSegmentsRef {
  TubeSegment segments[];
};

// The sub-segment of this invocation (false past the last). Workgroups of
// kTubeBinGroupSize: the constant, not gl_WorkGroupSize, which an include
// before the shader's local-size layout would read as 1.
bool tubeBinItem(TubeBinPush pc, out uint item) {
  item = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * kTubeBinGroupSize + gl_LocalInvocationID.x;
  return item < pc.sub_segments;
}

// The first and last tile (inclusive) `item`'s box covers; false for none.
bool tubeBinTiles(TubeBinPush pc, uint item, out uvec2 tmin, out uvec2 tmax) {
  tmin = uvec2(1u);
  tmax = uvec2(0u);
  const TubeSegment s = TubeBinSegmentsRef(pc.segments).segments[item / 2u];
  const TubeQuadratic q = tubeQuadratic(TubeBinNodesRef(pc.nodes).nodes[s.node],
                                        TubeBinNodesRef(pc.nodes).nodes[s.node + 1u], s.chord, item % 2u);
  vec3 lo, hi;
  tubeBox(q, lo, hi);
  const CameraBlock cam = CameraRef(pc.camera).camera;
  vec2 smin = vec2(1e30), smax = vec2(-1e30);
  bool behind = false, all_far = true;
  for (uint k = 0u; k < 8u; ++k) {
    const vec3 corner = vec3((k & 1u) != 0u ? hi.x : lo.x, (k & 2u) != 0u ? hi.y : lo.y, (k & 4u) != 0u ? hi.z : lo.z);
    const vec4 c = cameraTransformPoint(cam.view_projection, corner);
    if (c.w <= 1e-6) {
      behind = true;
      continue;
    }
    const vec3 ndc = c.xyz / c.w;
    if (ndc.z <= 1.0) all_far = false;
    smin = min(smin, ndc.xy);
    smax = max(smax, ndc.xy);
  }
  if (behind) {
    smin = vec2(-1.0);
    smax = vec2(1.0);
  } else if (all_far) {
    return false;
  }
  if (smax.x < -1.0 || smax.y < -1.0 || smin.x > 1.0 || smin.y > 1.0) return false;
  // Window coordinates, then tiles (clamped to the frame).
  const vec2 size = cam.viewport.xy;
  const vec2 wmin = (clamp(smin, -1.0, 1.0) + 1.0) * 0.5 * size, wmax = (clamp(smax, -1.0, 1.0) + 1.0) * 0.5 * size;
  tmin = uvec2(wmin) / kTubeTileSize;
  tmax = min(uvec2(wmax) / kTubeTileSize, uvec2(pc.tiles_x - 1u, pc.tiles_y - 1u));
  return true;
}

#endif  // FIBSCOPE_GLSL_TUBE_BIN_GLSL
