// Tessellation fiblet pipeline, evaluation stage: vertex i of the fiblet's
// isoline (i = gl_TessCoord.x * segments, exact for these small integers)
// is point i as fiblet_lines.tesc decoded it (point 0 per patch, point
// i >= 1 in control point (i - 1) / 2); no decode here. Flat outputs as
// fiblet_lines.geom's: vertex i carries segment i's values (its index, the
// packed tangent of point i -> i + 1) for the first-vertex provoking
// convention, on the assumption that the tessellator emits each isoline
// segment from its lower u to its higher (every driver we know of does; the
// tests compare the segment ids with the compute pipeline's, which would
// catch the other order). Clip planes as the lines baseline.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/render_push.h"
#include "glsl/render_buffers.glsl"
#include "glsl/tangent.glsl"

layout(isolines, equal_spacing) in;

layout(push_constant, std430) uniform Push { FibletDrawPush pc; };

layout(location = 4) in vec3 point_a[];
layout(location = 5) in vec3 point_b[];
layout(location = 6) patch in vec3 first_point;
layout(location = 7) patch in uint fiber;
layout(location = 8) patch in uint segments;

out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[kMaxFrameClipPlanes];
};

layout(location = 0) flat out uint out_fiber;
layout(location = 1) flat out uint out_segment;
layout(location = 2) flat out uint out_tangent;

vec3 fibletPoint(uint i) {
  if (i == 0u) return first_point;
  const uint slot = i - 1u;
  return (slot & 1u) == 0u ? point_a[slot >> 1u] : point_b[slot >> 1u];
}

void main() {
  const uint i = min(uint(round(gl_TessCoord.x * float(segments))), segments);
  const vec3 p = fibletPoint(i);
  const CameraBlock cam = CameraRef(pc.camera).camera;
  gl_Position = cameraTransformPoint(cam.view_projection, p);
  const uint planes = uint(cam.cuts.x);
  for (uint c = 0u; c < kMaxFrameClipPlanes; ++c)
    gl_ClipDistance[c] = c < planes ? dot(cam.clip_world[c].xyz, p) + cam.clip_world[c].w : 1.0;
  out_fiber = fiber;
  // The last vertex provokes no segment.
  out_segment = i < segments ? i : 0u;
  out_tangent = i < segments ? packSegmentTangent(fibletPoint(i + 1u) - p) : 0u;
}
