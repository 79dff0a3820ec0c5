// Bundling, anisotropic splat (shared/bundling.h; the structure-aware mode
// after Bouma, Hurter, Telea): one invocation per sample adds its kernel,
// an ellipsoid elongated along its fiber (Ra = R along, Rb across), to
// every voxel centre of the cube |v - c| <= Ra around it, as fixed point
// (bundleSplatWeight). Replaces count and the three density passes; the
// gradient reads the fixed point.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kBundleGroupSize

#include "glsl/bundling.glsl"

layout(push_constant, std430) uniform Push { BundleSamplePush pc; };

void main() {
  const uint i = bundleInvocation();
  if (i >= pc.sample_count) return;
  BundleVec4Ref src = BundleVec4Ref(pc.src);
  const vec3 p = src.values[i].xyz;
  const uint fiber = BundleUintsRef(pc.sample_fiber).values[i];
  const uint s0 = BundleUintsRef(pc.sample_offsets).values[fiber];
  const uint s1 = BundleUintsRef(pc.sample_offsets).values[fiber + 1u];
  const vec3 along = src.values[min(i + 1u, s1 - 1u)].xyz - src.values[i > s0 ? i - 1u : i].xyz;
  const float alen = length(along);
  const vec3 d = alen > 0.0 ? along / alen : vec3(0.0);
  const vec3 c = (p - vec3(pc.grid.origin_x, pc.grid.origin_y, pc.grid.origin_z)) / pc.grid.voxel;
  const vec3 top = vec3(pc.grid.nx - 1u, pc.grid.ny - 1u, pc.grid.nz - 1u);
  const uvec3 lo = uvec3(clamp(floor(c - pc.radius_along), vec3(0.0), top));
  const uvec3 hi = uvec3(clamp(floor(c + pc.radius_along), vec3(0.0), top));
  const float inv_along2 = 1.0 / (pc.radius_along * pc.radius_along);
  const float inv_across2 = 1.0 / (pc.radius_across * pc.radius_across);
  BundleUintsRef density = BundleUintsRef(pc.field);
  for (uint z = lo.z; z <= hi.z; ++z)
    for (uint y = lo.y; y <= hi.y; ++y)
      for (uint x = lo.x; x <= hi.x; ++x) {
        const uint w = bundleSplatWeight(vec3(x, y, z) + 0.5 - c, d, inv_along2, inv_across2);
        if (w != 0u) atomicAdd(density.values[bundleVoxelIndex(pc.grid, x, y, z)], w);
      }
}
