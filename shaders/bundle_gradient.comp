// Bundling, gradient (shared/bundling.h): one invocation per voxel takes
// the density's central differences (D[i+1] - D[i-1]) / 2h, one-sided
// (D[i+1] - D[i]) / h at the grid's faces, into a vec4 (w = 0) per voxel.
// D: the density passes' floats, or the splat's fixed point (src_is_count).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kBundleGroupSize

#include "glsl/bundling.glsl"

layout(push_constant, std430) uniform Push { BundleGridPush pc; };

// The density at voxel i: float, or the anisotropic splat's fixed point.
float density(uint i) {
  return pc.src_is_count != 0u ? float(BundleUintsRef(pc.src).values[i]) * pc.src_scale
                               : BundleFloatsRef(pc.src).values[i];
}

float difference(uint index, uint at, uint n, uint stride) {
  if (n < 2u) return 0.0;
  const uint lo = at > 0u ? index - stride : index;
  const uint hi = at + 1u < n ? index + stride : index;
  const float span = float((at + 1u < n ? 1u : 0u) + (at > 0u ? 1u : 0u)) * pc.grid.voxel;
  return (density(hi) - density(lo)) / span;
}

void main() {
  const uint index = bundleInvocation();
  const uint voxels = pc.grid.nx * pc.grid.ny * pc.grid.nz;
  if (index >= voxels) return;
  const uvec3 v = uvec3(index % pc.grid.nx, (index / pc.grid.nx) % pc.grid.ny, index / (pc.grid.nx * pc.grid.ny));
  const vec3 g = vec3(difference(index, v.x, pc.grid.nx, 1u), difference(index, v.y, pc.grid.ny, pc.grid.nx),
                      difference(index, v.z, pc.grid.nz, pc.grid.nx * pc.grid.ny));
  BundleVec4Ref(pc.dst).values[index] = vec4(g, 0.0);
}
