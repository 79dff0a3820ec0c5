// Spline tubes ray-cast in the fragment shader, pass 1 (shared/tube_raster.h
// TubeBoxPush): one instance per quadratic sub-segment, 36 vertices, the
// 12 triangles of its tight oriented box (glsl/tube_box.glsl).
//
// Only the faces the eye sees from behind (the eye not outside their
// plane) are drawn; the others collapse to a point. Every eye ray that
// meets the convex box in front of the eye leaves it through exactly one
// such face, whose exit point is in front of the eye, so each pixel the
// box covers gets exactly one fragment, also when the eye is inside the box
// (all faces drawn) or the box crosses the near plane. Clip z is 0: the
// pass has no depth attachment (the fragment shader computes the hit's own
// depth), so no box is cut by the near or far plane either.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/tube_raster.h"
#include "shared/tubes.h"
#define SHADE_COMMON_NO_TILES  // vertex/fragment stage: no workgroup built-ins
#include "glsl/shade_common.glsl"
#include "glsl/tube_box.glsl"

layout(push_constant, std430) uniform Push { TubeBoxPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodesRef { TubeNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SegmentsRef { TubeSegment segments[]; };

// The sub-segment, passed bit for bit to the fragment shader.
layout(location = 0) flat out uint out_item;
layout(location = 1) flat out vec4 out_b0;
layout(location = 2) flat out vec4 out_b1;
layout(location = 3) flat out vec4 out_b2;

// The two triangles of a face as corners (u, v) on its two other axes.
const uvec2 kFaceCorners[6] = uvec2[6](uvec2(0, 0), uvec2(1, 0), uvec2(1, 1), uvec2(0, 0), uvec2(1, 1), uvec2(0, 1));

void main() {
  const uint item = uint(gl_InstanceIndex);
  const uint v = uint(gl_VertexIndex);
  const TubeSegment s = SegmentsRef(pc.segments).segments[item / 2u];
  const TubeQuadratic q =
      tubeQuadratic(NodesRef(pc.nodes).nodes[s.node], NodesRef(pc.nodes).nodes[s.node + 1u], s.chord, item % 2u);
  out_item = item;
  out_b0 = q.b0;
  out_b1 = q.b1;
  out_b2 = q.b2;
  mat3 axes;
  vec3 lo, hi;
  tubeOrientedBox(q, axes, lo, hi);
  const CameraBlock cam = CameraRef(pc.camera).camera;
  const vec3 eye = transpose(axes) * (cam.eye.xyz - q.b0.xyz);
  // Face f: axis f / 2, the low side (f even) or the high side.
  const uint f = v / 6u, axis = f / 2u;
  const bool high = (f & 1u) != 0u;
  const bool seen_from_outside = high ? eye[axis] > hi[axis] : eye[axis] < lo[axis];
  const bool empty = any(greaterThan(lo, hi));
  if (seen_from_outside || empty) {
    gl_Position = vec4(2.0, 2.0, 0.0, 1.0);  // the face's 6 vertices coincide: no fragment
    return;
  }
  const uvec2 c = kFaceCorners[v % 6u];
  vec3 local;
  local[axis] = high ? hi[axis] : lo[axis];
  const uint a1 = (axis + 1u) % 3u, a2 = (axis + 2u) % 3u;
  local[a1] = c.x != 0u ? hi[a1] : lo[a1];
  local[a2] = c.y != 0u ? hi[a2] : lo[a2];
  const vec4 clip = cameraTransformPoint(cam.view_projection, q.b0.xyz + axes * local);
  gl_Position = vec4(clip.xy, 0.0, clip.w);
}
