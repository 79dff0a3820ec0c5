// One direction of the depth-aware separable blur of the SSAO factor
// (ssao.comp): a 2 * kSsaoBlurRadius + 1 tap Gaussian along (step_x,
// step_y) over covered pixels whose view depth lies within
// depth_tolerance_mm of the centre's, so the per-pixel rotation noise is
// smoothed along and across a bundle without bleeding between fibers far
// apart in depth or into the background. Run once with (1, 0), once with
// (0, 1). Empty pixels copy their value (1).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/shade_push.h"
#include "glsl/shade_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { SsaoBlurPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer AoRef { float values[]; };

// Gaussian weights of taps 1 .. kSsaoBlurRadius (4), sigma = radius / 2 so
// the outermost taps weigh e^-2; folded to constants by the compiler.
const float kBlurSigma2x2 = float(kSsaoBlurRadius * kSsaoBlurRadius) / 2.0;
const float kBlurWeight[4] = float[4](exp(-1.0 / kBlurSigma2x2), exp(-4.0 / kBlurSigma2x2), exp(-9.0 / kBlurSigma2x2),
                                      exp(-16.0 / kBlurSigma2x2));

// The clip depth of view distance z (the inverse of viewDistance):
// d = f (z - n) / ((f - n) z), increasing in z.
float clipDepthOf(CameraBlock cam, float z) {
  const float n = cam.depth_range.x, f = cam.depth_range.y;
  return f * (z - n) / ((f - n) * z);
}

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  const uint index = p.y * pc.width + p.x;
  GBufferRef gbuffer = GBufferRef(pc.gbuffer);
  AoRef ao_in = AoRef(pc.ao_in);
  const GBufferTexel centre = gbuffer.texels[index];
  float result = ao_in.values[index];
  if (centre.fiber != kNoFiberId) {
    const CameraBlock cam = CameraRef(pc.camera).camera;
    const float z = viewDistance(cam, centre.depth);
    // A tap counts where its view distance lies within the tolerance of the
    // centre's: since clip depth increases with distance, the same as its
    // clip depth within these bounds (no division per tap).
    const float z_near = z - pc.depth_tolerance_mm;
    const float depth_lo = z_near > cam.depth_range.x ? clipDepthOf(cam, z_near) : -1.0;
    const float depth_hi = clipDepthOf(cam, z + pc.depth_tolerance_mm);
    float sum = result, total = 1.0;
    const ivec2 step = ivec2(pc.step_x, pc.step_y);
    for (int k = -int(kSsaoBlurRadius); k <= int(kSsaoBlurRadius); ++k) {
      if (k == 0) continue;
      const ivec2 q = ivec2(p) + k * step;
      if (q.x < 0 || q.y < 0 || q.x >= int(pc.width) || q.y >= int(pc.height)) continue;
      const uint qi = uint(q.y) * pc.width + uint(q.x);
      const GBufferTexel t = gbuffer.texels[qi];
      if (t.fiber == kNoFiberId || t.depth < depth_lo || t.depth > depth_hi) continue;
      const float w = kBlurWeight[abs(k) - 1];
      sum += w * ao_in.values[qi];
      total += w;
    }
    result = sum / total;
  }
  AoRef(pc.ao_out).values[index] = result;
}
