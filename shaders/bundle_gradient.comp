// Bundling, gradient (shared/bundling.h): one invocation per voxel takes
// the density's central differences (D[i+1] - D[i-1]) / 2h, one-sided
// (D[i+1] - D[i]) / h at the grid's faces, into a vec4 (w = 0) per voxel.
// D: the density passes' floats, or the splat's fixed point (src_is_count).
// The advection takes the same gradient (bundleGradientAt) at the voxels
// around each sample itself; this grid is written only for the tests
// (GpuBundlerOptions::keep_stages), which check it against the reference.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kBundleGroupSize

#include "glsl/bundling.glsl"

layout(push_constant, std430) uniform Push { BundleGridPush pc; };

void main() {
  const uint index = bundleInvocation();
  const uint voxels = pc.grid.nx * pc.grid.ny * pc.grid.nz;
  if (index >= voxels) return;
  const uvec3 v = uvec3(index % pc.grid.nx, (index / pc.grid.nx) % pc.grid.ny, index / (pc.grid.nx * pc.grid.ny));
  const vec3 g = bundleGradientAt(pc.grid, pc.src, pc.src_is_count, pc.src_scale, v);
  BundleVec4Ref(pc.dst).values[index] = vec4(g, 0.0);
}
