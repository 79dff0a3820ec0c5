// Analytic spheres into the surface target (shared/surface_push.h for the
// rule): one invocation per pixel, every sphere tested, the nearest hit
// kept against what earlier surface passes left in the texel. The minimal
// surface pass: marks, ROI spheres and one-point fibers use it; the CPU
// reference of the same rule is rasterizeReferenceSpheres.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/surface_push.h"
#include "shared/workgroup.h"
#include "glsl/shade_common.glsl"
#include "glsl/tangent.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { SphereSurfacePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SpheresRef { SurfaceSphere spheres[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer SurfaceRef { SurfaceTexel texels[]; };

// Clip depth z/w of world point q; > 1 or < 0 outside the depth range.
float clipDepth(CameraBlock cam, vec3 q) {
  const vec4 c = cameraTransformPoint(cam.view_projection, q);
  return c.w > 0.0 ? c.z / c.w : -1.0;
}

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  const uint index = p.y * pc.width + p.x;
  const CameraBlock cam = CameraRef(pc.camera).camera;
  const vec3 o = cam.eye.xyz;
  const vec3 d = -pixelToEye(cam, p);
  float best = SurfaceRef(pc.surface).texels[index].depth;
  int hit = -1;
  vec3 hit_point = vec3(0.0);
  for (uint i = 0u; i < pc.count; ++i) {
    const vec4 s = SpheresRef(pc.spheres).spheres[i].center_radius;
    const vec3 oc = o - s.xyz;
    const float b = dot(oc, d);
    const vec3 h = oc - b * d;
    const float disc = s.w * s.w - dot(h, h);
    if (disc < 0.0) continue;
    const float root = sqrt(disc);
    float t = -b - root;
    float depth = clipDepth(cam, o + t * d);
    if (depth < 0.0) {  // before the near plane: the far side
      t = -b + root;
      depth = clipDepth(cam, o + t * d);
    }
    if (depth >= 0.0 && depth <= 1.0 && depth < best) {
      best = depth;
      hit = int(i);
      hit_point = o + t * d;
    }
  }
  if (hit < 0) return;
  const SurfaceSphere s = SpheresRef(pc.spheres).spheres[hit];
  const vec3 n = (hit_point - s.center_radius.xyz) / s.center_radius.w;
  SurfaceTexel texel;
  texel.depth = best;
  texel.fiber = s.id;
  texel.normal = packSegmentTangent(n);
  texel.tangent = texel.normal;
  texel.position = 0.0;
  texel.color = s.color;
  texel.source = kSurfaceSourceSphere;
  texel.pad0 = 0u;
  SurfaceRef(pc.surface).texels[index] = texel;
}
