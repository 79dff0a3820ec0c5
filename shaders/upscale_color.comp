// Bilinear upscale of a shaded RGBA8 image into a larger one
// (shared/upscale_push.h): the viewer draws its coarse frames (camera
// moving, slow device) at a lower resolution and stretches them over the
// window. One invocation per destination pixel.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "shared/upscale_push.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { UpscalePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Src { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer Dst { uint values[]; };

vec4 fetch(ivec2 q) {
  q = clamp(q, ivec2(0), ivec2(int(pc.src_width) - 1, int(pc.src_height) - 1));
  const uint c = Src(pc.src).values[uint(q.y) * pc.src_width + uint(q.x)];
  return vec4(c & 255u, (c >> 8) & 255u, (c >> 16) & 255u, c >> 24);
}

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.dst_width || p.y >= pc.dst_height) return;
  // The destination pixel centre in source pixel coordinates.
  const vec2 s = (vec2(p) + 0.5) * vec2(pc.src_width, pc.src_height) / vec2(pc.dst_width, pc.dst_height) - 0.5;
  const ivec2 q = ivec2(floor(s));
  const vec2 f = s - vec2(q);
  const vec4 c = mix(mix(fetch(q), fetch(q + ivec2(1, 0)), f.x), mix(fetch(q + ivec2(0, 1)), fetch(q + ivec2(1, 1)), f.x),
                     f.y);
  const uvec4 b = uvec4(clamp(c + 0.5, 0.0, 255.0));
  Dst(pc.dst).values[p.y * pc.dst_width + p.x] = b.r | (b.g << 8) | (b.b << 16) | (b.a << 24);
}
