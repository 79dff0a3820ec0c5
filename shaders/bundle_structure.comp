// Bundling, structure tensor step 2 (shared/bundling.h): one invocation per
// cell (pc.grid is the cell grid, pc.src the cell means) writes
// J = mean of G G^T over the cell and its up to 26 neighbours, G the
// means' central differences (one-sided at the faces): the integration
// over neighbours lets a sheet's middle cell, where G changes sign, see
// the sheet's normal. 6 floats a cell: xx xy xz yy yz zz.
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
  if (index >= pc.grid.nx * pc.grid.ny * pc.grid.nz) return;
  const uvec3 size = uvec3(pc.grid.nx, pc.grid.ny, pc.grid.nz);
  const uvec3 c = uvec3(index % size.x, (index / size.x) % size.y, index / (size.x * size.y));
  const uvec3 lo = max(c, uvec3(1u)) - 1u;
  const uvec3 hi = min(c + 2u, size);
  vec3 diag = vec3(0.0);  // xx yy zz
  vec3 off = vec3(0.0);   // xy xz yz
  for (uint z = lo.z; z < hi.z; ++z)
    for (uint y = lo.y; y < hi.y; ++y)
      for (uint x = lo.x; x < hi.x; ++x) {
        const vec3 g = bundleGradientAt(pc.grid, pc.src, 0u, 1.0, uvec3(x, y, z));
        diag += g * g;
        off += vec3(g.x * g.y, g.x * g.z, g.y * g.z);
      }
  const uvec3 n = hi - lo;
  const float inv = 1.0 / float(n.x * n.y * n.z);
  BundleFloatsRef tensor = BundleFloatsRef(pc.dst);
  tensor.values[6u * index + 0u] = diag.x * inv;
  tensor.values[6u * index + 1u] = off.x * inv;
  tensor.values[6u * index + 2u] = off.y * inv;
  tensor.values[6u * index + 3u] = diag.y * inv;
  tensor.values[6u * index + 4u] = off.z * inv;
  tensor.values[6u * index + 5u] = diag.z * inv;
}
