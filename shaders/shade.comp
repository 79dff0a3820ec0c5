// Shading (DESIGN.md section 6, "Shading"): per pixel, the G-buffer texel's
// base colour (solid, |tangent| as RGB, a hashed per-fiber colour, a
// per-fiber scalar through a colormap, the view-facing normal, or the
// highlight colour of a selected fiber) times
// the lighting (none, or illuminated lines: Zoeckler, Stalling, Hege 1996,
// which light a line from its tangent alone: the normal is the one in the
// plane of T and L that maximises the Phong terms), times the ambient
// occlusion factor when ssao.comp ran, unselected fibers faded towards the
// background when there is a selection, as RGBA8 (R in the low byte,
// A = 255). Empty pixels get the background colour. Formulas:
// shared/shade_push.h. One workgroup per covered tile (tile_classify.comp);
// the other tiles hold the background already.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/shade_push.h"
#include "glsl/shade_common.glsl"
#include "glsl/tangent.glsl"

layout(local_size_x = 8, local_size_y = 8) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { ShadePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer AoRef { float values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer ScalarRef { float values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer WordRef { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer ColorRef { uint values[]; };

uint packRgba8(vec3 c) {
  const uvec3 b = uvec3(clamp(c, 0.0, 1.0) * 255.0 + 0.5);
  return b.r | (b.g << 8) | (b.b << 16) | (255u << 24);
}

vec3 unpackRgb8(uint c) { return vec3(c & 255u, (c >> 8) & 255u, (c >> 16) & 255u) / 255.0; }

// The colormap entry of fiber scalar s (colormap.h: colormapIndex).
vec3 scalarColor(float s) {
  float t = pc.scalar_max > pc.scalar_min ? (s - pc.scalar_min) / (pc.scalar_max - pc.scalar_min) : 0.5;
  if (isnan(s)) t = 0.0;
  const uint entry = uint(clamp(t, 0.0, 1.0) * float(kShadeColormapEntries - 1u) + 0.5);
  return unpackRgb8(WordRef(pc.colormap).values[entry]);
}

// The line's normal facing the eye, in view space, as a colour.
vec3 normalColor(CameraBlock cam, vec3 t, vec3 v) {
  const vec3 towards = v - dot(v, t) * t;
  const float len = length(towards);
  const vec3 n = len > kShadeNormalParallelEps ? towards / len : v;
  return 0.5 + 0.5 * vec3(dot(n, cameraRight(cam)), dot(n, cameraUp(cam)), dot(n, cameraBack(cam)));
}

void main() {
  uvec2 p;
  if (!tilePixel(pc.tiles, pc.width, pc.height, p)) return;
  const uint index = p.y * pc.width + p.x;
  const GBufferTexel texel = GBufferRef(pc.gbuffer).texels[index];
  const vec3 background = unpackRgb8(pc.background);
  vec3 c = background;
  if (texel.fiber != kNoFiberId) {
    const CameraBlock cam = CameraRef(pc.camera).camera;
    const vec3 t = unpackTangent(texel.tangent);
    const vec3 v = pixelToEye(cam, p);
    const bool known = texel.fiber < pc.fiber_count;
    bool selected = false, dimmed = false;
    if (pc.selection_bits != 0ul && known) {
      selected = (WordRef(pc.selection_bits).values[texel.fiber >> 5] & (1u << (texel.fiber & 31u))) != 0u;
      dimmed = !selected;
    }
    uint mode = pc.color_mode;
    if (mode == kShadeColorScalar && (pc.fiber_scalars == 0ul || !known)) mode = kShadeColorOrientation;
    if (selected) c = unpackRgb8(pc.highlight);
    else if (mode == kShadeColorOrientation) c = abs(t);
    else if (mode == kShadeColorPerFiber) c = fiberColor(texel.fiber);
    else if (mode == kShadeColorScalar) c = scalarColor(ScalarRef(pc.fiber_scalars).values[texel.fiber]);
    else if (mode == kShadeColorNormal) c = normalColor(cam, t, v);
    else c = unpackRgb8(pc.solid);
    if (pc.lighting == kShadeLightingIlluminated) {
      const vec3 lv = normalize(vec3(kShadeLightViewX, kShadeLightViewY, kShadeLightViewZ));
      const vec3 l = lv.x * cameraRight(cam) + lv.y * cameraUp(cam) + lv.z * cameraBack(cam);
      const float lt = dot(l, t), vt = dot(v, t);
      const float diffuse = sqrt(max(1.0 - lt * lt, 0.0));
      const float cos_rv = max(diffuse * sqrt(max(1.0 - vt * vt, 0.0)) - lt * vt, 0.0);
      const float specular = pow(cos_rv, pc.shininess);
      c = c * (pc.ambient + pc.diffuse * diffuse) + vec3(pc.specular * specular);
    }
    if (pc.ao != 0ul) c *= AoRef(pc.ao).values[index];
    if (dimmed) c = mix(c, background, pc.dim_unselected);
  }
  ColorRef(pc.color).values[index] = packRgba8(c);
}
