// The orientation overlay over the final image (shared/orientation_overlay.h
// for the layout): four letters at the middle of the edges and the axis
// triad in the bottom-right corner, one invocation per pixel of each box
// (the grid's z), every other pixel untouched.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/orientation_overlay.h"
#include "shared/workgroup.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { OrientationOverlayPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer ColorRef { uint values[]; };

// Whether cell (x, y) of glyph g is set (outside the glyph: not).
bool glyphCell(uint g, int x, int y) {
  if (x < 0 || y < 0 || x >= int(kOrientationGlyphWidth) || y >= int(kOrientationGlyphHeight)) return false;
  const uint row = kOrientationGlyphRows[g * kOrientationGlyphHeight + uint(y)];
  return ((row >> (kOrientationGlyphWidth - 1u - uint(x))) & 1u) != 0u;
}

uint darken(uint c) {
  const uvec3 rgb = uvec3(c & 255u, (c >> 8) & 255u, (c >> 16) & 255u) / 4u;
  return rgb.r | (rgb.g << 8) | (rgb.b << 16) | (255u << 24);
}

// Distance from pixel centre q to the segment from a to b.
float segmentDistance(vec2 q, vec2 a, vec2 b) {
  const vec2 ab = b - a;
  const float len2 = dot(ab, ab);
  const float t = len2 > 0.0 ? clamp(dot(q - a, ab) / len2, 0.0, 1.0) : 0.0;
  return length(q - (a + t * ab));
}

void main() {
  const int s = int(pc.scale);
  const int w = int(pc.width), h = int(pc.height);
  const int m = 4 * s;
  const uint box = gl_GlobalInvocationID.z;
  const ivec2 local = ivec2(gl_GlobalInvocationID.xy);
  ColorRef color = ColorRef(pc.color);
  if (box < 4u) {
    const int bw = 7 * s, bh = 9 * s;
    if (local.x >= bw || local.y >= bh) return;
    ivec2 origin;
    if (box == 0u) origin = ivec2(m, (h - bh) / 2);
    else if (box == 1u) origin = ivec2(w - m - bw, (h - bh) / 2);
    else if (box == 2u) origin = ivec2((w - bw) / 2, max(m, kOrientationTopMargin));
    else origin = ivec2((w - bw) / 2, h - m - bh);
    const ivec2 p = origin + local;
    if (p.x < 0 || p.y < 0 || p.x >= w || p.y >= h) return;
    const uint g = (pc.glyphs >> (8u * box)) & 255u;
    const ivec2 cell = local / s - 1;
    const uint index = uint(p.y) * pc.width + uint(p.x);
    if (glyphCell(g, cell.x, cell.y)) {
      color.values[index] = kOrientationLabelColor;
      return;
    }
    bool edge = false;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) edge = edge || glyphCell(g, cell.x + dx, cell.y + dy);
    if (edge) color.values[index] = darken(color.values[index]);
    return;
  }
  // The triad.
  const int reach = 13 * s;
  const ivec2 centre = ivec2(w - m - reach, h - m - reach);
  const ivec2 p = centre - reach - 1 + local;
  if (local.x > 2 * reach + 2 || local.y > 2 * reach + 2) return;
  if (p.x < 0 || p.y < 0 || p.x >= w || p.y >= h) return;
  const vec2 q = vec2(p) + 0.5;
  const vec2 c = vec2(centre) + 0.5;
  const float length_px = 12.0 * float(s), radius = 0.5 * float(s) + 0.5;
  const uint colors[3] = uint[3](kOrientationAxisXColor, kOrientationAxisYColor, kOrientationAxisZColor);
  float nearest_depth = -2.0;
  uint drawn = 0u;
  for (int a = 0; a < 3; ++a) {
    const vec3 v = pc.axis[a].xyz;
    const vec2 tip = c + length_px * vec2(v.x, -v.y);  // image y grows downwards
    if (segmentDistance(q, c, tip) <= radius && v.z > nearest_depth) {
      nearest_depth = v.z;
      drawn = colors[a];
    }
  }
  if (drawn != 0u) color.values[uint(p.y) * pc.width + uint(p.x)] = drawn;
}
