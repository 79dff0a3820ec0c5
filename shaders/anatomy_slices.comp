// Anatomical slices into the surface target (shared/anatomy.h for the rule):
// one invocation per pixel, the eye ray against the three voxel planes in
// voxel space, the nearest hit inside the volume kept against what earlier
// surface passes left in the texel, its value sampled (nearest or
// trilinear: a specialisation constant) and mapped to grey.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/anatomy.h"
#include "shared/surface_push.h"
#include "shared/workgroup.h"
#include "glsl/shade_common.glsl"
#include "glsl/tangent.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(constant_id = kAnatomySpecSampling) const uint SAMPLING = kAnatomySamplingTrilinear;

layout(push_constant, std430) uniform Push { AnatomySlicePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer BlockRef { AnatomySliceBlock b; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer ValuesRef { float values[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer SurfaceRef { SurfaceTexel texels[]; };

// Clip depth z/w of world point q; < 0 behind the eye.
float clipDepth(CameraBlock cam, vec3 q) {
  const vec4 c = cameraTransformPoint(cam.view_projection, q);
  return c.w > 0.0 ? c.z / c.w : -1.0;
}

float voxel(uvec3 dims, ivec3 v) {
  return ValuesRef(pc.values).values[(uint(v.z) * dims.y + uint(v.y)) * dims.x + uint(v.x)];
}

// The value at voxel coordinate q (inside the extent).
float sampleVolume(uvec3 dims, vec3 q) {
  const ivec3 last = ivec3(dims) - 1;
  if (SAMPLING == kAnatomySamplingNearest) return voxel(dims, clamp(ivec3(floor(q + 0.5)), ivec3(0), last));
  const vec3 c = clamp(q, vec3(0.0), vec3(last));
  const ivec3 a = min(ivec3(floor(c)), last);
  const ivec3 b = min(a + 1, last);
  const vec3 f = c - vec3(a);
  const float x00 = mix(voxel(dims, ivec3(a.x, a.y, a.z)), voxel(dims, ivec3(b.x, a.y, a.z)), f.x);
  const float x10 = mix(voxel(dims, ivec3(a.x, b.y, a.z)), voxel(dims, ivec3(b.x, b.y, a.z)), f.x);
  const float x01 = mix(voxel(dims, ivec3(a.x, a.y, b.z)), voxel(dims, ivec3(b.x, a.y, b.z)), f.x);
  const float x11 = mix(voxel(dims, ivec3(a.x, b.y, b.z)), voxel(dims, ivec3(b.x, b.y, b.z)), f.x);
  return mix(mix(x00, x10, f.y), mix(x01, x11, f.y), f.z);
}

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  const uint index = p.y * pc.width + p.x;
  const CameraBlock cam = CameraRef(pc.camera).camera;
  BlockRef block = BlockRef(pc.block);
  const uvec3 dims = uvec3(block.b.dim_x, block.b.dim_y, block.b.dim_z);
  const vec3 hi = vec3(dims) - 0.5;
  const mat3 to_voxel = mat3(block.b.world_to_voxel[0].xyz, block.b.world_to_voxel[1].xyz,
                             block.b.world_to_voxel[2].xyz);
  const vec3 d = -pixelToEye(cam, p);
  const vec3 dv = to_voxel * d;
  const vec3 ov = block.b.eye_voxel.xyz;
  const vec3 position = block.b.position.xyz;

  float best = SurfaceRef(pc.surface).texels[index].depth;
  int axis = -1;
  float value = 0.0;
  for (int a = 0; a < 3; ++a) {
    if (((block.b.shown >> uint(a)) & 1u) == 0u || dv[a] == 0.0) continue;
    const float t = (position[a] - ov[a]) / dv[a];
    if (!(t > 0.0)) continue;
    vec3 q = ov + t * dv;
    q[a] = position[a];  // on the plane exactly
    if (any(lessThan(q, vec3(-0.5))) || any(greaterThan(q, hi))) continue;
    const float depth = clipDepth(cam, cam.eye.xyz + t * d);
    if (!(depth >= 0.0 && depth <= 1.0 && depth < best)) continue;
    const float v = sampleVolume(dims, q);
    if (isnan(v)) continue;  // no value there: nothing drawn
    best = depth;
    axis = a;
    value = v;
  }
  if (axis < 0) return;

  const float lo = block.b.value_min, range = block.b.value_max - lo;
  const float g = range > 0.0 ? clamp((value - lo) / range, 0.0, 1.0) : (value >= lo ? 1.0 : 0.0);
  const uint grey = uint(g * 255.0 + 0.5);
  vec3 n = block.b.normal[axis].xyz;
  if (dot(n, d) > 0.0) n = -n;  // facing the viewer
  SurfaceTexel texel;
  texel.depth = best;
  texel.fiber = kNoFiberObject;
  texel.normal = packTangent(n);
  texel.tangent = texel.normal;
  texel.position = 0.0;
  texel.color = grey | (grey << 8) | (grey << 16) | (block.b.alpha << 24);
  texel.source = kSurfaceSourceSlice;
  texel.pad0 = 0u;
  SurfaceRef(pc.surface).texels[index] = texel;
}
