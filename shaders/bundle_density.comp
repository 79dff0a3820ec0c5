// Bundling, density along one axis (shared/bundling.h): one invocation per
// voxel sums its neighbours along pc.axis within floor(R) voxels, weighted
// by the parabola 1 - d^2 / R^2 (bundleKernelWeight). Run for x (from the
// counts), y and z: the product kernel k(dx) k(dy) k(dz). Voxels outside
// the grid count as empty. The sum runs from -r to r in order (one order on
// the CPU and the GPU).
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
  const uvec3 size = uvec3(pc.grid.nx, pc.grid.ny, pc.grid.nz);
  const int n = int(size[pc.axis]);
  const int at = int(v[pc.axis]);
  const uint stride = pc.axis == 0u ? 1u : (pc.axis == 1u ? pc.grid.nx : pc.grid.nx * pc.grid.ny);
  const int r = int(floor(pc.radius));
  const int lo = max(-r, -at), hi = min(r, n - 1 - at);
  float sum = 0.0;
  for (int d = lo; d <= hi; ++d) {
    const uint j = uint(int(index) + d * int(stride));
    const float value = pc.src_is_count != 0u ? float(BundleUintsRef(pc.src).values[j]) : BundleFloatsRef(pc.src).values[j];
    sum += bundleKernelWeight(float(d), pc.inv_radius2) * value;
  }
  BundleFloatsRef(pc.dst).values[index] = sum;
}
