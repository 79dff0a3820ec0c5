// Distance-field soft shadows (shared/distance_field.h DfShadowPush;
// Quilez's penumbra estimate): per covered pixel, a sphere trace from the
// surface towards the shade pass's headlight through the tubes' distance
// field; the smallest softness * d / t along it is the light that gets
// through. The shade pass scales the direct light by it.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/distance_field.h"
#include "shared/shade_push.h"
#include "shared/workgroup.h"
#include "glsl/shade_common.glsl"
#include "glsl/tangent.glsl"
#include "glsl/distance_field.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { DfShadowPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer ShadowRef { float values[]; };

void main() {
  uvec2 p;
  if (!tilePixel(pc.tiles, pc.width, pc.height, p)) return;
  const CameraBlock cam = CameraRef(pc.camera).camera;
  vec3 position, normal;
  float shadow = 1.0;
  if (dfPixelPoint(cam, pc.gbuffer, pc.surface, p, pc.width, position, normal)) {
    // shade.comp's headlight, in world space.
    const vec3 lv = normalize(vec3(kShadeLightViewX, kShadeLightViewY, kShadeLightViewZ));
    const vec3 l = lv.x * cameraRight(cam) + lv.y * cameraUp(cam) + lv.z * cameraBack(cam);
    if (dot(normal, l) > 0.0) {
      const float s = kDfShadowStartVoxels * pc.grid.voxel;
      const float min_step = kDfShadowMinStepVoxels * pc.grid.voxel;
      const float open = kDfShadowOpenFraction * pc.grid.band;
      const vec3 o = position + s * normal;
      float t = s;
      for (uint j = 0u; j < kDfShadowSteps; ++j) {
        const vec3 q = o + t * l;
        if (!dfInside(pc.grid, q)) break;
        const float d = dfSample(pc.field, pc.grid, q);
        if (d < open) shadow = min(shadow, pc.softness * d / t);
        if (shadow <= 0.0) break;
        t += max(d, min_step);
      }
      shadow = clamp(shadow, 0.0, 1.0);
    }
  }
  ShadowRef(pc.shadow).values[p.y * pc.width + p.x] = shadow;
}
