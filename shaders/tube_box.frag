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
  // What can be skipped before the bisection cascade (a fragment's cost):
  // the sub-segment lies in the sphere about its control points' centroid
  // through the farthest of them, widened by the largest radius (a
  // quadratic Bezier lies in its control points' hull, its radius under
  // their largest). A ray that misses that sphere misses the tube; one that
  // enters it behind the pixel's nearest hit so far holds no nearer hit. The
  // margins (1 % and 1 um on the sphere, 16 ulps of depth 1 as the compute
  // caster's skip) keep every candidate that rounding could still let win,
  // so the image is the one without the skip whatever order fragments run.
  const uint index = p.y * pc.width + p.x;
  const vec3 centre = (q.b0.xyz + q.b1.xyz + q.b2.xyz) / 3.0;
  const float reach = max(max(distance(centre, q.b0.xyz), distance(centre, q.b1.xyz)), distance(centre, q.b2.xyz)) +
                      max(max(q.b0.w, q.b1.w), q.b2.w);
  const float bound = reach * 1.01 + 1e-3;
  const float dd = dot(d, d);
  const float closest = dot(centre - o, d) / dd;  // the ray's parameter nearest the centre
  const vec3 off = o + closest * d - centre;
  const float miss2 = bound * bound - dot(off, off);
  if (miss2 < 0.0) return;
  const float enter = closest - sqrt(miss2 / dd);
  if (enter > 0.0) {
    const float best = uintBitsToFloat(uint(KeysRef(pc.visibility).keys[index] >> 32));  // ~0: NaN, no skip
    const vec4 ce = cameraTransformPoint(cam.view_projection, o + enter * d);
    if (ce.w > 0.0 && ce.z / ce.w > best + 1e-6) return;
  }
  float s, t;
  if (!tubeIntersect(q, o, d, s, t)) return;
  const vec4 c = cameraTransformPoint(cam.view_projection, o + s * d);
  if (!(c.w > 0.0)) return;
  const float depth = c.z / c.w;
  if (!(depth >= 0.0 && depth <= 1.0)) return;
  if (!surfaceCutsKeep(cam, o + s * d, index, depth)) return;
  const uint64_t key = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(in_item);
  atomicMin(KeysRef(pc.visibility).keys[index], key);
}
