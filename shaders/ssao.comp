// Screen-space ambient occlusion for lines (DESIGN.md section 6, "Shading").
// Lines have no surface normal, so instead of a normal-oriented hemisphere
// each covered pixel looks at `samples` G-buffer neighbours on a disc of
// radius_px around it (a Vogel spiral, turned by one of 16 angles set by the
// pixel's place in a 4 x 4 tile, so neighbouring pixels sample different
// directions and the 5-tap blur averages all 16) and counts those of
// OTHER fibers that lie nearer the camera, as line renderers with depth
// cues do (e.g. the fiblets paper's fig. 1): a fiber behind or inside a
// bundle darkens, the front of a bundle does not.
//   - A neighbour occludes when it is nearer by more than epsilon_mm (fibers
//     side by side in a bundle do not) and less than range_mm, with a
//     smooth falloff over the second half of the range: foreground far in
//     front (another bundle) casts no shadow.
//   - Samples nearer the centre weigh more (1 at the centre, 0.5 at the rim).
//   - Neighbours of the same fiber never occlude, so a lone fiber over an
//     empty background stays exactly 1 however it turns in depth.
// ao = 1 - strength * (weighted occluders / total weight); 1 where empty.
// Multi-scale AO (FiberVisualizer section 11.3): with scales > 1 the same
// again on discs of 2, 4, 8, 16 times the radius, each with half the
// previous scale's samples (a wider disc's occluders are whole bundles,
// which fewer samples find), the factors multiplied: contact shadows from
// the first scale, whole bundles darkening those behind from the last.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "shared/shade_push.h"
#include "glsl/shade_common.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { SsaoPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer AoRef { float values[]; };

const float kGoldenAngle = 2.39996323;

void main() {
  uvec2 p;
  if (!tilePixel(pc.tiles, pc.width, pc.height, p)) return;
  const uint index = p.y * pc.width + p.x;
  GBufferRef gbuffer = GBufferRef(pc.gbuffer);
  const GBufferTexel centre = gbuffer.texels[index];
  float ao = 1.0;
  // Anatomical slices (kNoFiberObject) take no occlusion (shade shows their
  // grey as is) and cast none: a fiber behind a translucent slice is not
  // darkened by it.
  if (centre.fiber != kNoFiberId && centre.fiber != kNoFiberObject && pc.radius_px > 0.0 && pc.strength > 0.0) {
    const CameraBlock cam = CameraRef(pc.camera).camera;
    const float z = viewDistance(cam, centre.depth);
    // A 4 x 4 Bayer matrix: consecutive angles as far apart in the tile as
    // they can be, so even a partial blur (at a depth edge) mixes spread
    // directions.
    const uint bayer = ((p.x ^ p.y) & 1u) << 3 | (p.y & 1u) << 2 | ((p.x ^ p.y) & 2u) | (p.y & 2u) >> 1;
    const float rotation = (float(bayer) + 0.5) * (6.28318531 / float(kSsaoRotations));
    // Scale k samples a disc 2^k times wider; the factors multiply.
    for (uint k = 0u; k < pc.scales; ++k) {
      const float radius = pc.radius_px * float(1u << k);
      const float turn = rotation + float(k) * kGoldenAngle;
      const uint samples = max(pc.samples >> k, kSsaoMinSamples);
      float occluded = 0.0, total = 0.0;
      for (uint i = 0u; i < samples; ++i) {
        const float r = radius * sqrt((float(i) + 0.5) / float(samples));
        const float a = float(i) * kGoldenAngle + turn;
        const float weight = 1.0 - 0.5 * r / radius;
        total += weight;
        const ivec2 q = ivec2(floor(vec2(p) + 0.5 + r * vec2(cos(a), sin(a))));
        if (q.x < 0 || q.y < 0 || q.x >= int(pc.width) || q.y >= int(pc.height)) continue;
        const GBufferTexel t = gbuffer.texels[uint(q.y) * pc.width + uint(q.x)];
        if (t.fiber == kNoFiberId || t.fiber == kNoFiberObject || t.fiber == centre.fiber) continue;
        const float nearer = z - viewDistance(cam, t.depth);
        if (nearer > pc.epsilon_mm && nearer < pc.range_mm)
          occluded += weight * (1.0 - smoothstep(0.5 * pc.range_mm, pc.range_mm, nearer));
      }
      ao *= 1.0 - pc.strength * occluded / total;
    }
  }
  AoRef(pc.ao).values[index] = ao;
}
