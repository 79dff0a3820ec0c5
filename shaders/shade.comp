// Shading (DESIGN.md section 6, "Shading"): per pixel, the G-buffer texel's
// base colour (solid, |tangent| as RGB, a hashed per-fiber colour, a
// per-fiber scalar through a colormap, the view-facing normal, or the
// highlight colour of a selected fiber) times
// the lighting (none; illuminated lines: Zoeckler, Stalling, Hege 1996,
// which light a line from its tangent alone: the normal is the one in the
// plane of T and L that maximises the Phong terms; surfaces: Blinn-Phong
// from their normal; or PBR: Cook-Torrance under FiberVisualizer's ring of
// directional lights, lines taking their view-facing normal; the direct
// light scaled by df_shadow.comp's factor when it ran), times the ambient
// occlusion factor when ssao.comp or df_ao.comp ran, unselected fibers faded towards the
// background when there is a selection, as RGBA8 (R in the low byte,
// A = 255). Empty pixels get the background colour. Formulas:
// shared/shade_push.h. Colour mode, lighting and surfaces are
// specialisation constants: each pipeline holds one combination's code.
// One workgroup per covered tile (tile_classify.comp); the other tiles hold
// the background already.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/shade_push.h"
#include "shared/workgroup.h"
#include "glsl/shade_common.glsl"
#include "glsl/tangent.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(constant_id = kShadeSpecColorMode) const uint COLOR_MODE = kShadeColorOrientation;
layout(constant_id = kShadeSpecLighting) const uint LIGHTING = kShadeLightingIlluminated;
layout(constant_id = kShadeSpecSurfaces) const bool SURFACES = false;
layout(constant_id = kShadeSpecTranslucentSlices) const bool TRANSLUCENT_SLICES = false;

