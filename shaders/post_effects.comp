// Post effects over the shaded RGBA8 image (FiberVisualizer section 12):
// colour flattening, contrast, brightness, saturation, then sharpening, in
// that order. Formulas, order, clamping and borders: shared/post_push.h.
// Reads color_in, writes color_out (a different buffer): sharpening reads
// the neighbours as steps 1-4 leave them, which each invocation recomputes
// for its 4 neighbours (the steps are per pixel) instead of a second pass.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "shared/post_push.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(constant_id = kPostSpecSharpen) const bool kSharpen = false;

layout(push_constant, std430) uniform Push { PostPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer ColorIn { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer ColorOut { uint values[]; };

// Clamp-to-edge reads.
vec3 fetch(ivec2 q) {
  q = clamp(q, ivec2(0), ivec2(int(pc.width) - 1, int(pc.height) - 1));
  const uint c = ColorIn(pc.color_in).values[uint(q.y) * pc.width + uint(q.x)];
  return vec3(c & 255u, (c >> 8) & 255u, (c >> 16) & 255u) / 255.0;
}

// Steps 1-4 (per pixel).
vec3 grade(vec3 c) {
  if (pc.levels >= 2u) {
    const float steps = float(pc.levels - 1u);
    c = floor(c * steps + 0.5) / steps;
  }
  c = clamp((c - 0.5) * pc.contrast + 0.5, 0.0, 1.0);
  c = clamp(c + pc.brightness, 0.0, 1.0);
  const float l = dot(c, vec3(kPostLumaR, kPostLumaG, kPostLumaB));
  return clamp(l + pc.saturation * (c - l), 0.0, 1.0);
}

uint packRgba8(vec3 c) {
  const uvec3 b = uvec3(clamp(c, 0.0, 1.0) * 255.0 + 0.5);
  return b.r | (b.g << 8) | (b.b << 16) | (255u << 24);
}

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
  vec3 c = grade(fetch(p));
  if (kSharpen) {
    // y grows downwards (top row first).
    const vec3 around = grade(fetch(p + ivec2(0, -1))) + grade(fetch(p + ivec2(0, 1))) +
                        grade(fetch(p + ivec2(-1, 0))) + grade(fetch(p + ivec2(1, 0)));
    c = (1.0 + 4.0 * pc.sharpen) * c - pc.sharpen * around;
  }
  ColorOut(pc.color_out).values[uint(p.y) * pc.width + uint(p.x)] = packRgba8(c);
}
