// Spline tubes, compute ray casting, pass 1 (shared/tubes.h TubeBinPush):
// one invocation per quadratic sub-segment; its box projected to the
// screen and the sub-segment appended to the list of every tile the
// projection overlaps. A box reaching behind the eye plane covers the
// whole screen (conservative); one wholly beyond the far plane or beside
// the frustum is dropped.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/tubes.h"
#include "shared/workgroup.h"
#include "glsl/render_buffers.glsl"
#include "glsl/tube_intersect.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kTubeBinGroupSize

layout(push_constant, std430) uniform Push { TubeBinPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodesRef { TubeNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SegmentsRef { TubeSegment segments[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer CountsRef { uint counts[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer ListsRef { uint items[]; };

void main() {
  const uint item = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                    gl_LocalInvocationID.x;
  if (item >= pc.sub_segments) return;
  const TubeSegment s = SegmentsRef(pc.segments).segments[item / 2u];
  const TubeQuadratic q =
      tubeQuadratic(NodesRef(pc.nodes).nodes[s.node], NodesRef(pc.nodes).nodes[s.node + 1u], s.chord, item % 2u);
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
    return;
  }
  if (smax.x < -1.0 || smax.y < -1.0 || smin.x > 1.0 || smin.y > 1.0) return;
  // Window coordinates, then tiles (clamped to the frame).
  const vec2 size = cam.viewport.xy;
  const vec2 wmin = (clamp(smin, -1.0, 1.0) + 1.0) * 0.5 * size, wmax = (clamp(smax, -1.0, 1.0) + 1.0) * 0.5 * size;
  const uvec2 tmin = uvec2(wmin) / kTubeTileSize;
  const uvec2 tmax = min(uvec2(wmax) / kTubeTileSize, uvec2(pc.tiles_x - 1u, pc.tiles_y - 1u));
  for (uint ty = tmin.y; ty <= tmax.y; ++ty)
    for (uint tx = tmin.x; tx <= tmax.x; ++tx) {
      const uint tile = ty * pc.tiles_x + tx;
      const uint slot = atomicAdd(CountsRef(pc.tile_counts).counts[tile], 1u);
      if (slot < kTubeTileCapacity) ListsRef(pc.tile_lists).items[tile * kTubeTileCapacity + slot] = item;
      if (slot == kTubeTileCapacity) atomicAdd(CountsRef(pc.tile_counts).counts[pc.tiles_x * pc.tiles_y], 1u);
    }
}
