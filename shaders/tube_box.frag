// Spline tubes ray-cast in the fragment shader, pass 1 (shared/tube_raster.h
// TubeBoxPush): the eye ray through the fragment's pixel centre (as the
// compute caster makes it) against the instance's sub-segment
// (tubeIntersect, glsl/tube_intersect.glsl); a front hit with clip depth
// in [0, 1] is kept by a 64-bit atomicMin of (depth bits << 32 | item) in
// the pixel's visibility key. No colour or depth attachment.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "shared/tube_raster.h"
#include "shared/tubes.h"
#define SHADE_COMMON_NO_TILES  // vertex/fragment stage: no workgroup built-ins
#include "glsl/shade_common.glsl"
#include "glsl/tube_intersect.glsl"
#include "glsl/surface_cuts.glsl"

layout(push_constant, std430) uniform Push { TubeBoxPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 8) buffer KeysRef { uint64_t keys[]; };

layout(location = 0) flat in uint in_item;
layout(location = 1) flat in vec4 in_b0;
layout(location = 2) flat in vec4 in_b1;
layout(location = 3) flat in vec4 in_b2;

void main() {
  const uvec2 p = uvec2(gl_FragCoord.xy);
  const CameraBlock cam = CameraRef(pc.camera).camera;
  const vec3 o = cam.eye.xyz;
  const vec3 d = -pixelToEye(cam, p);
  TubeQuadratic q;
  q.b0 = in_b0;
  q.b1 = in_b1;
  q.b2 = in_b2;
  float s, t;
  if (!tubeIntersect(q, o, d, s, t)) return;
  const vec4 c = cameraTransformPoint(cam.view_projection, o + s * d);
  if (!(c.w > 0.0)) return;
  const float depth = c.z / c.w;
  if (!(depth >= 0.0 && depth <= 1.0)) return;
  if (!surfaceCutsKeep(cam, o + s * d, p.y * pc.width + p.x, depth)) return;
  const uint64_t key = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(in_item);
  atomicMin(KeysRef(pc.visibility).keys[p.y * pc.width + p.x], key);
}
