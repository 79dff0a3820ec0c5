// One direction of the depth-aware separable blur of the SSAO factor
// (ssao.comp): 5 taps weighted 1 2 2 2 1 along (step_x, step_y), over
// covered pixels whose view depth lies within depth_tolerance_mm of the
// centre's. The weights give each phase of ssao.comp's 4 x 4 rotation tile
// the same total, so the x then y passes average the 16 rotations (no
// pattern left where the depth is even) without bleeding between fibers far
// apart in depth or into the background. Run once with (1, 0), once with
// (0, 1). Empty pixels copy their value (1).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "shared/shade_push.h"
#include "glsl/shade_common.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { SsaoBlurPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer AoRef { float values[]; };

void main() {
  uvec2 p;
  if (!tilePixel(pc.tiles, pc.width, pc.height, p)) return;
  const uint index = p.y * pc.width + p.x;
  GBufferRef gbuffer = GBufferRef(pc.gbuffer);
  AoRef ao_in = AoRef(pc.ao_in);
  const GBufferTexel centre = gbuffer.texels[index];
  float result = ao_in.values[index];
  if (centre.fiber != kNoFiberId) {
    const CameraBlock cam = CameraRef(pc.camera).camera;
    const float z = viewDistance(cam, centre.depth);
    float sum = 2.0 * result, total = 2.0;
    const ivec2 step = ivec2(pc.step_x, pc.step_y);
    for (int k = -int(kSsaoBlurRadius); k <= int(kSsaoBlurRadius); ++k) {
      if (k == 0) continue;
      const ivec2 q = ivec2(p) + k * step;
      if (q.x < 0 || q.y < 0 || q.x >= int(pc.width) || q.y >= int(pc.height)) continue;
      const uint qi = uint(q.y) * pc.width + uint(q.x);
      const GBufferTexel t = gbuffer.texels[qi];
      if (t.fiber == kNoFiberId || abs(viewDistance(cam, t.depth) - z) > pc.depth_tolerance_mm) continue;
      const float w = abs(k) == int(kSsaoBlurRadius) ? 1.0 : 2.0;
      sum += w * ao_in.values[qi];
      total += w;
    }
    result = sum / total;
  }
  AoRef(pc.ao_out).values[index] = result;
}
