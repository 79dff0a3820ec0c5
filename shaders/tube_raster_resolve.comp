// Spline tubes ray-cast in the fragment shader, pass 2 (shared/tube_raster.h
// TubeRasterResolvePush): one invocation per pixel. The winning
// sub-segment of the pixel's visibility key is intersected again with the
// compute caster's ray and, when its front hit is strictly nearer than the
// surface texel's depth (what other surfaces left), the texel is written
// by the compute caster's own function (glsl/tube_texel.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/tube_raster.h"
#include "shared/tubes.h"
#include "shared/workgroup.h"
#include "glsl/shade_common.glsl"
#include "glsl/tube_intersect.glsl"
#include "glsl/tube_texel.glsl"

// kTubeResolveGroupSize x kTubeResolveGroupSize
layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;

layout(push_constant, std430) uniform Push { TubeRasterResolvePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodesRef { TubeNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SegmentsRef { TubeSegment segments[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer KeysRef { uint64_t keys[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer SurfaceRef { SurfaceTexel texels[]; };

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  const uint index = p.y * pc.width + p.x;
  const uint64_t key = KeysRef(pc.visibility).keys[index];
  if (key == 0xFFFFFFFFFFFFFFFFul) return;
  const uint item = uint(key & 0xFFFFFFFFul);
  const CameraBlock cam = CameraRef(pc.camera).camera;
  const vec3 o = cam.eye.xyz;
  const vec3 d = -pixelToEye(cam, p);
  const TubeSegment s = SegmentsRef(pc.segments).segments[item / 2u];
  const TubeNode a = NodesRef(pc.nodes).nodes[s.node], b = NodesRef(pc.nodes).nodes[s.node + 1u];
  const TubeQuadratic q = tubeQuadratic(a, b, s.chord, item % 2u);
  float dist, t;
  if (!tubeIntersect(q, o, d, dist, t)) return;
  const vec4 c = cameraTransformPoint(cam.view_projection, o + dist * d);
  if (!(c.w > 0.0)) return;
  const float depth = c.z / c.w;
  if (!(depth >= 0.0 && depth <= 1.0 && depth < SurfaceRef(pc.surface).texels[index].depth)) return;
  SurfaceRef(pc.surface).texels[index] = tubeSurfaceTexel(s, a, b, item, o + dist * d, t, depth);
}
