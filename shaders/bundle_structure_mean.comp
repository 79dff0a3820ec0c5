// Bundling, structure tensor step 1 (shared/bundling.h): one invocation per
// cell of pc.cell voxels a side writes the cell's mean density, the density
// at the tensor's scale (coarse enough that the ripple between neighbouring
// fibers, which isotropic bundling amplifies into strands, is gone). The
// last cell of an axis may hold fewer voxels: its mean is over those.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kBundleGroupSize

#include "glsl/bundling.glsl"

layout(push_constant, std430) uniform Push { BundleGridPush pc; };

void main() {
  const BundleGridBlock cells = bundleStructureCells(pc.grid, pc.cell);
  const uint index = bundleInvocation();
  if (index >= cells.nx * cells.ny * cells.nz) return;
  const uvec3 c = uvec3(index % cells.nx, (index / cells.nx) % cells.ny, index / (cells.nx * cells.ny));
  const uvec3 lo = c * pc.cell;
  const uvec3 hi = min(lo + pc.cell, uvec3(pc.grid.nx, pc.grid.ny, pc.grid.nz));
  float sum = 0.0;
  for (uint z = lo.z; z < hi.z; ++z)
    for (uint y = lo.y; y < hi.y; ++y)
      for (uint x = lo.x; x < hi.x; ++x)
        sum += bundleDensity(pc.src, pc.src_is_count, pc.src_scale, bundleVoxelIndex(pc.grid, x, y, z));
  const uvec3 n = hi - lo;
  BundleFloatsRef(pc.dst).values[index] = sum / float(n.x * n.y * n.z);
}