layout(push_constant, std430) uniform Push { ShadePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer ShadeBlockRef { ShadeBlock b; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer AoRef { float values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer ShadowRef { float values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer ScalarRef { float values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer WordRef { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer ColorRef { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SurfaceRef { SurfaceTexel texels[]; };

uint packRgba8(vec3 c) {
  const uvec3 b = uvec3(clamp(c, 0.0, 1.0) * 255.0 + 0.5);
  return b.r | (b.g << 8) | (b.b << 16) | (255u << 24);
}

vec3 unpackRgb8(uint c) { return vec3(c & 255u, (c >> 8) & 255u, (c >> 16) & 255u) / 255.0; }
float alpha8(uint c) { return float(c >> 24) / 255.0; }

// The colormap entry of fiber scalar s (colormap.h: colormapIndex).
vec3 scalarColor(ShadeBlockRef block, float s) {
  const float lo = block.b.scalar_min, hi = block.b.scalar_max;
  float t = hi > lo ? (s - lo) / (hi - lo) : 0.5;
  if (isnan(s)) t = 0.0;
  const uint entry = uint(clamp(t, 0.0, 1.0) * float(kShadeColormapEntries - 1u) + 0.5);
  return unpackRgb8(block.b.colormap[entry]);
}

// A unit normal in view space, as a colour.
vec3 viewNormalColor(CameraBlock cam, vec3 n) {
  return 0.5 + 0.5 * vec3(dot(n, cameraRight(cam)), dot(n, cameraUp(cam)), dot(n, cameraBack(cam)));
}

// Cook-Torrance (GGX, Schlick-GGX/Smith, Fresnel-Schlick) summed over the
// ring, plus the ambient term (formulas: shared/shade_push.h).
vec3 pbrColor(ShadeBlockRef block, CameraBlock cam, vec3 albedo, vec3 n, vec3 v) {
  const float rough = block.b.roughness, metal = block.b.metalness;
  const float a = rough * rough, a2 = a * a;
  const float k = (rough + 1.0) * (rough + 1.0) / 8.0;
  const vec3 f0 = mix(vec3(0.04), albedo, metal);
  const float nv = max(dot(n, v), 0.0);
  const float g1v = nv / (nv * (1.0 - k) + k);
  const float radiance = block.b.light_intensity / float(kPbrLights);
  // The ring (shared/shade_push.h) in world space: light i is
  // cos(polar) back + sin(polar) (cos(phi_i) right + sin(phi_i) up); phi
  // steps by a constant rotation, so a pixel takes no sine per light.
  const vec3 axis = cos(kPbrRingPolar) * cameraBack(cam);
  const vec3 right = sin(kPbrRingPolar) * cameraRight(cam), up = sin(kPbrRingPolar) * cameraUp(cam);
  const float step_c = cos(6.28318531 / float(kPbrLights)), step_s = sin(6.28318531 / float(kPbrLights));
  vec2 phi = vec2(1.0, 0.0);  // (cos, sin) of light i's azimuth
  vec3 sum = vec3(0.0);
  for (uint i = 0u; i < kPbrLights; ++i, phi = vec2(phi.x * step_c - phi.y * step_s, phi.y * step_c + phi.x * step_s)) {
    const vec3 l = axis + phi.x * right + phi.y * up;
    const float nl = dot(n, l);
    if (nl <= 0.0) continue;
    const vec3 h = normalize(l + v);
    const float nh = max(dot(n, h), 0.0), hv = max(dot(h, v), 0.0);
    const float q = nh * nh * (a2 - 1.0) + 1.0;
    const float d = a2 / (3.14159265 * q * q);
    const float g = g1v * nl / (nl * (1.0 - k) + k);
    const vec3 f = f0 + (1.0 - f0) * pow(1.0 - hv, 5.0);
    const vec3 kd = (1.0 - f) * (1.0 - metal);
    const vec3 specular = d * g * f / max(4.0 * nl * nv, kPbrMinDenominator);
    sum += (kd * albedo / 3.14159265 + specular) * radiance * nl;
  }
  return block.b.ambient * albedo + sum;
}

// The line's unit normal facing the eye: in the plane of T and V.
vec3 viewFacingNormal(vec3 t, vec3 v) {
  const vec3 towards = v - dot(v, t) * t;
  const float len = length(towards);
  return len > kShadeNormalParallelEps ? towards / len : v;
}

// The headlight in world space.
vec3 lightDirection(CameraBlock cam) {
  const vec3 lv = normalize(vec3(kShadeLightViewX, kShadeLightViewY, kShadeLightViewZ));
  return lv.x * cameraRight(cam) + lv.y * cameraUp(cam) + lv.z * cameraBack(cam);
}

void main() {
  uvec2 p;
  if (!tilePixel(pc.tiles, pc.width, pc.height, p)) return;
  const uint index = p.y * pc.width + p.x;
  const GBufferTexel texel = GBufferRef(pc.gbuffer).texels[index];
  ShadeBlockRef block = ShadeBlockRef(pc.block);
  const vec3 background = unpackRgb8(block.b.background);
  vec3 c = background;
  if (texel.fiber != kNoFiberId) {
    const CameraBlock cam = CameraRef(pc.camera).camera;
    const vec3 t = unpackTangent(texel.tangent);
    const vec3 v = pixelToEye(cam, p);
    // A surface's normal and own colour (shared/gbuffer.h).
    bool surface = false, slice = false;
    vec3 n = vec3(0.0);
    uint own_color = 0u;
    if (SURFACES && (texel.segment & kGBufferSurface) != 0u) {
      const SurfaceTexel s = SurfaceRef(pc.surface).texels[index];
      surface = true;
      slice = s.source == kSurfaceSourceSlice;
      n = unpackTangent(s.normal);
      if (dot(n, v) < 0.0) n = -n;
      own_color = s.color;
    }
    if (slice) {
      // Anatomy shows its window/level grey as is: no lighting, no
      // occlusion; a translucent one over the background.
      ColorRef(pc.color).values[index] = packRgba8(mix(background, unpackRgb8(own_color), alpha8(own_color)));
      return;
    }
    const bool known = texel.fiber < block.b.fiber_count;
    bool selected = false, dimmed = false;
    if (block.b.selection_bits != 0ul && known) {
      selected = (WordRef(block.b.selection_bits).values[texel.fiber >> 5] & (1u << (texel.fiber & 31u))) != 0u;
      dimmed = !selected;
    }
    if (selected) c = unpackRgb8(block.b.highlight);
    else if (SURFACES && (own_color >> 24) != 0u) c = unpackRgb8(own_color);
    else if (COLOR_MODE == kShadeColorOrientation) c = abs(t);
    else if (COLOR_MODE == kShadeColorPerFiber) c = fiberColor(texel.fiber);
    else if (COLOR_MODE == kShadeColorScalar)
      c = known ? scalarColor(block, ScalarRef(block.b.fiber_scalars).values[texel.fiber]) : abs(t);
    else if (COLOR_MODE == kShadeColorNormal) c = viewNormalColor(cam, surface ? n : viewFacingNormal(t, v));
    else c = unpackRgb8(block.b.solid);
    const vec3 base = c;
    if (LIGHTING == kShadeLightingIlluminated) {
      const vec3 l = lightDirection(cam);
      const float ambient = block.b.ambient, diffuse_k = block.b.diffuse, specular_k = block.b.specular;
      const float shininess = block.b.shininess;
      if (surface) {
        const float diffuse = max(dot(n, l), 0.0);
        const float specular = pow(max(dot(n, normalize(l + v)), 0.0), shininess);
        c = c * (ambient + diffuse_k * diffuse) + vec3(specular_k * specular);
      } else {
        const float lt = dot(l, t), vt = dot(v, t);
        const float diffuse = sqrt(max(1.0 - lt * lt, 0.0));
        const float cos_rv = max(diffuse * sqrt(max(1.0 - vt * vt, 0.0)) - lt * vt, 0.0);
        const float specular = pow(cos_rv, shininess);
        c = c * (ambient + diffuse_k * diffuse) + vec3(specular_k * specular);
      }
    } else if (LIGHTING == kShadeLightingPbr) {
      c = pbrColor(block, cam, c, surface ? n : viewFacingNormal(t, v), v);
    }
    // Soft shadows scale the direct light only (shared/shade_push.h).
    if (LIGHTING != kShadeLightingNone && pc.shadow != 0ul)
      c = mix(base * block.b.ambient, c, ShadowRef(pc.shadow).values[index]);
    if (pc.ao != 0ul) c *= AoRef(pc.ao).values[index];
    if (dimmed) c = mix(c, background, block.b.dim_unselected);
    if (TRANSLUCENT_SLICES) {
      // A translucent slice in front (the merge left the pixel's texel).
      const SurfaceTexel front = SurfaceRef(pc.surface).texels[index];
      if (front.source == kSurfaceSourceSlice && front.depth < texel.depth)
        c = mix(clamp(c, 0.0, 1.0), unpackRgb8(front.color), alpha8(front.color));  // over what is shown
    }
  }
  ColorRef(pc.color).values[index] = packRgba8(c);
}
