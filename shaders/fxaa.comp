// Fast approximate anti-aliasing over the shaded RGBA8 image (DESIGN.md
// section 6, "Shading"), after the description of T. Lottes' FXAA 3.11
// (NVIDIA, 2011) "quality" preset, on a storage buffer instead of a
// filtered texture: the bilinear taps FXAA takes half-way between two
// pixels are the averages of those pixels here, and the search walks whole
// pixels. The steps and their constants: shared/shade_push.h (FxaaPush).
// Reads color_in, writes color_out (a different buffer): every pixel reads
// its neighbours as shaded.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "shared/shade_push.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { FxaaPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer ColorIn { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer ColorOut { uint values[]; };

// Pixels walked along the edge per search step (FXAA's quality steps
// 1, 1, 1, 1, 1, 1.5, 2, 2, 2, 2, 4, 8, rounded to whole pixels).
const int kStep[kFxaaSearchSteps] = int[](1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 4, 8);

// Clamp-to-edge reads, as a texture sampler would.
uint fetch(ivec2 q) {
  q = clamp(q, ivec2(0), ivec2(int(pc.width) - 1, int(pc.height) - 1));
  return ColorIn(pc.color_in).values[uint(q.y) * pc.width + uint(q.x)];
}
vec3 rgb(uint c) { return vec3(c & 255u, (c >> 8) & 255u, (c >> 16) & 255u) / 255.0; }
float luma(uint c) { return dot(rgb(c), vec3(0.299, 0.587, 0.114)); }
float lumaAt(ivec2 q) { return luma(fetch(q)); }

uint packRgba8(vec3 c) {
  const uvec3 b = uvec3(clamp(c, 0.0, 1.0) * 255.0 + 0.5);
  return b.r | (b.g << 8) | (b.b << 16) | (255u << 24);
}

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
  const uint index = uint(p.y) * pc.width + uint(p.x);
  const uint centre = fetch(p);
  const float m = luma(centre);
  // y grows downwards (top row first): n is the row above.
  const float n = lumaAt(p + ivec2(0, -1)), s = lumaAt(p + ivec2(0, 1));
  const float w = lumaAt(p + ivec2(-1, 0)), e = lumaAt(p + ivec2(1, 0));
  const float lo = min(m, min(min(n, s), min(w, e)));
  const float hi = max(m, max(max(n, s), max(w, e)));
  const float contrast = hi - lo;
  // 1. Flat (or only faintly varying) neighbourhoods are left alone.
  if (contrast < max(pc.edge_threshold_min, hi * pc.edge_threshold)) {
    ColorOut(pc.color_out).values[index] = centre;
    return;
  }
  const float nw = lumaAt(p + ivec2(-1, -1)), ne = lumaAt(p + ivec2(1, -1));
  const float sw = lumaAt(p + ivec2(-1, 1)), se = lumaAt(p + ivec2(1, 1));

  // 2. Horizontal edge (luma changes along y) when the second differences
  // down the three columns outweigh those along the three rows.
  const float edge_h = 2.0 * abs(n + s - 2.0 * m) + abs(nw + sw - 2.0 * w) + abs(ne + se - 2.0 * e);
  const float edge_v = 2.0 * abs(w + e - 2.0 * m) + abs(nw + ne - 2.0 * n) + abs(sw + se - 2.0 * s);
  const bool horizontal = edge_h >= edge_v;
  const float before = horizontal ? n : w, after = horizontal ? s : e;
  const float g_before = before - m, g_after = after - m;
  const bool towards_before = abs(g_before) >= abs(g_after);
  const float far_luma = towards_before ? before : after;
  const float gradient_scaled = 0.25 * max(abs(g_before), abs(g_after));
  const float local_average = 0.5 * (m + far_luma);
  const ivec2 across = (horizontal ? ivec2(0, 1) : ivec2(1, 0)) * (towards_before ? -1 : 1);
  const ivec2 along = horizontal ? ivec2(1, 0) : ivec2(0, 1);

  // 3. Follow the edge both ways on the luma half-way across it.
  int dist_neg = 0, dist_pos = 0;
  float end_neg = 0.0, end_pos = 0.0;
  bool done_neg = false, done_pos = false;
  for (uint i = 0u; i < kFxaaSearchSteps && !(done_neg && done_pos); ++i) {
    if (!done_neg) {
      dist_neg += kStep[i];
      const ivec2 q = p - dist_neg * along;
      end_neg = 0.5 * (lumaAt(q) + lumaAt(q + across)) - local_average;
      done_neg = abs(end_neg) >= gradient_scaled;
    }
    if (!done_pos) {
      dist_pos += kStep[i];
      const ivec2 q = p + dist_pos * along;
      end_pos = 0.5 * (lumaAt(q) + lumaAt(q + across)) - local_average;
      done_pos = abs(end_pos) >= gradient_scaled;
    }
  }

  // 4. Blend across the edge by how near the pixel is to the end where the
  // edge steps its way (the other end belongs to the neighbouring step).
  const bool neg_nearer = dist_neg < dist_pos;
  const float nearer = float(min(dist_neg, dist_pos));
  const float edge_length = float(dist_neg + dist_pos);
  const bool centre_darker = m < local_average;
  const bool steps_our_way = ((neg_nearer ? end_neg : end_pos) < 0.0) != centre_darker;
  const float edge_blend = steps_our_way ? 0.5 - nearer / edge_length : 0.0;

  // 5. Sub-pixel aliasing: a pixel unlike its whole neighbourhood.
  const float average = (2.0 * (n + s + w + e) + nw + ne + sw + se) / 12.0;
  const float sub = clamp(abs(average - m) / contrast, 0.0, 1.0);
  const float sub_smooth = (3.0 - 2.0 * sub) * sub * sub;
  const float sub_blend = sub_smooth * sub_smooth * pc.subpix;

  const float blend = max(edge_blend, sub_blend);
  const vec3 result = mix(rgb(centre), rgb(fetch(p + across)), blend);
  ColorOut(pc.color_out).values[index] = packRgba8(result);
}
