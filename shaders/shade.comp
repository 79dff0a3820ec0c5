// Shading (DESIGN.md section 6, "Shading"): per pixel, the G-buffer texel's
// base colour (solid, |tangent| as RGB, or a hashed per-fiber colour) times
// the lighting (none, or illuminated lines: Zoeckler, Stalling, Hege 1996,
// which light a line from its tangent alone: the normal is the one in the
// plane of T and L that maximises the Phong terms), times the ambient
// occlusion factor when ssao.comp ran, as RGBA8 (R in the low byte, A = 255).
// Empty pixels get the background colour. Formulas: shared/shade_push.h.
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
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer ColorRef { uint values[]; };

uint packRgba8(vec3 c) {
  const uvec3 b = uvec3(clamp(c, 0.0, 1.0) * 255.0 + 0.5);
  return b.r | (b.g << 8) | (b.b << 16) | (255u << 24);
}

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  const uint index = p.y * pc.width + p.x;
  const GBufferTexel texel = GBufferRef(pc.gbuffer).texels[index];
  vec3 c = vec3(pc.background_r, pc.background_g, pc.background_b);
  if (texel.fiber != kNoFiberId) {
    const vec3 t = unpackTangent(texel.tangent);
    if (pc.color_mode == kShadeColorOrientation) c = abs(t);
    else if (pc.color_mode == kShadeColorPerFiber) c = fiberColor(texel.fiber);
    else c = vec3(pc.solid_r, pc.solid_g, pc.solid_b);
    if (pc.lighting == kShadeLightingIlluminated) {
      const CameraBlock cam = CameraRef(pc.camera).camera;
      const vec3 lv = normalize(vec3(kShadeLightViewX, kShadeLightViewY, kShadeLightViewZ));
      const vec3 l = lv.x * cameraRight(cam) + lv.y * cameraUp(cam) + lv.z * cameraBack(cam);
      const vec3 v = pixelToEye(cam, p);
      const float lt = dot(l, t), vt = dot(v, t);
      const float diffuse = sqrt(max(1.0 - lt * lt, 0.0));
      const float cos_rv = max(diffuse * sqrt(max(1.0 - vt * vt, 0.0)) - lt * vt, 0.0);
      const float specular = pow(cos_rv, pc.shininess);
      c = c * (pc.ambient + pc.diffuse * diffuse) + vec3(pc.specular * specular);
    }
    if (pc.ao != 0ul) c *= AoRef(pc.ao).values[index];
  }
  ColorRef(pc.color).values[index] = packRgba8(c);
}
