// Distance-field ambient occlusion (shared/distance_field.h DfAoPush;
// Evans 2006, as McGraw's seed): per covered pixel, N samples of the
// tubes' distance field along the pixel's normal, each sample's shortfall
// from its height weighted 2^-i, into the AO buffer the shade pass
// multiplies by (in place of ssao.comp: RenderSettings::ao_method).
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

layout(push_constant, std430) uniform Push { DfAoPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer AoRef { float values[]; };

void main() {
  uvec2 p;
  if (!tilePixel(pc.tiles, pc.width, pc.height, p)) return;
  const CameraBlock cam = CameraRef(pc.camera).camera;
  vec3 position, normal;
  float ao = 1.0;
  if (dfPixelPoint(cam, pc.gbuffer, pc.surface, p, pc.width, position, normal)) {
    const float eps = kDfSelfOffsetVoxels * pc.grid.voxel;
    float sum = 0.0, weight = 0.5;
    for (uint i = 1u; i <= pc.steps; ++i, weight *= 0.5) {
      const float h = eps + float(i) * pc.delta;
      const float d = dfSample(pc.field, pc.grid, position + h * normal);
      sum += weight * max(min(h, pc.grid.band) - d, 0.0);
    }
    ao = clamp(1.0 - pc.strength / pc.delta * sum, 0.0, 1.0);
  }
  AoRef(pc.ao).values[p.y * pc.width + p.x] = ao;
}
